//! The environment map: texels plus the projection that says which direction each one sees.

use crate::projection::{Projection, WorldProjection};
use crate::Image;
use glam::{DVec2, DVec3};
use mirrorball_simd::{trunc_i32, F32x4, F32x8, I32x4, I32x8, M32x4, M32x8, Taps, X8};
use rayon::prelude::*;
use std::fmt;

/// Why layers do not make an environment map.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum EnvMapError {
    /// The projection needs a different number of layers.
    LayerCount {
        /// Layers the projection has.
        expected: usize,
        /// Layers given.
        got: usize,
    },
    /// Layers differ in size or channel count.
    Mismatch,
    /// A layer has no texels.
    Empty,
}

impl fmt::Display for EnvMapError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EnvMapError::LayerCount { expected, got } => {
                write!(
                    f,
                    "the projection has {expected} layers but {got} images were given"
                )
            }
            EnvMapError::Mismatch => f.write_str("layers differ in size or channel count"),
            EnvMapError::Empty => f.write_str("an image has no texels"),
        }
    }
}

impl std::error::Error for EnvMapError {}

/// A world projection filled with linear-light texels: one [`Image`] per layer, all the same
/// size.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvMap {
    projection: Projection,
    layers: Vec<Image>,
}

/// Radiance statistics of an environment map, over the texels the projection covers.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    /// Smallest finite colour channel value.
    pub min: f32,
    /// Largest finite colour channel value.
    pub max: f32,
    /// Mean colour (RGB) over the sphere, each texel weighted by its exact solid angle.
    pub mean: [f64; 3],
    /// NaN colour values (a texel counts up to three times, once per channel; alpha is not
    /// counted): with `inf` and `negative`, what [`EnvMap::sanitize`] changes.
    pub nan: u64,
    /// Infinite colour values.
    pub inf: u64,
    /// Negative (finite) colour values.
    pub negative: u64,
    /// Solid angle the texels cover (should be the projection's covered solid angle).
    pub solid_angle: f64,
}

impl EnvMap {
    /// Wraps layers in a projection, checking their number and sizes.
    pub fn new(projection: Projection, layers: Vec<Image>) -> Result<EnvMap, EnvMapError> {
        let expected = projection.layer_count();
        if layers.len() != expected {
            return Err(EnvMapError::LayerCount {
                expected,
                got: layers.len(),
            });
        }
        let first = &layers[0];
        if first.width() == 0 || first.height() == 0 {
            return Err(EnvMapError::Empty);
        }
        if layers.iter().any(|l| {
            l.width() != first.width()
                || l.height() != first.height()
                || l.channels() != first.channels()
        }) {
            return Err(EnvMapError::Mismatch);
        }
        Ok(EnvMap { projection, layers })
    }

    /// Evaluates `f` at the centre direction of every texel, for edge `size` (see
    /// [`WorldProjection::layer_extent`]). Texels outside the covered domain get the value
    /// at the nearest covered point. Useful for analytic test environments.
    pub fn from_fn<F>(projection: Projection, size: u32, channels: usize, f: F) -> EnvMap
    where
        F: Fn(DVec3) -> [f32; 4] + Sync,
    {
        let (w, h) = projection.layer_extent(size);
        let layers = (0..projection.layer_count())
            .map(|layer| {
                let mut img = Image::new(w, h, channels);
                img.data_mut()
                    .par_chunks_mut(w as usize * channels)
                    .enumerate()
                    .for_each(|(y, row)| {
                        for x in 0..w as usize {
                            let uv = DVec2::new(
                                (x as f64 + 0.5) / w as f64,
                                (y as f64 + 0.5) / h as f64,
                            );
                            let uv = projection.nearest_covered(layer, uv);
                            let v = match projection.uv_to_dir(layer, uv) {
                                Some(d) => f(d),
                                None => [0.0; 4],
                            };
                            row[x * channels..(x + 1) * channels].copy_from_slice(&v[..channels]);
                        }
                    });
                img
            })
            .collect();
        EnvMap { projection, layers }
    }

