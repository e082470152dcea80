//! Mip pyramids for every projection, built with exact solid-angle weights.
//!
//! A texel's value is the mean radiance over the part of the sphere it covers, so a coarser
//! texel is the solid-angle-weighted mean of the finer texels under it,
//! `L = Σ Lᵢ Ωᵢ / Σ Ωᵢ`, with each `Ωᵢ` the projection's exact texel solid angle (a cube
//! map's corner texels cover about five times less of the sphere than its centre texels;
//! a lat-long map's polar texels far less than its equatorial ones). Energy `Σ L Ω` is
//! preserved from level to level.
//!
//! Two filters:
//!
//! * [`MipFilter::Box`]: each coarse texel averages exactly the fine texels it covers (for
//!   odd sizes, the fractions of them it covers). Cube faces of even size never cross an edge,
//!   and each level tiles the sphere exactly, so levels are seamless by construction: the
//!   values on either side of a cube edge are means over adjacent regions.
//! * [`MipFilter::Tent`]: a separable tent one coarse texel in radius (`[1 3 3 1]/8` for
//!   even sizes), weighted by solid angle. Its footprint reaches one fine texel past the
//!   coarse texel, across cube edges and corners, the longitude wrap and the poles; those
//!   texels come from [`WorldProjection::wrap_texel`], which is how ARB_seamless_cube_map
//!   filters across edges (at a corner the three texels meeting there are each weighted).
//!
//! Sizes halve, rounding down, to 1×1 (a `w×h` layer has `1 + ⌊log₂ max(w, h)⌋` levels).
//!
//! [`MipChain::resampled`] is the third way, each level converted from level 0 by the
//! resampler: what `convert --mips` writes into KTX2 and DDS files. (The resampler's own
//! lookup pyramid, inside `mirrorball-core`, weights each 2×2 block by the density at the
//! texel centres: cheaper, and only ever read through its bilinear lookups.)

use glam::DVec2;
use mirrorball_core::{EnvMap, Image, Projection, WorldProjection};
use rayon::prelude::*;

/// How a level is made from the one before.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MipFilter {
    /// Solid-angle-weighted mean of the texels covered (energy-exact; the default).
    #[default]
    Box,
    /// Solid-angle-weighted tent, one coarse texel in radius, crossing seams.
    Tent,
}

/// A mip pyramid: level 0 is the map itself, each further level half the size.
#[derive(Clone, Debug)]
pub struct MipChain {
    levels: Vec<EnvMap>,
}

impl MipChain {
    /// The full pyramid of `env`, down to 1×1.
    pub fn build(env: &EnvMap, filter: MipFilter) -> MipChain {
        MipChain::build_levels(env, filter, usize::MAX)
    }

    /// At most `max_levels` levels (level 0 included; at least 1).
    pub fn build_levels(env: &EnvMap, filter: MipFilter, max_levels: usize) -> MipChain {
        let mut levels = vec![env.clone()];
        while levels.len() < max_levels.max(1) {
            let last = levels.last().expect("level 0 exists");
            if last.width() == 1 && last.height() == 1 {
                break;
            }
            let next = downsample(last, filter);
            levels.push(next);
        }
        MipChain { levels }
    }

    /// The pyramid `convert --mips` writes: level `k` is level 0 converted to half, quarter…
    /// the edge by [`mirrorball_core::resample`] (each output texel integrated over its
    /// footprint on level 0, not a mean of the level before), down to 1 texel along the
    /// edge. Unlike [`MipChain::build`], the weights are the resampler's (density at the
    /// integration points), so energy is conserved to the resampler's accuracy rather than
    /// exactly; it is kept for the files `convert` has always written.
    ///
    /// Each level is counted in `mirrorball_core::work` once made ([`MipChain::resampled_work`]).
    pub fn resampled(env: &EnvMap) -> MipChain {
        let mut levels = vec![env.clone()];
        let proj = *env.projection();
        let mut size = env.width() / 2;
        let texels = |m: &EnvMap| m.width() as u64 * m.height() as u64 * m.layers().len() as u64;
        while size >= 1 {
            let level = mirrorball_core::resample(
                env,
                proj,
                size,
                &mirrorball_core::ResampleOptions::default(),
            );
            mirrorball_core::work::add(mirrorball_core::work::resample(
                texels(env),
                texels(&level),
            ));
            levels.push(level);
            if size == 1 {
                break;
            }
            size /= 2;
        }
        MipChain { levels }
    }

