//! The hot loop for one sample per pixel without diagnostic channels (modes 2 and 3 with a
//! mirror read straight from a cube, and everything else through [`Prepared::shade`]):
//! square tiles of a band, each tile row in passes (directions, texel addresses, reads).

use super::prepare::Prepared;
use crate::fast::{CubeFaces, CubeLoc};
use crate::mirror::{MirrorSetup, MirrorView};
use crate::raster::{Binned, NO_HIT};
use crate::scene::{Attach, Filter, Indexing, Material};
use glam::{Vec3, Vec3A};
use rayon::prelude::*;

/// Columns of the square tiles the hot loop walks (a band is as many rows).
const TILE: usize = crate::mirror::SPAN;

/// A band's visibility, as the fast loop reads it.
pub(super) struct BandVis<'a> {
    pub binned: &'a Binned,
    /// Depth and setup id per sample.
    pub depth: &'a [f32],
    pub ids: &'a [u32],
    /// The columns outside which the band has no hit.
    pub cols: std::ops::Range<usize>,
    /// Per setup, when the per-pixel mirror applies.
    pub mirrors: Option<&'a [MirrorSetup]>,
}

/// What a pixel of a tile row needs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
enum Need {
    /// Nothing: transparent black.
    Skip = 0,
    /// An environment lookup along its direction in `dirs`, times its `tint`.
    Lookup = 1,
    /// Its colour, already in `tint`.
    Done = 2,
}

/// What every tile row of a band shares.
struct FastBand<'a> {
    w: usize,
    cube: Option<CubeFaces<'a>>,
    intensity: f32,
    background: bool,
    /// The background is a plain lookup along the view ray (not blurred, not filtered over
    /// the pixel's footprint).
    plain_bg: bool,
    /// Perspective background rays made a component array at a time: `perspective_parts`.
    batch_bg: Option<(Vec3, Vec3, Vec3)>,
    view: MirrorView,
}

/// A tile row's scratch: per pixel its need, direction (a component array at a time),
/// tint, cube location, and background ray.
struct RowScratch {
    need: [Need; TILE],
    dirs: [[f32; TILE]; 3],
    tint: [[f32; 3]; TILE],
    locs: [CubeLoc; TILE],
    bg: [[f32; TILE]; 3],
}

/// One tile row: its sample row `sy` (centre `fy`), first column `xb`, setup ids, and the
/// band row `ly` they are in.
struct TileRow<'a> {
    ly: usize,
    sy: u32,
    fy: f32,
    xb: usize,
    ids: &'a [u32],
}