    /// The natural edge (`size`, as [`WorldProjection::layer_extent`] takes it) of this map
    /// in projection `kind`: the power of two nearest (in ratio) to the edge that keeps this
    /// map's texels per steradian, so that cube faces are 256, 512, 1024 … and lat-longs
    /// 2:1 (1024×512, 4096×2048 …), as engines and users expect. An 8192×4096 lat-long
    /// gives 2048² cube faces.
    pub fn natural_size(&self, kind: crate::ProjectionKind) -> u32 {
        // Texels per steradian of the source, spread evenly.
        let n_src = self.width() as f64 * self.height() as f64 * self.layers.len() as f64;
        let per_sr = n_src / self.projection.covered_solid_angle();
        let dst = kind.default_projection();
        let (w1, h1) = dst.layer_extent(1024);
        let texels_1024 = w1 as f64 * h1 as f64 * dst.layer_count() as f64;
        let want = per_sr * dst.covered_solid_angle();
        let size = 1024.0 * (want / texels_1024).sqrt();
        let log2 = size.max(1.0).log2().round().clamp(0.0, 14.0);
        1 << log2 as u32
    }

    /// The projection.
    pub fn projection(&self) -> &Projection {
        &self.projection
    }
    /// The layers (cube faces in OpenGL order, paraboloid front then back).
    pub fn layers(&self) -> &[Image] {
        &self.layers
    }
    /// The layers, mutably (their sizes cannot change).
    pub fn layers_mut(&mut self) -> &mut [Image] {
        &mut self.layers
    }
    /// Gives up the layers.
    pub fn into_layers(self) -> Vec<Image> {
        self.layers
    }
    /// Width of each layer.
    pub fn width(&self) -> u32 {
        self.layers[0].width()
    }
    /// Height of each layer.
    pub fn height(&self) -> u32 {
        self.layers[0].height()
    }
    /// 3 or 4.
    pub fn channels(&self) -> usize {
        self.layers[0].channels()
    }

    /// Bilinear lookup at `(layer, uv)`, seamless across cube edges, the longitude wrap and
    /// the poles (the neighbours come from [`WorldProjection::wrap_texel`]). Writes
    /// `channels()` values to `out`.
    #[inline]
    pub fn bilinear_at(&self, layer: usize, uv: DVec2, out: &mut [f32]) {
        bilinear(&self.projection, &self.layers, layer, uv, out);
    }

    /// Bilinear lookup in direction `dir` (unit length). Directions the projection does not
    /// cover read as zero.
    pub fn sample(&self, dir: DVec3) -> [f32; 4] {
        let mut out = [0.0f32; 4];
        if let Some((layer, uv)) = self.projection.dir_to_uv(dir) {
            self.bilinear_at(layer, uv, &mut out[..self.channels()]);
        }
        out
    }

    /// Exact texel solid angles of one layer, row by row.
    pub fn solid_angles(&self, layer: usize) -> Vec<f64> {
        let (w, h) = (self.width(), self.height());
        let p = self.projection;
        (0..h)
            .into_par_iter()
            .flat_map_iter(|y| (0..w).map(move |x| p.texel_solid_angle(layer, x, y, w, h)))
            .collect()
    }

    /// Radiance statistics over the covered texels.
    pub fn stats(&self) -> Stats {
        let mut s = Stats {
            min: f32::INFINITY,
            max: f32::NEG_INFINITY,
            ..Stats::default()
        };
        let c = self.channels();
        for (layer, img) in self.layers.iter().enumerate() {
            let weights = self.solid_angles(layer);
            for (px, &w) in img.data().chunks_exact(c).zip(&weights) {
                let rgb = &px[..3];
                let nan = rgb.iter().filter(|v| v.is_nan()).count() as u64;
                let inf = rgb.iter().filter(|v| v.is_infinite()).count() as u64;
                s.nan += nan;
                s.inf += inf;
                s.negative += rgb.iter().filter(|&&v| v < 0.0 && v.is_finite()).count() as u64;
                if nan + inf > 0 {
                    continue;
                }
                if w <= 0.0 {
                    continue;
                }
                for (i, &v) in rgb.iter().enumerate() {
                    s.min = s.min.min(v);
                    s.max = s.max.max(v);
                    s.mean[i] += v as f64 * w;
                }
                s.solid_angle += w;
            }
        }
        if s.solid_angle > 0.0 {
            for m in &mut s.mean {
                *m /= s.solid_angle;
            }
        } else {
            s.min = 0.0;
            s.max = 0.0;
        }
        s
    }