    /// The work [`MipChain::resampled`] counts for `env`: each level converted from it.
    pub fn resampled_work(env: &EnvMap) -> u64 {
        let texels = env.width() as u64 * env.height() as u64 * env.layers().len() as u64;
        let mut work = 0;
        let mut size = env.width() / 2;
        while size >= 1 {
            let (w, h) = env.projection().layer_extent(size);
            let out = w as u64 * h as u64 * env.layers().len() as u64;
            work += mirrorball_core::work::resample(texels, out);
            if size == 1 {
                break;
            }
            size /= 2;
        }
        work
    }

    /// Wraps levels made elsewhere (each must be the same projection; not checked).
    pub fn from_levels(levels: Vec<EnvMap>) -> MipChain {
        assert!(!levels.is_empty(), "a mip chain has at least one level");
        MipChain { levels }
    }

    /// The levels, finest first.
    pub fn levels(&self) -> &[EnvMap] {
        &self.levels
    }

    /// Level `i` (clamped to the coarsest).
    pub fn level(&self, i: usize) -> &EnvMap {
        &self.levels[i.min(self.levels.len() - 1)]
    }

    /// Number of levels.
    pub fn len(&self) -> usize {
        self.levels.len()
    }

    /// Always false: a chain has level 0.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Gives up the levels.
    pub fn into_levels(self) -> Vec<EnvMap> {
        self.levels
    }
}

/// Number of levels of a full pyramid over `w×h` layers: `1 + ⌊log₂ max(w, h)⌋`.
pub fn level_count(w: u32, h: u32) -> usize {
    32 - w.max(h).max(1).leading_zeros() as usize
}

/// Exact solid angles of every texel of every layer of a `w×h` map of `proj`, row-major.
/// (Cube maps: one table serves all six faces and is returned once; index layers with
/// `min(layer, len − 1)`.)
pub fn texel_solid_angles(proj: &Projection, w: u32, h: u32) -> Vec<Vec<f64>> {
    if proj.kind() == mirrorball_core::ProjectionKind::Cube && w == h {
        return vec![crate::cube::face_solid_angles(w as usize)];
    }
    (0..proj.layer_count())
        .map(|layer| {
            (0..h)
                .into_par_iter()
                .flat_map_iter(|y| (0..w).map(move |x| proj.texel_solid_angle(layer, x, y, w, h)))
                .collect()
        })
        .collect()
}

/// One level down: half the size (rounded down, at least 1), with `filter`.
pub fn downsample(env: &EnvMap, filter: MipFilter) -> EnvMap {
    let proj = *env.projection();
    let (w, h) = (env.width(), env.height());
    let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
    let c = env.channels();
    let omega = texel_solid_angles(&proj, w, h);
    let layers: Vec<Image> = (0..proj.layer_count())
        .map(|layer| {
            let mut out = Image::new(nw, nh, c);
            out.data_mut()
                .par_chunks_mut(nw as usize * c)
                .enumerate()
                .for_each(|(y, row)| match filter {
                    MipFilter::Box => box_row(env, &omega, layer, y as u32, nw, nh, row),
                    MipFilter::Tent => tent_row(env, &omega, layer, y as u32, nw, nh, row),
                });
            out
        })
        .collect();
    EnvMap::new(proj, layers).expect("same shape as the source")
}

/// Overlap of fine texel `i` (of `n`) with coarse texel `j` (of `m`), as a fraction of the
/// fine texel.
#[inline]
fn overlap(i: u32, n: u32, j: u32, m: u32) -> f64 {
    let (a0, a1) = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
    let (b0, b1) = (j as f64 / m as f64, (j + 1) as f64 / m as f64);
    ((a1.min(b1) - a0.max(b0)) * n as f64).max(0.0)
}