impl Prepared<'_> {
    /// The per-pixel mirror's [`MirrorSetup`] of every setup of `binned`, or `None` where
    /// the fast loop does not read it (another mode, or a footprint sampler).
    pub(super) fn mirror_setups(&self, binned: &Binned) -> Option<Vec<MirrorSetup>> {
        // Mode 2 interpolates the per-vertex reflected vectors the same way (in `v`).
        let per_vertex = self.settings.indexing == Indexing::PerVertexReflection;
        if !(self.settings.indexing == Indexing::PerPixel || per_vertex) || self.sampler.is_some() {
            return None;
        }
        let persp = self.cam.is_perspective();
        let eye = self.cam.eye;
        Some(
            (0..binned.setup_count() as u32)
                .into_par_iter()
                .map(|id| {
                    let (tri, ob, scale) = binned.corners(id);
                    let material = &self.materials[self.tri_mat[tri as usize] as usize];
                    let [i0, i1, i2] = self.tris[tri as usize].map(|i| i as usize);
                    let at = |a: &[Vec3], k: usize| {
                        let b = ob[k];
                        Vec3A::from(a[i0] * b.x + a[i1] * b.y + a[i2] * b.z) * scale[k]
                    };
                    let rel: [Vec3; 3] = [i0, i1, i2].map(|i| self.pos[i] - eye);
                    let v = |k: usize| {
                        let b = ob[k];
                        Vec3A::from(rel[0] * b.x + rel[1] * b.y + rel[2] * b.z) * scale[k]
                    };
                    let (mirror, tint) = match material {
                        Material::Mirror { tint } => (true, *tint),
                        _ => (false, [0.0; 3]),
                    };
                    MirrorSetup::new(
                        binned.edges(id),
                        [0, 1, 2].map(|k| at(&self.nrm, k)),
                        if per_vertex {
                            [0, 1, 2].map(|k| at(&self.r_vert, k))
                        } else if persp {
                            [0, 1, 2].map(v)
                        } else {
                            [Vec3A::ZERO; 3]
                        },
                        tint,
                        mirror,
                    )
                })
                .collect(),
        )
    }

    /// Colour and coverage of the band of pixel rows starting at row `y0`, one sample a
    /// pixel, no diagnostic channels (`vis` holds its samples, `out` its RGBA pixels, every
    /// one written here). Background rays are computed a tile row at a time, and a
    /// per-pixel mirror reads a cube map directly; what this loop does not specialise goes
    /// through [`Prepared::shade`]. Allocates nothing.
    pub(super) fn shade_band_fast(&self, y0: u32, vis: &BandVis, out: &mut [f32]) {
        let band = self.fast_band();
        let w = band.w;
        let rows = vis.ids.len() / w;
        let mut scratch = RowScratch {
            need: [Need::Skip; TILE],
            dirs: [[0.0; TILE]; 3],
            tint: [[1.0; 3]; TILE],
            locs: [CubeLoc::NONE; TILE],
            bg: [[0.0; TILE]; 3],
        };
        // Square tiles of the band, column block by column block: neighbouring pixels read
        // neighbouring texels. Each row of a tile is shaded in three passes: directions,
        // then every texel address (prefetched, so the cache misses of a minified mirror
        // overlap instead of queueing one after the other), then the bilinear reads.
        for xb in (0..w).step_by(TILE) {
            let xe = (xb + TILE).min(w);
            for ly in 0..rows {
                let sy = y0 + ly as u32;
                let row = TileRow {
                    ly,
                    sy,
                    fy: sy as f32 + 0.5,
                    xb,
                    ids: &vis.ids[ly * w + xb..ly * w + xe],
                };
                let orow = &mut out[(ly * w + xb) * 4..(ly * w + xe) * 4];
                let beside = xe <= vis.cols.start || vis.cols.end <= xb;
                if !band.background && (beside || row.ids.iter().all(|&id| id == NO_HIT)) {
                    orow.fill(0.0); // transparent black
                    continue;
                }
                if self.mirror_tile_row(&band, vis, &row, orow) {
                    continue;
                }
                self.background_rays(&band, &row, &mut scratch.bg);
                let mirror_lanes = self.classify(&band, vis, &row, &mut scratch);
                if let (Some(m), true) = (vis.mirrors, mirror_lanes != 0) {
                    let (ids, xb, fy) = (row.ids, row.xb, row.fy);
                    crate::mirror::mirror_dirs(
                        ids,
                        mirror_lanes,
                        xb,
                        fy,
                        m,
                        &band.view,
                        &mut scratch.dirs,
                    );
                }
                locate_row(&band, row.ids.len(), &mut scratch);
                self.fetch_row(&band, &scratch, orow);
            }
        }
    }

    /// What the band's tile rows share.
    #[inline(always)]
    fn fast_band(&self) -> FastBand<'_> {
        let env = self.scene.environment.as_ref();
        let eye_attached = env.is_some_and(|e| e.attach == Attach::Eye);
        let background = self.scene.background;
        // The background is a plain lookup along the view ray unless it is blurred or
        // filtered over the pixel's footprint (a footprint sampler: trilinear, EWA, mode 4).
        let plain_bg = background && self.prev_rays.is_none() && self.sampler.is_none();
        FastBand {
            w: self.cam.width as usize,
            cube: env
                .filter(|e| e.filter == Filter::Bilinear)
                .and_then(|e| CubeFaces::new(&e.map)),
            intensity: env.map_or(1.0, |e| e.intensity),
            background,
            plain_bg,
            // Background rays of a segment, as `background` computes them (normalised,
            // then attached and normalised again: a blurred frame of a still camera must
            // equal the sharp one bit for bit), but a component array at a time, so the
            // square roots and divisions vectorise.
            batch_bg: match self.rays.perspective_parts() {
                Some(parts) if plain_bg && !eye_attached => Some(parts),
                _ => None,
            },
            // A per-pixel mirror is one lookup along the reflected ray unless a footprint
            // sampler filters it over the pixel's corners: then `vis.mirrors` holds its
            // setups.
            view: MirrorView {
                persp: self.cam.is_perspective(),
                forward: Vec3A::from(self.forward),
                rot: eye_attached.then_some(self.view_rot),
                per_vertex: self.settings.indexing == Indexing::PerVertexReflection,
            },
        }
    }

    /// A mirror-only tile row without background, eight pixels a step where it can
    /// ([`crate::mirror::mirror_row`]), its other pixels shaded one by one; `false` where
    /// it does not apply, having done nothing.
    #[inline(always)]
    fn mirror_tile_row(
        &self,
        band: &FastBand,
        vis: &BandVis,
        row: &TileRow,
        orow: &mut [f32],
    ) -> bool {
        let (Some(m), Some(cf), false, true) = (
            vis.mirrors,
            &band.cube,
            band.background,
            band.intensity == 1.0,
        ) else {
            return false;
        };
        let Some(mut left) =
            crate::mirror::mirror_row(row.ids, row.xb, row.fy, m, &band.view, cf, orow)
        else {
            return false;
        };
        while left != 0 {
            let i = left.trailing_zeros() as usize;
            left &= left - 1;
            let x = row.xb + i;
            let s = vis
                .binned
                .sample(row.ids[i], vis.depth[row.ly * band.w + x], x as u32, row.sy);
            let c = self.shade(x as u32, row.sy, s).color;
            orow[i * 4..i * 4 + 4].copy_from_slice(&[c[0], c[1], c[2], 1.0]);
        }
        true
    }

    /// The tile row's background rays, a component array at a time, where they are batched.
    #[inline(always)]
    fn background_rays(&self, band: &FastBand, row: &TileRow, bg: &mut [[f32; TILE]; 3]) {
        let Some((f, r, u)) = band.batch_bg else {
            return;
        };
        let (sw, sh) = (self.sw as f32, self.sh as f32);
        let yn = 1.0 - 2.0 * row.fy / sh;
        let uy = u * yn;
        let [bx, by, bz] = bg;
        for (i, ((bx, by), bz)) in bx.iter_mut().zip(by).zip(bz).enumerate() {
            let xn = 2.0 * ((row.xb + i) as f32 + 0.5) / sw - 1.0;
            let x = f.x + r.x * xn + uy.x;
            let y = f.y + r.y * xn + uy.y;
            let z = f.z + r.z * xn + uy.z;
            let k = 1.0 / (x * x + y * y + z * z).sqrt();
            let (x, y, z) = (x * k, y * k, z * k);
            let k = 1.0 / (x * x + y * y + z * z).sqrt();
            let ok = k.is_finite() && k > 0.0;
            *bx = if ok { x * k } else { 0.0 };
            *by = if ok { y * k } else { 0.0 };
            *bz = if ok { z * k } else { 0.0 };
        }
    }

    /// Each pixel's [`Need`]: background pixels get their ray (or colour), pixels of other
    /// materials are shaded here; returns the pixels whose setup is a mirror (their
    /// directions come after, from [`crate::mirror::mirror_dirs`]).
    #[inline(always)]
    fn classify(&self, band: &FastBand, vis: &BandVis, row: &TileRow, sc: &mut RowScratch) -> u32 {
        let mut mirror_lanes = 0u32;
        for (i, &id) in row.ids.iter().enumerate() {
            let x = row.xb + i;
            let fx = x as f32 + 0.5;
            sc.need[i] = Need::Lookup;
            if id == NO_HIT {
                sc.tint[i] = [1.0; 3];
                if !band.background {
                    sc.need[i] = Need::Skip;
                } else if band.batch_bg.is_some() {
                    for (d, b) in sc.dirs.iter_mut().zip(&sc.bg) {
                        d[i] = b[i];
                    }
                } else if band.plain_bg {
                    // Exactly as `background` computes it (a blurred frame of a still
                    // camera must equal the sharp one bit for bit).
                    let (x, y) = self.ndc(fx, row.fy);
                    let r = self.attach32(self.rays.ray(x, y).1);
                    (sc.dirs[0][i], sc.dirs[1][i], sc.dirs[2][i]) = (r.x, r.y, r.z);
                } else {
                    sc.need[i] = Need::Done;
                    sc.tint[i] = self.background(fx, row.fy).color;
                }
                continue;
            }
            match vis.mirrors.map(|m| &m[id as usize]) {
                Some(m) if m.mirror => {
                    mirror_lanes |= 1 << i;
                    sc.tint[i] = m.tint;
                }
                _ => {
                    sc.need[i] = Need::Done;
                    let k = row.ly * band.w + x;
                    let s = vis.binned.sample(id, vis.depth[k], x as u32, row.sy);
                    sc.tint[i] = self.shade(x as u32, row.sy, s).color;
                }
            }
        }
        mirror_lanes
    }

    /// Each pixel's colour into `orow`, from its need (the cube reads at the located
    /// texels, or the environment's own lookup).
    #[inline(always)]
    fn fetch_row(&self, band: &FastBand, sc: &RowScratch, orow: &mut [f32]) {
        let intensity = band.intensity;
        for (i, o) in orow.chunks_exact_mut(4).enumerate() {
            let c = match sc.need[i] {
                Need::Skip => [0.0; 4],
                Need::Done => [sc.tint[i][0], sc.tint[i][1], sc.tint[i][2], 1.0],
                Need::Lookup => {
                    let t = sc.tint[i];
                    match &band.cube {
                        Some(cf) if intensity == 1.0 => {
                            cf.fetch_tinted(&sc.locs[i], [t[0], t[1], t[2], 1.0])
                        }
                        _ => {
                            let e = match &band.cube {
                                Some(cf) => cf.fetch(&sc.locs[i]).map(|c| c * intensity),
                                None => self.read_dir32(dir(&sc.dirs, i)).0,
                            };
                            [e[0] * t[0], e[1] * t[1], e[2] * t[2], 1.0]
                        }
                    }
                }
            };
            o.copy_from_slice(&c);
        }
    }
}

/// Pixel `i`'s direction.
#[inline(always)]
fn dir(dirs: &[[f32; TILE]; 3], i: usize) -> Vec3 {
    Vec3::new(dirs[0][i], dirs[1][i], dirs[2][i])
}

/// The cube texels the first `n` pixels of the row look up (four at a time where a lane
/// needs it; a lane that does not is located and ignored).
#[inline(always)]
fn locate_row(band: &FastBand, n: usize, sc: &mut RowScratch) {
    let Some(cf) = &band.cube else {
        return;
    };
    let mut i = 0;
    while i + 4 <= n {
        if sc.need[i..i + 4].contains(&Need::Lookup) {
            let d = |c: usize| -> &[f32; 4] { sc.dirs[c][i..i + 4].try_into().unwrap() };
            let l = cf.locate4(d(0), d(1), d(2));
            sc.locs[i..i + 4].copy_from_slice(&l);
        }
        i += 4;
    }
    for i in i..n {
        if sc.need[i] == Need::Lookup {
            sc.locs[i] = cf.locate(dir(&sc.dirs, i));
        }
    }
}