    /// Replaces NaN and infinite colour values by 0 and clamps negative ones to 0. Returns
    /// how many texel values were changed.
    pub fn sanitize(&mut self) -> u64 {
        self.layers.iter_mut().map(sanitize_layer).sum()
    }
}

/// [`EnvMap::sanitize`] of one layer (or any image): NaN, infinite and negative colour
/// values set to 0; returns how many were.
pub fn sanitize_layer(img: &mut Image) -> u64 {
    let c = img.channels();
    // Blocks of texels on all cores; within a block, a select rather than a branch
    // (`v ≥ 0` is false for NaN, `v < ∞` for +∞), so the scan vectorises.
    img.data_mut()
        .par_chunks_mut(c * 16384)
        .map(|block| u64::from(sanitize_block(block, c == 4)))
        .sum::<u64>()
}

/// How many colour values of `texels` [`EnvMap::sanitize`] would change: NaN, infinite or
/// negative. `texels` are interleaved, four channels when `rgba` (the fourth, alpha, is not
/// counted) else three. A reader can count a block of texels as it decodes it, while the
/// block is still in cache, and a map found clean need not be scanned again.
///
/// ```
/// use mirrorball_core::count_invalid;
/// assert_eq!(count_invalid(&[1.0, -2.0, f32::NAN, 0.0, f32::INFINITY, 3.0], false), 3);
/// assert_eq!(count_invalid(&[1.0, 1.0, 1.0, -1.0], true), 0); // alpha is not a colour
/// ```
pub fn count_invalid(texels: &[f32], rgba: bool) -> u64 {
    texels
        .chunks(if rgba { 4 } else { 3 } * 16384)
        .map(|block| u64::from(count_block(block, rgba)))
        .sum()
}

/// Whether `x` at position `i` of a block is a valid value (`x ≥ 0` is false for NaN, `x < ∞`
/// for +∞): alpha (every fourth of an RGBA block) always is.
#[inline(always)]
fn valid(i: usize, x: f32, rgba: bool) -> bool {
    (0.0..f32::INFINITY).contains(&x) || (rgba && i % 4 == 3)
}

/// [`count_invalid`] of one block of whole texels, four values a step with lane masks (a
/// per-texel loop over three colours does not vectorise).
fn count_block(block: &[f32], rgba: bool) -> u32 {
    let quads = block.chunks_exact(4);
    // Only RGB blocks leave a remainder, and it holds no alpha.
    let mut n = quads
        .remainder()
        .iter()
        .filter(|&&x| !valid(0, x, rgba))
        .count() as u32;
    let (zero, inf) = (F32x4::splat(0.0), F32x4::splat(f32::INFINITY));
    // RGBA: the fourth lane (alpha) always passes.
    let keep = M32x4::from_bools([false, false, false, rgba]);
    for quad in quads {
        let v = F32x4::load(quad);
        let ok = (v.ge(zero) & v.lt(inf)) | keep;
        n += (ok.bitmask() ^ 0xF).count_ones();
    }
    n
}

/// [`EnvMap::sanitize`] of one block of whole texels: counted first, read only, so that a
/// valid block (nearly every one) is read once and not rewritten; fixed only where the
/// count finds something. Returns how many values it changed.
fn sanitize_block(block: &mut [f32], rgba: bool) -> u32 {
    let n = count_block(block, rgba);
    if n > 0 {
        for (i, v) in block.iter_mut().enumerate() {
            if !valid(i, *v, rgba) {
                *v = 0.0;
            }
        }
    }
    n
}