fn box_row(
    env: &EnvMap,
    omega: &[Vec<f64>],
    layer: usize,
    y: u32,
    nw: u32,
    nh: u32,
    row: &mut [f32],
) {
    let (w, h) = (env.width(), env.height());
    let c = env.channels();
    let img = &env.layers()[layer];
    let om = &omega[layer.min(omega.len() - 1)];
    let y0 = (y as u64 * h as u64 / nh as u64) as u32;
    let y1 = (((y + 1) as u64 * h as u64).div_ceil(nh as u64) as u32).min(h);
    for x in 0..nw {
        let x0 = (x as u64 * w as u64 / nw as u64) as u32;
        let x1 = (((x + 1) as u64 * w as u64).div_ceil(nw as u64) as u32).min(w);
        let mut acc = [0.0f64; 4];
        let mut wsum = 0.0;
        for sy in y0..y1 {
            let oy = overlap(sy, h, y, nh);
            for sx in x0..x1 {
                let wt = oy * overlap(sx, w, x, nw) * om[(sy * w + sx) as usize];
                if wt <= 0.0 {
                    continue;
                }
                for (a, v) in acc.iter_mut().zip(img.get(sx, sy)) {
                    *a += wt * *v as f64;
                }
                wsum += wt;
            }
        }
        write_mean(
            &mut row[x as usize * c..(x as usize + 1) * c],
            &acc,
            wsum,
            || {
                // Texels of zero solid angle only (outside a disk map's rim): plain mean.
                let mut a = [0.0f64; 4];
                let mut n = 0.0;
                for sy in y0..y1 {
                    for sx in x0..x1 {
                        for (a, v) in a.iter_mut().zip(img.get(sx, sy)) {
                            *a += *v as f64;
                        }
                        n += 1.0;
                    }
                }
                (a, n)
            },
        );
    }
}

fn tent_row(
    env: &EnvMap,
    omega: &[Vec<f64>],
    layer: usize,
    y: u32,
    nw: u32,
    nh: u32,
    row: &mut [f32],
) {
    let proj = env.projection();
    let (w, h) = (env.width(), env.height());
    let c = env.channels();
    // Coarse texel centre in fine texel coordinates (centres at half-integers): the tent
    // reaches one coarse texel either way.
    let sy_scale = h as f64 / nh as f64;
    let sx_scale = w as f64 / nw as f64;
    let cy = (y as f64 + 0.5) * sy_scale;
    let ry = sy_scale.max(1.0);
    let ylo = (cy - ry - 0.5).floor() as i64;
    let yhi = (cy + ry - 0.5).ceil() as i64;
    for x in 0..nw {
        let cx = (x as f64 + 0.5) * sx_scale;
        let rx = sx_scale.max(1.0);
        let xlo = (cx - rx - 0.5).floor() as i64;
        let xhi = (cx + rx - 0.5).ceil() as i64;
        let mut acc = [0.0f64; 4];
        let mut wsum = 0.0;
        for sy in ylo..=yhi {
            let ty = 1.0 - ((sy as f64 + 0.5 - cy) / ry).abs();
            if ty <= 0.0 {
                continue;
            }
            for sx in xlo..=xhi {
                let tx = 1.0 - ((sx as f64 + 0.5 - cx) / rx).abs();
                if tx <= 0.0 {
                    continue;
                }
                let (l, fx, fy) = if sx >= 0 && sy >= 0 && sx < w as i64 && sy < h as i64 {
                    (layer, sx as u32, sy as u32)
                } else {
                    proj.wrap_texel(layer, sx, sy, w, h)
                };
                let wt = tx * ty * omega[l.min(omega.len() - 1)][(fy * w + fx) as usize];
                if wt <= 0.0 {
                    continue;
                }
                for (a, v) in acc.iter_mut().zip(env.layers()[l].get(fx, fy)) {
                    *a += wt * *v as f64;
                }
                wsum += wt;
            }
        }
        write_mean(
            &mut row[x as usize * c..(x as usize + 1) * c],
            &acc,
            wsum,
            || {
                // No covered texel under the tent: take the nearest covered point's value.
                let uv = DVec2::new((x as f64 + 0.5) / nw as f64, (y as f64 + 0.5) / nh as f64);
                let uv = proj.nearest_covered(layer, uv);
                let mut out = [0.0f32; 4];
                env.bilinear_at(layer, uv, &mut out[..c]);
                let mut a = [0.0f64; 4];
                for (a, v) in a.iter_mut().zip(out) {
                    *a = v as f64;
                }
                (a, 1.0)
            },
        );
    }
}

#[inline]
fn write_mean(out: &mut [f32], acc: &[f64; 4], wsum: f64, fallback: impl Fn() -> ([f64; 4], f64)) {
    if wsum > 0.0 {
        for (o, a) in out.iter_mut().zip(acc) {
            *o = (a / wsum) as f32;
        }
    } else {
        let (a, n) = fallback();
        for (o, a) in out.iter_mut().zip(a) {
            *o = (a / n.max(1.0)) as f32;
        }
    }
}