/// Where a bilinear lookup at `(u, v)` in a `w`×`h` layer reads (texel centres at
/// half-integers): its top-left texel `(x0, y0)`, which may lie outside the layer (`-1` or
/// `w - 1`, `h - 1` at the edges), and the fractions `(fx, fy)` towards `+x`, `+y`, in
/// `f32`. `floor` is taken without a libm call (x86-64's baseline has no rounding
/// instruction). Every `f32` bilinear filter in the workspace starts here, so all agree to
/// the bit on where they read.
///
/// ```
/// let (x0, y0, fx, fy) = mirrorball_core::bilinear_corner(0.5, 0.0, 4, 2);
/// assert_eq!((x0, y0), (1, -1)); // between texels 1 and 2; above the first row
/// assert_eq!((fx, fy), (0.5, 0.5));
/// ```
#[inline(always)]
pub fn bilinear_corner(u: f32, v: f32, w: u32, h: u32) -> (i32, i32, f32, f32) {
    let x = u * w as f32 - 0.5;
    let y = v * h as f32 - 0.5;
    let (xi, yi) = (trunc_i32(x), trunc_i32(y));
    let x0 = xi.wrapping_sub(((xi as f32) > x) as i32);
    let y0 = yi.wrapping_sub(((yi as f32) > y) as i32);
    (x0, y0, x - x0 as f32, y - y0 as f32)
}

/// [`bilinear_corner`] of lanes of `(u, v)`, and which lanes' 2×2 texels lie inside the
/// layer (`0 ≤ x0 < w − 1`, `0 ≤ y0 < h − 1`).
#[derive(Clone, Copy, Debug)]
pub struct CornerLanes<F, I, M> {
    /// The top-left texels' columns.
    pub x0: I,
    /// The top-left texels' rows.
    pub y0: I,
    /// The fractions towards `+x`.
    pub fx: F,
    /// The fractions towards `+y`.
    pub fy: F,
    /// The lanes whose four texels are inside the layer.
    pub inside: M,
}

/// [`bilinear_corner`]'s operations on lanes (the step down is the comparison's mask, −1
/// where set, added), written once for four and eight lanes.
macro_rules! corner_lanes {
    // Written without closures: a closure is compiled as a function of its own, without the
    // eight-lane kernel's AVX2, and its lane operations would stay calls.
    ($u:expr, $v:expr, $w:expr, $h:expr, [$($splat:tt)+], [$($splat_i:tt)+]) => {{
        let (w, h) = ($w as i32, $h as i32);
        let (cx, cy) = (
            $u * $($splat)+(w as f32) - $($splat)+(0.5),
            $v * $($splat)+(h as f32) - $($splat)+(0.5),
        );
        let (tx, ty) = (cx.trunc_i32(), cy.trunc_i32());
        let x0 = tx + tx.to_f32().gt(cx).to_i32();
        let y0 = ty + ty.to_f32().gt(cy).to_i32();
        let (fx, fy) = (cx - x0.to_f32(), cy - y0.to_f32());
        let lo = $($splat_i)+(-1);
        let inside = x0.gt(lo) & x0.lt($($splat_i)+(w - 1)) & y0.gt(lo) & y0.lt($($splat_i)+(h - 1));
        CornerLanes {
            x0,
            y0,
            fx,
            fy,
            inside,
        }
    }};
}

/// [`bilinear_corner`] of four lookups, lane by lane to the bit (tested).
#[inline(always)]
pub fn bilinear_corner4(u: F32x4, v: F32x4, w: u32, h: u32) -> CornerLanes<F32x4, I32x4, M32x4> {
    corner_lanes!(u, v, w, h, [F32x4::splat], [I32x4::splat])
}

/// [`bilinear_corner`] of eight lookups, lane by lane to the bit (tested).
#[inline(always)]
pub fn bilinear_corner8(
    x8: X8,
    u: F32x8,
    v: F32x8,
    w: u32,
    h: u32,
) -> CornerLanes<F32x8, I32x8, M32x8> {
    corner_lanes!(u, v, w, h, [x8.splat], [x8.splat_i32])
}

/// The bilinear blend of four lanes each of the 2×2 texels `a b / c d` (`a` top left):
/// `top = a + fx·(b − a)`, `bottom = c + fx·(d − c)`, `top + fy·(bottom − top)`, the
/// arithmetic of every bilinear read in the workspace ([`lerp4`] is its scalar form, to the
/// bit). `p` holds the first texel's channels from `p[0]`, the second's from `p[c]`, the
/// row below `stride` floats on; four floats are read from each, so `p` must hold
/// `stride + c + 4` (panics otherwise).
#[inline(always)]
pub fn bilinear_blend(p: &[f32], stride: usize, c: usize, fx: f32, fy: f32) -> F32x4 {
    let p = &p[..stride + c + 4];
    let (a, b) = (F32x4::load(p), F32x4::load(&p[c..]));
    let (e, f) = (F32x4::load(&p[stride..]), F32x4::load(&p[stride + c..]));
    bilinear_mix([a, b, e, f], fx, fy)
}

/// [`bilinear_blend`]'s arithmetic on its four reads `[a, b, c, d]` (top row, then bottom).
#[inline(always)]
pub fn bilinear_mix(t: [F32x4; 4], fx: f32, fy: f32) -> F32x4 {
    let [a, b, e, f] = t;
    let (vx, vy) = (F32x4::splat(fx), F32x4::splat(fy));
    let top = a + vx * (b - a);
    let bot = e + vx * (f - e);
    top + vy * (bot - top)
}

/// [`bilinear_blend`]'s four reads in any of `N` equal layers of `c`-channel texels,
/// `stride` floats a row, as [`Taps`] (the texels of a row `c` floats apart, the rows
/// `stride`): index `i` of a layer is a footprint's first float, and its reads stay inside
/// for every `i ≤ last()` (`None` where the layers cannot hold one footprint). Blend them
/// with [`bilinear_mix`]: the same bits as [`bilinear_blend`] at `&layer[i..]` (tested).
pub fn bilinear_taps<const N: usize>(
    layers: [&[f32]; N],
    stride: usize,
    c: usize,
) -> Option<Taps<'_, N>> {
    Taps::new(layers, c, stride)
}

/// `floor` as an integer without a libm call.
#[inline(always)]
fn floor_i(x: f64) -> i64 {
    let i = x as i64;
    if (i as f64) > x {
        i - 1
    } else {
        i
    }
}

/// Bilinear filtering over `layers` of `proj` at `(layer, uv)`; texel centres at
/// half-integers. Writes `out.len()` channels (at most the image's).
#[inline]
pub(crate) fn bilinear(
    proj: &Projection,
    layers: &[Image],
    layer: usize,
    uv: DVec2,
    out: &mut [f32],
) {
    match (layers[layer].channels(), out.len()) {
        (1, 1) => bilinear_n::<1>(proj, layers, layer, uv, out),
        (3, 3) => bilinear_n::<3>(proj, layers, layer, uv, out),
        (4, 4) => bilinear_n::<4>(proj, layers, layer, uv, out),
        (4, 3) => {
            let mut t = [0.0; 4];
            bilinear_n::<4>(proj, layers, layer, uv, &mut t);
            out.copy_from_slice(&t[..3]);
        }
        _ => {
            let mut t = [0.0; 3];
            bilinear_n::<3>(proj, layers, layer, uv, &mut t);
            out[..3].copy_from_slice(&t);
            out[3..].fill(1.0);
        }
    }
}

/// The four texels and weights of [`bilinear`]'s lookup at `(layer, uv)` in a map of `proj`
/// whose layers are `w`×`h`: inside the layer the 2×2 block and its bilinear weights, at an
/// edge the [`seam_taps`] (the weights in both cases `(1−fx)(1−fy), fx(1−fy), (1−fx)fy,
/// fx·fy`).
pub(crate) fn lookup_taps(
    proj: &Projection,
    layer: usize,
    (w, h): (u32, u32),
    uv: DVec2,
) -> [(usize, u32, u32, f32); 4] {
    let x = uv.x * w as f64 - 0.5;
    let y = uv.y * h as f64 - 0.5;
    let (x0, y0) = (floor_i(x), floor_i(y));
    let (fx, fy) = ((x - x0 as f64) as f32, (y - y0 as f64) as f32);
    seam_taps(proj, layer, (w, h), (x0, y0), (fx, fy))
}

/// [`bilinear`] at `f32` coordinates for `C`-channel images, for the conversion's batch path.
#[inline(always)]
pub(crate) fn bilinear32<const C: usize>(
    proj: &Projection,
    layers: &[Image],
    layer: usize,
    u: f32,
    v: f32,
    out: &mut [f32],
) {
    let q = bilinear32_quad::<C>(proj, layers, layer, u, v);
    out[..C].copy_from_slice(&q[..C]);
}

/// [`bilinear32`] as four lanes: the `C` channels, then (for `C = 3`) a lane to ignore,
/// so that callers can go on with four-lane arithmetic (the resampler's weighted sums).
#[inline(always)]
pub(crate) fn bilinear32_quad<const C: usize>(
    proj: &Projection,
    layers: &[Image],
    layer: usize,
    u: f32,
    v: f32,
) -> [f32; 4] {
    let img = &layers[layer];
    let (x0, y0, fx, fy) = bilinear_corner(u, v, img.width(), img.height());
    let (w, h) = (img.width() as i32, img.height() as i32);
    let mut out = [0.0f32; 4];
    if x0 >= 0 && y0 >= 0 && x0 + 1 < w && y0 + 1 < h {
        let data = img.data();
        let stride = w as usize * C;
        let i00 = y0 as usize * stride + x0 as usize * C;
        if let Some(q) = lerp_quad::<C>(data, i00, stride, fx, fy) {
            return q;
        }
        if let (Some(r0), Some(r1)) = (
            data.get(i00..i00 + 2 * C),
            data.get(i00 + stride..i00 + stride + 2 * C),
        ) {
            lerp4::<C>(r0, r1, fx, fy, &mut out[..C]);
            return out;
        }
    }
    bilinear(
        proj,
        layers,
        layer,
        DVec2::new(u as f64, v as f64),
        &mut out[..C],
    );
    out
}

/// Bilinear blend of the 2×2 texels of `C` channels whose top-left texel starts at float
/// `i` of `data` (rows `stride` floats apart), as four lanes: the `C` channels, then (for
/// `C = 3`) a lane to ignore. `None` when a four-float read would pass the end of `data`
/// (the last texels of an image), where [`lerp4`] serves. [`bilinear_blend`]: the same
/// arithmetic as [`lerp4`], so results agree to the bit.
#[inline(always)]
pub(crate) fn lerp_quad<const C: usize>(
    data: &[f32],
    i: usize,
    stride: usize,
    fx: f32,
    fy: f32,
) -> Option<[f32; 4]> {
    let p = data.get(i..i.checked_add(stride + C + 4)?)?;
    Some(bilinear_blend(p, stride, C, fx, fy).to_array())
}

/// Bilinear blend of two rows of two `C`-channel texels.
#[inline(always)]
pub(crate) fn lerp4<const C: usize>(r0: &[f32], r1: &[f32], fx: f32, fy: f32, out: &mut [f32]) {
    let out = &mut out[..C];
    for i in 0..C {
        let top = r0[i] + fx * (r0[C + i] - r0[i]);
        let bot = r1[i] + fx * (r1[C + i] - r1[i]);
        out[i] = top + fy * (bot - top);
    }
}

/// [`bilinear`] for images of `C` channels.
#[inline(always)]
fn bilinear_n<const C: usize>(
    proj: &Projection,
    layers: &[Image],
    layer: usize,
    uv: DVec2,
    out: &mut [f32],
) {
    let (w, h) = (layers[layer].width(), layers[layer].height());
    let v = bilinear_read::<C>(proj, (w, h), layer, uv, |l, x, y| {
        layers[l].get(x, y).try_into().expect("C channels")
    });
    out[..C].copy_from_slice(&v);
}

/// The arithmetic of every bilinear lookup at `(layer, uv)` of a map of `proj` whose layers
/// are `w`×`h` texels, the texels read through `texel(layer, x, y)`: inside the layer, the
/// top and bottom pairs blended across and then down; at an edge, the four
/// [`seam_taps`] summed with their weights, in order.
#[inline(always)]
fn bilinear_read<const C: usize>(
    proj: &Projection,
    (w, h): (u32, u32),
    layer: usize,
    uv: DVec2,
    mut texel: impl FnMut(usize, u32, u32) -> [f32; C],
) -> [f32; C] {
    let x = uv.x * w as f64 - 0.5;
    let y = uv.y * h as f64 - 0.5;
    let (x0, y0) = (floor_i(x), floor_i(y));
    let (fx, fy) = ((x - x0 as f64) as f32, (y - y0 as f64) as f32);
    let mut out = [0.0f32; C];
    if x0 >= 0 && y0 >= 0 && x0 + 1 < w as i64 && y0 + 1 < h as i64 {
        let (x0, y0) = (x0 as u32, y0 as u32);
        let (a, b) = (texel(layer, x0, y0), texel(layer, x0 + 1, y0));
        let (e, f) = (texel(layer, x0, y0 + 1), texel(layer, x0 + 1, y0 + 1));
        for i in 0..C {
            let top = a[i] + fx * (b[i] - a[i]);
            let bot = e[i] + fx * (f[i] - e[i]);
            out[i] = top + fy * (bot - top);
        }
        return out;
    }
    for (l, tx, ty, wt) in seam_taps(proj, layer, (w, h), (x0, y0), (fx, fy)) {
        let t = texel(l, tx, ty);
        for i in 0..C {
            out[i] += wt * t[i];
        }
    }
    out
}

/// [`EnvMap::sample`] of a map of `proj` with `w`×`h`-texel layers whose `C`-channel
/// texels are read through `texel(layer, x, y)` rather than held in layers: the same texels
/// read, in the same order, blended with the same arithmetic, so the same bits as `sample`
/// of a map that holds them (tested). For a caller that holds only the few texels some
/// lookups read (a packed frame's border, made from its faces' edges), or that wants to
/// know which texels those are (a `texel` that records its arguments). Directions the
/// projection does not cover read as zero, reading nothing.
///
/// ```
/// use mirrorball_core::{sample_texels, EnvMap, ProjectionKind};
/// use mirrorball_core::glam::DVec3;
/// let cube = ProjectionKind::Cube.default_projection();
/// let env = EnvMap::from_fn(cube, 8, 3, |d| [d.x as f32, d.y as f32, d.z as f32, 1.0]);
/// let d = DVec3::new(1.0, 0.999, 0.3).normalize(); // next to an edge: across the seam
/// let mut read = Vec::new();
/// let v = sample_texels::<3>(&cube, (8, 8), d, |l, x, y| {
///     read.push((l, x, y));
///     env.layers()[l].get(x, y).try_into().unwrap()
/// });
/// assert_eq!(v, env.sample(d)[..3]);
/// assert_eq!(read.len(), 4);
/// ```
pub fn sample_texels<const C: usize>(
    proj: &Projection,
    (w, h): (u32, u32),
    dir: DVec3,
    texel: impl FnMut(usize, u32, u32) -> [f32; C],
) -> [f32; C] {
    match proj.dir_to_uv(dir) {
        Some((layer, uv)) => bilinear_read::<C>(proj, (w, h), layer, uv, texel),
        None => [0.0; C],
    }
}

/// The four texels and weights of a bilinear lookup whose top-left texel `(x0, y0)` (with
/// fractions `(fx, fy)`) may lie outside the `w`×`h` layer `layer`: each corner outside is
/// moved to where it really is, across a cube edge, around the longitude wrap or over a
/// pole ([`WorldProjection::wrap_texel`]).
#[inline]
pub(crate) fn seam_taps(
    proj: &Projection,
    layer: usize,
    (w, h): (u32, u32),
    (x0, y0): (i64, i64),
    (fx, fy): (f32, f32),
) -> [(usize, u32, u32, f32); 4] {
    let weights = [
        (1.0 - fx) * (1.0 - fy),
        fx * (1.0 - fy),
        (1.0 - fx) * fy,
        fx * fy,
    ];
    let corners = [(x0, y0), (x0 + 1, y0), (x0, y0 + 1), (x0 + 1, y0 + 1)];
    std::array::from_fn(|k| {
        let (cx, cy) = corners[k];
        let (l, tx, ty) = if cx >= 0 && cy >= 0 && cx < w as i64 && cy < h as i64 {
            (layer, cx as u32, cy as u32)
        } else {
            proj.wrap_texel(layer, cx, cy, w, h)
        };
        (l, tx, ty, weights[k])
    })
}
