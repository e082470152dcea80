//! Conversion between any two projections, antialiased.
//!
//! For each output texel the ratio `r` of its solid angle to that of the source texels under
//! it (from the two projections' exact area elements) decides the filter:
//!
//! * `r < 4` (the output texel spans less than two source texels each way): one bilinear
//!   lookup at the texel centre, seamless across cube edges, the longitude wrap and poles.
//!   Bilinear weights are a tent two texels wide, so up to a 2× linear minification every
//!   source texel still contributes (the rule by which GPUs stay on mip level 0 until the
//!   footprint exceeds two texels);
//! * otherwise the output texel is integrated: an `n×n` grid of points over the texel
//!   (`n ≈ √r`, at most [`ResampleOptions::max_samples`]), each weighted by its solid angle
//!   and looked up bilinearly, on a solid-angle-weighted mip level of the source once `r`
//!   exceeds `n_max²`, so that each point stands for about one source texel.
//!
//! The work runs in parallel over rows with rayon and allocates nothing per texel.

use crate::codes::{CodeKind, CodeWidth, Narrow, Wide};
use crate::envmap::{bilinear32, bilinear32_quad, bilinear_corner, bilinear_corner4, lerp_quad};
use crate::projection::{DirRun, Lookup, OverlapBlend, Projection, WorldProjection};
use crate::{Codes, EnvMap, Image, Plane};
use glam::{DMat3, DVec3};
use mirrorball_simd::{prefetch as prefetch_line, F32x4, M32x4};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// A world axis, named `x`, `y` or `z`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Axis {
    /// +X, to the right.
    X = 0,
    /// +Y, up.
    Y = 1,
    /// +Z, towards the viewer.
    Z = 2,
}

impl crate::Choice for Axis {
    const NAMES: &'static [(Self, &'static [&'static str])] =
        &[(Axis::X, &["x"]), (Axis::Y, &["y"]), (Axis::Z, &["z"])];
}
crate::choice_traits!(Axis);

/// An orthogonal transform of the environment (a rotation, or a mirroring to switch
/// handedness conventions): the output shows the source turned by it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rotation {
    /// Maps an output direction to the source direction it shows (the inverse transform).
    to_source: DMat3,
}

impl Default for Rotation {
    fn default() -> Self {
        Rotation {
            to_source: DMat3::IDENTITY,
        }
    }
}

impl Rotation {
    /// Turns the environment by `yaw` about +Y, then `pitch` about +X, then `roll` about −Z
    /// (degrees; positive yaw turns what was straight ahead, −Z, towards −X, i.e. to the
    /// left).
    ///
    /// ```
    /// use mirrorball_core::Rotation;
    /// use glam::DVec3;
    /// let r = Rotation::from_euler_deg(90.0, 0.0, 0.0);
    /// // After turning 90° left, what was ahead (-Z) is seen at -X:
    /// assert!((r.source_of(DVec3::NEG_X) - DVec3::NEG_Z).length() < 1e-12);
    /// ```
    pub fn from_euler_deg(yaw: f64, pitch: f64, roll: f64) -> Rotation {
        let m = DMat3::from_rotation_y(yaw.to_radians())
            * DMat3::from_rotation_x(pitch.to_radians())
            * DMat3::from_rotation_z(-roll.to_radians());
        Rotation {
            to_source: m.transpose(),
        }
    }

    /// A general orthogonal transform (forward: source direction → output direction).
    /// `None` unless `m` is orthogonal to 1e-6.
    pub fn from_matrix(m: DMat3) -> Option<Rotation> {
        let e = (m.transpose() * m - DMat3::IDENTITY).to_cols_array();
        if e.iter().any(|v| v.abs() > 1e-6 || !v.is_finite()) {
            return None;
        }
        Some(Rotation {
            to_source: m.transpose(),
        })
    }

    /// Mirrors the environment across the plane through the origin normal to `axis`: for
    /// example z, to go between right- and left-handed worlds.
    ///
    /// ```
    /// use mirrorball_core::{Axis, Rotation};
    /// use glam::DVec3;
    /// let r = Rotation::mirror(Axis::Z);
    /// assert_eq!(r.source_of(DVec3::new(0.6, 0.0, 0.8)), DVec3::new(0.6, 0.0, -0.8));
    /// ```
    pub fn mirror(axis: Axis) -> Rotation {
        let mut d = DVec3::ONE;
        d[axis as usize] = -1.0;
        Rotation {
            to_source: DMat3::from_diagonal(d),
        }
    }

    /// First `self`, then `then`.
    pub fn then(self, then: Rotation) -> Rotation {
        Rotation {
            to_source: self.to_source * then.to_source,
        }
    }

    /// The source direction seen at output direction `d`.
    #[inline]
    pub fn source_of(&self, d: DVec3) -> DVec3 {
        self.to_source * d
    }

    /// Whether this is the identity.
    pub fn is_identity(&self) -> bool {
        self.to_source == DMat3::IDENTITY
    }
}

/// Options for [`resample`].
#[derive(Clone, Debug)]
pub struct ResampleOptions {
    /// Turn (or mirror) the environment.
    pub rotation: Rotation,
    /// Exposure in stops: texels are multiplied by `2^exposure`.
    pub exposure: f32,
    /// Most points per axis when integrating one output texel (default 8; 1 turns
    /// integration off and leaves plain bilinear interpolation). Footprints of up to its
    /// square in source texels are integrated on the source itself, larger ones on a mip
    /// level; a level's 2×2 boxes blur what a grid of points on the source keeps, so 8
    /// scores 9 dB above 4 against the exact box filter where footprints cover 16 to 64
    /// source texels (a zone plate shrunk to a 128² or a 64² cube: 41.4 against 31.9 dB,
    /// `tests/cli/zoneplate.rs`), for about 10–20% more time on such shrinks.
    pub max_samples: u32,
    /// Counts finished output rows, for progress bars.
    pub progress: Option<Arc<AtomicU64>>,
    /// What each finished row adds to [`progress`](Self::progress): 1 (rows) by default;
    /// a bar that counts work in other units gives a row's cost.
    pub progress_unit: u64,
    /// What the output's texels outside its covered domain hold; `None`: the output
    /// projection's rule ([`ProjectionKind::outside`](crate::ProjectionKind::outside)).
    pub outside: Option<Outside>,
}

/// What an output's texels outside the projection's covered domain hold: the corners of a
/// disk map, the outside of a world map's outline, a fisheye's surround.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Outside {
    /// The nearest covered point's value, so that filtering near the rim never pulls in
    /// black: for maps a renderer samples (sphere, angular and paraboloid maps).
    Rim,
    /// Zero (and zero alpha): for pictures people look at and cameras' frames (fisheye,
    /// dual fisheye, Hammer, sinusoidal), as FFmpeg's `v360` and dome masters leave them.
    Black,
}

impl crate::Choice for Outside {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (Outside::Rim, &["rim", "extend", "nearest"]),
        (Outside::Black, &["black", "zero", "transparent"]),
    ];
}
crate::choice_traits!(Outside);

impl Default for ResampleOptions {
    fn default() -> Self {
        ResampleOptions {
            rotation: Rotation::default(),
            exposure: 0.0,
            max_samples: 8,
            progress: None,
            progress_unit: 1,
            outside: None,
        }
    }
}

/// Below this footprint ratio (2× linear minification) one bilinear lookup is used.
const BILINEAR_MAX_RATIO: f64 = 4.0;

/// A source map with its solid-angle-weighted mip pyramid (only as deep as needed), for the
/// resampler's lookups alone: each 2×2 block weighted by the density at the texel centres
/// (cheap, and exact enough for a bilinear read). `mirrorball-filter`'s `MipChain` is the
/// public, energy-exact pyramid (exact texel solid angles, odd sizes split fractionally).
///
/// Its base is the source's layers, or what the plan's [`OverlapBlend`] makes of them (a
/// dual fisheye's overlap blended): every lookup of the resampler and of `Remap` reads here,
/// so the blend reaches them all and no other projection's reads change.
pub(crate) struct Pyramid<'a> {
    base: std::borrow::Cow<'a, [Image]>,
    levels: Vec<Vec<Image>>,
}

/// A pyramid's memory, given back by [`Pyramid::take_spare`] for the next source of the
/// same shape to fill: the blended base (where the projection blends) and the levels.
#[derive(Default)]
pub(crate) struct PyramidSpare {
    base: Vec<Image>,
    levels: Vec<Vec<Image>>,
}

impl<'a> Pyramid<'a> {
    pub(crate) fn new(src: &'a EnvMap, depth: usize) -> Pyramid<'a> {
        let plan = PyramidPlan::new(
            src.projection(),
            (src.width(), src.height()),
            src.layers().len(),
            depth,
        );
        Pyramid::planned(src, &plan, PyramidSpare::default())
    }

    /// The pyramid of `src` with `plan`'s blend and block weights (made for `src`'s
    /// projection and size), filling the images of `spare` (an earlier pyramid's, from
    /// [`Pyramid::take_spare`]) where their shapes fit, so that a frame loop allocates
    /// nothing.
    pub(crate) fn planned(src: &'a EnvMap, plan: &PyramidPlan, spare: PyramidSpare) -> Pyramid<'a> {
        let base = match &plan.blend {
            Some(blend) => {
                let mut base = spare.base;
                base.truncate(1);
                if base.is_empty() {
                    base.push(Image::new(0, 0, src.channels()));
                }
                blend.apply_into(&src.layers()[0], &mut base[0]);
                std::borrow::Cow::Owned(base)
            }
            None => std::borrow::Cow::Borrowed(src.layers()),
        };
        Pyramid::build(base, None, None, plan, spare.levels)
    }

    /// [`Pyramid::planned`] of a one-layer source held as codes: the levels below the base
    /// (the first made from the codes through their table, so the same bits as from the
    /// float layer they decode to); the base itself is not kept (empty), its reads being
    /// the codes' own.
    pub(crate) fn planned_codes(
        src: Codes<'_>,
        plan: &PyramidPlan,
        spare: PyramidSpare,
    ) -> Pyramid<'a> {
        Pyramid::build(
            std::borrow::Cow::Owned(Vec::new()),
            Some(src),
            None,
            plan,
            spare.levels,
        )
    }

    /// [`Pyramid::planned_codes`] of a one-layer, one-channel source held as a plane's
    /// codes: the first level made from the plane's values, so the same bits as from the
    /// float layer of them; the base not kept.
    pub(crate) fn planned_plane(
        src: Plane<'_>,
        plan: &PyramidPlan,
        spare: PyramidSpare,
    ) -> Pyramid<'a> {
        Pyramid::build(
            std::borrow::Cow::Owned(Vec::new()),
            None,
            Some(src),
            plan,
            spare.levels,
        )
    }

    fn build(
        base: std::borrow::Cow<'a, [Image]>,
        codes: Option<Codes<'_>>,
        plane: Option<Plane<'_>>,
        plan: &PyramidPlan,
        mut spare: Vec<Vec<Image>>,
    ) -> Pyramid<'a> {
        spare.truncate(plan.levels.len());
        let mut levels: Vec<Vec<Image>> = Vec::with_capacity(plan.levels.len());
        let mut spare = spare.into_iter();
        for weights in &plan.levels {
            let prev = levels.last().map(|l| l.as_slice());
            let mut next = spare.next().unwrap_or_default();
            // What this level halves: the level above, or the base (its float layers, or
            // the codes' one layer).
            let shapes: Vec<(u32, u32, usize)> = match (prev, codes) {
                (Some(p), _) => p
                    .iter()
                    .map(|i| (i.width(), i.height(), i.channels()))
                    .collect(),
                (None, Some(c)) => vec![(c.extent().0, c.extent().1, 3)],
                (None, None) if plane.is_some() => plane
                    .map(|p| (p.extent().0, p.extent().1, 1))
                    .into_iter()
                    .collect(),
                (None, None) => base
                    .iter()
                    .map(|i| (i.width(), i.height(), i.channels()))
                    .collect(),
            };
            next.truncate(shapes.len());
            for (layer, (&(w, h, c), wts)) in shapes.iter().zip(weights).enumerate() {
                let (nw, nh) = half_extent(w, h);
                let fits = next
                    .get(layer)
                    .is_some_and(|o: &Image| (o.width(), o.height(), o.channels()) == (nw, nh, c));
                if !fits {
                    next.truncate(layer);
                    next.push(Image::new(nw, nh, c));
                }
                let out = &mut next[layer];
                match (prev, codes) {
                    (Some(p), _) => downsample_into(&p[layer], wts, out),
                    (None, Some(cd)) => match cd.kind() {
                        CodeKind::Wide => {
                            let t = Wide::table(cd.table());
                            downsample_texels((w, h), |i| Wide::texel(cd.bytes(), t, i), wts, out)
                        }
                        CodeKind::Narrow => {
                            let t = Narrow::table(cd.table());
                            downsample_texels((w, h), |i| Narrow::texel(cd.bytes(), t, i), wts, out)
                        }
                        CodeKind::Float => {
                            let f = cd.floats();
                            downsample_texels(
                                (w, h),
                                |i| [f[3 * i], f[3 * i + 1], f[3 * i + 2]],
                                wts,
                                out,
                            )
                        }
                    },
                    (None, None) => match plane {
                        Some(p) => downsample_texels((w, h), |i| [p.value(i)], wts, out),
                        None => downsample_into(&base[layer], wts, out),
                    },
                }
            }
            levels.push(next);
        }
        Pyramid { base, levels }
    }

    /// The pyramid's memory (its levels, and its base where it made one), taken out for
    /// [`Pyramid::planned`] to fill again.
    pub(crate) fn take_spare(&mut self) -> PyramidSpare {
        let base = match std::mem::take(&mut self.base) {
            std::borrow::Cow::Owned(b) => b,
            std::borrow::Cow::Borrowed(_) => Vec::new(),
        };
        PyramidSpare {
            base,
            levels: std::mem::take(&mut self.levels),
        }
    }

    #[inline]
    pub(crate) fn level(&self, l: usize) -> &[Image] {
        if l == 0 || self.levels.is_empty() {
            &self.base
        } else {
            &self.levels[(l - 1).min(self.levels.len() - 1)]
        }
    }
}

/// A level's size: each side halved, at least 1.
fn half_extent(w: u32, h: u32) -> (u32, u32) {
    ((w / 2).max(1), (h / 2).max(1))
}

/// What [`Pyramid`] needs of the projection, worked out once for a source's projection and
/// size: for each level below the base and each layer, every 2×2 block's four weights (the
/// source texels' densities at their centres, normalised to sum to 1; a block past an odd
/// edge repeats its last row or column). A conversion applied frame after frame
/// ([`crate::Remap`]) keeps one, so that no frame works out a direction.
#[derive(Clone)]
pub(crate) struct PyramidPlan {
    /// The projection's overlap blend at the base's size, where it has one.
    blend: Option<OverlapBlend>,
    /// Per level (the first is half the base), per layer, one entry per texel of that level.
    levels: Vec<Vec<Vec<[f32; 4]>>>,
}

impl PyramidPlan {
    /// The plan of `depth` levels (fewer where halving reaches 1×1) of `layers` layers of
    /// `(w, h)` texels in `proj`.
    pub(crate) fn new(proj: &Projection, (w, h): (u32, u32), layers: usize, depth: usize) -> Self {
        let mut levels = Vec::new();
        let (w0, h0) = (w, h);
        let (mut w, mut h) = (w.max(1), h.max(1));
        for _ in 0..depth {
            if w == 1 && h == 1 {
                break;
            }
            levels.push(
                (0..layers)
                    .map(|layer| block_weights(proj, layer, w, h))
                    .collect(),
            );
            (w, h) = half_extent(w, h);
        }
        let blend = proj.overlap_blend((w0, h0), layers);
        PyramidPlan { blend, levels }
    }

    /// Bytes the plan occupies.
    pub(crate) fn memory_bytes(&self) -> usize {
        let blend = self.blend.as_ref().map_or(0, OverlapBlend::memory_bytes);
        blend
            + self
                .levels
                .iter()
                .flatten()
                .map(|l| l.len() * 16)
                .sum::<usize>()
    }
}

/// The four weights of each 2×2 block of a `w`×`h` layer `layer` of `proj` (the texels
/// `(2x, 2y)`, `(2x + 1, 2y)`, `(2x, 2y + 1)`, `(2x + 1, 2y + 1)`, clamped to the layer),
/// each texel's density at its centre (its solid angle per unit `uv`, the texels being
/// equal in `uv`) over the block's sum; a texel nothing sees weighs 10⁻¹² so that a block
/// wholly outside the map still averages.
fn block_weights(proj: &Projection, layer: usize, w: u32, h: u32) -> Vec<[f32; 4]> {
    let (nw, nh) = half_extent(w, h);
    let mut out = vec![[0.0f32; 4]; nw as usize * nh as usize];
    out.par_chunks_mut(nw as usize).enumerate().for_each_init(
        || (vec![None; w as usize], vec![None; w as usize]),
        |(d0, d1), (y, row)| {
            let ys = [(2 * y as u32).min(h - 1), (2 * y as u32 + 1).min(h - 1)];
            proj.row_dirs(layer, ys[0], w, h, d0);
            proj.row_dirs(layer, ys[1], w, h, d1);
            for (x, wt) in row.iter_mut().enumerate() {
                let xs = [(2 * x).min(w as usize - 1), (2 * x + 1).min(w as usize - 1)];
                let dens = |d: &[Option<(DVec3, f64)>], sx: usize| {
                    d[sx].map_or(0.0, |(_, dn)| dn).max(1e-12)
                };
                let q = [
                    dens(d0, xs[0]),
                    dens(d0, xs[1]),
                    dens(d1, xs[0]),
                    dens(d1, xs[1]),
                ];
                let sum: f64 = q.iter().sum();
                *wt = q.map(|v| (v / sum) as f32);
            }
        },
    );
    out
}

/// Halves `img` into `out` (its size from [`half_extent`]), each 2×2 block averaged with
/// `weights` ([`block_weights`] of `img`'s layer and size).
fn downsample_into(img: &Image, weights: &[[f32; 4]], out: &mut Image) {
    let (w, h, c) = (img.width(), img.height(), img.channels());
    let data = img.data();
    if c == 1 {
        // One plane of a planar picture (a YUV frame's Y, U or V), each converted alone.
        downsample_texels((w, h), |i| [data[i]], weights, out)
    } else if c == 3 {
        downsample_texels(
            (w, h),
            |i| [data[3 * i], data[3 * i + 1], data[3 * i + 2]],
            weights,
            out,
        )
    } else {
        downsample_texels::<4>(
            (w, h),
            |i| data[4 * i..4 * i + 4].try_into().unwrap(),
            weights,
            out,
        )
    }
}

/// [`downsample_into`] of a layer of `w`×`h` texels of `C` channels read by `texel` (its
/// row-major index): each texel of `out` its 2×2 block's weighted sum, in one order, so
/// that any source holding the same values gives the same bits.
#[inline(always)]
fn downsample_texels<const C: usize>(
    (w, h): (u32, u32),
    texel: impl Fn(usize) -> [f32; C] + Sync,
    weights: &[[f32; 4]],
    out: &mut Image,
) {
    let (w, h) = (w as usize, h as usize);
    let nw = out.width() as usize;
    out.data_mut()
        .par_chunks_mut(nw * C)
        .zip(weights.par_chunks(nw))
        .enumerate()
        .for_each(|(y, (row, wts))| {
            let (r0, r1) = ((2 * y).min(h - 1) * w, (2 * y + 1).min(h - 1) * w);
            for (x, (o, q)) in row.chunks_exact_mut(C).zip(wts).enumerate() {
                let (a, b) = ((2 * x).min(w - 1), (2 * x + 1).min(w - 1));
                let (p0, p1, p2, p3) = (texel(r0 + a), texel(r0 + b), texel(r1 + a), texel(r1 + b));
                for i in 0..C {
                    o[i] = q[0] * p0[i] + q[1] * p1[i] + q[2] * p2[i] + q[3] * p3[i];
                }
            }
        });
}

/// Converts `src` into projection `dst` at edge `size` (see
/// [`WorldProjection::layer_extent`]).
pub fn resample(src: &EnvMap, dst: Projection, size: u32, opts: &ResampleOptions) -> EnvMap {
    let (w, h) = dst.layer_extent(size.max(1));
    resample_to_extent(src, dst, w, h, opts)
}

/// Bytes a conversion of `src` into `w`×`h` layers of `dst` holds besides the source and
/// the output: the source's pyramid, as deep as the conversion needs, each level's images
/// (the source's channels) and its blocks' four weights. What a memory budget adds to the
/// source and the output it counts itself.
pub fn resample_memory(
    src: &EnvMap,
    dst: Projection,
    (w, h): (u32, u32),
    opts: &ResampleOptions,
) -> u64 {
    let job = Job::new(
        *src.projection(),
        (src.width(), src.height()),
        dst,
        (w, h),
        opts,
    );
    let per_texel = src.channels() as u64 * 4 + 16;
    let layers = src.layers().len() as u64;
    let (mut lw, mut lh) = (src.width().max(1), src.height().max(1));
    let mut bytes = 0u64;
    for _ in 1..job.levels {
        if lw == 1 && lh == 1 {
            break;
        }
        (lw, lh) = half_extent(lw, lh);
        bytes += lw as u64 * lh as u64 * layers * per_texel;
    }
    bytes
}

/// Footprint ratio of an output texel of density `ddens` over the source texels at source
/// density `sdens` (`area` = output texel area / source texel area in their `uv` units).
#[inline]
fn footprint_ratio(ddens: f64, sdens: f64, area: f64) -> f64 {
    if sdens > 0.0 {
        ddens * area / sdens
    } else {
        f64::INFINITY
    }
}

/// How many mip levels the conversion needs, judged on a sparse grid of output texels: deep
/// enough that all but the top 1% of footprint ratios are integrated by at most `cap` points
/// per texel. (A few extreme ratios, such as a cube texel over a lat-long pole, come from
/// footprints that are long and thin on the source rather than large: `cap` points on the
/// full-resolution source integrate those better than a blurred level would.)
fn levels_needed(
    sproj: &Projection,
    dst: &Projection,
    w: u32,
    h: u32,
    area: f64,
    cap: f64,
    rot: &Rotation,
) -> usize {
    let step = (w.max(h) / 64).max(1);
    let mut ratios = Vec::new();
    // Only the sampled texels' directions (a whole row's, for one in `step`, cost 4 ms
    // before any work could start on a 1024² cube).
    let mut one = [None];
    for layer in 0..dst.layer_count() {
        for y in (0..h).step_by(step as usize) {
            for x in (0..w).step_by(step as usize) {
                dst.span_dirs(layer, y, w, h, x, &mut one);
                if let [Some((d, dd))] = one {
                    ratios.push(
                        footprint_ratio(dd, sproj.density_of_dir(rot.source_of(d)), area).min(1e12),
                    );
                }
            }
        }
    }
    if ratios.is_empty() {
        return 0;
    }
    let k = (ratios.len() * 99 / 100).min(ratios.len() - 1);
    let (_, p99, _) = ratios.select_nth_unstable_by(k, f64::total_cmp);
    if *p99 <= cap {
        0
    } else {
        ((*p99 / cap).log2() * 0.5).ceil() as usize + 1
    }
}

/// A side face (±X, ±Z) of a cube made from a lat-long without rotation, where a texel's
/// source longitude depends on its column alone: per column, `u` and `1/√(1 + sc²)` (`sc`
/// the column's face coordinate), so that a texel's lookup is one short `atan`.
///
/// The face point is `(±1, −tc, ∓sc)` or `(±sc, −tc, ±1)`, so `√(x² + z²) = √(1 + sc²)`
/// whatever the row, the longitude is that of the column, and with `a = tc/√(1 + sc²)`
/// (`|a| ≤ 1`): latitude `−atan a`, so `v = ½ + atan(a)/π`; the lat-long density
/// `2π² cos(lat) = 2π²/√(1 + a²)`; the cube's `4/(1 + sc² + tc²)^{3/2} =
/// 4 (1/√(1 + sc²))³ / (1 + a²)^{3/2}`. The same values as the general path's directions
/// and lookups, to `f32` rounding (tested).
struct SideColumns {
    u: Vec<f32>,
    ic: Vec<f32>,
}

impl SideColumns {
    /// The columns of side face `layer` of a `w`-wide cube, or `None` for the ±Y faces.
    fn new(layer: usize, w: u32) -> Option<SideColumns> {
        let face = crate::projection::CubeFace::from_index(layer)?;
        let (mut u, mut ic) = (
            Vec::with_capacity(w as usize),
            Vec::with_capacity(w as usize),
        );
        for x in 0..w {
            let sc = 2.0 * (x as f64 + 0.5) / w as f64 - 1.0;
            let p = face.point(sc, 0.0);
            if p.y != 0.0 {
                return None; // a pole face
            }
            let lon_u = p.x.atan2(-p.z) / std::f64::consts::TAU + 0.5;
            u.push(lon_u as f32);
            ic.push((1.0 / (1.0 + sc * sc).sqrt()) as f32);
        }
        Some(SideColumns { u, ic })
    }

    /// Row `y` (of `h`): each texel's cube density in `s.dens` and lat-long lookup in
    /// `s.look`.
    #[inline(always)]
    fn locate(&self, s: &mut RowScratch, y: usize, h: u32) {
        use std::f32::consts::PI;
        let tc = (2.0 * (y as f64 + 0.5) / h as f64 - 1.0) as f32;
        let k = (2.0 * std::f64::consts::PI * std::f64::consts::PI) as f32;
        let cols = self.u.iter().zip(&self.ic);
        for (((&u, &ic), d), lk) in cols.zip(&mut s.dens).zip(&mut s.look) {
            let a = tc * ic;
            let r = 1.0 / (1.0 + a * a).sqrt();
            *d = 4.0 * (ic * r) * (ic * r) * (ic * r);
            *lk = Lookup {
                layer: 0,
                u,
                v: 0.5 + crate::projection::fastmath::atan01_f32(a) * (1.0 / PI),
                density: k * r,
            };
        }
    }
}

/// Most integration points per output texel (16×16).
const MAX_POINTS: usize = 256;

/// Per-thread buffers for one output row.
pub(crate) struct RowScratch {
    xs: Vec<f32>,
    ys: Vec<f32>,
    zs: Vec<f32>,
    /// The output projection's density at each texel (−1: no direction, skip it).
    pub(crate) dens: Vec<f32>,
    pub(crate) look: Vec<Lookup>,
    /// Each texel's integration grid `(level, n)`, or [`NO_GRID`] or [`SEAM`].
    grid: Vec<(u16, u16)>,
    /// Each texel's bilinear lookup, or [`NO_TAP`].
    taps: Vec<Tap>,
}

/// A texel not integrated.
const NO_GRID: (u16, u16) = (u16::MAX, 0);
/// A texel of one bilinear lookup that straddles a seam of the source (or reads its last
/// floats), which [`bilinear32`]'s general path serves.
const SEAM: (u16, u16) = (u16::MAX, 1);

/// A bilinear lookup inside one source layer: the float where its top-left texel starts,
/// and the fractions towards `+x` and `+y` (as [`bilinear32`] computes them).
#[derive(Clone, Copy)]
struct Tap {
    layer: u32,
    at: u32,
    fx: f32,
    fy: f32,
}

/// No lookup: the texel is black (or filled by a later pass).
const NO_TAP: Tap = Tap {
    layer: u32::MAX,
    at: 0,
    fx: 0.0,
    fy: 0.0,
};

/// The [`Tap`] of `lk` when [`lerp_quad`](crate::envmap::lerp_quad)'s four-float reads at
/// its four texels stay inside the layer (and its start fits a `u32`).
#[inline(always)]
fn inner_tap<const C: usize>(layers: &[Image], lk: &Lookup) -> Option<Tap> {
    let img = layers.get(lk.layer as usize)?;
    let (x0, y0, fx, fy) = bilinear_corner(lk.u, lk.v, img.width(), img.height());
    let (w, h) = (img.width() as i32, img.height() as i32);
    if x0 < 0 || y0 < 0 || x0 + 1 >= w || y0 + 1 >= h {
        return None;
    }
    let stride = w as usize * C;
    let at = y0 as usize * stride + x0 as usize * C;
    if at + stride + C + 4 > img.data().len() {
        return None;
    }
    Some(Tap {
        layer: lk.layer,
        at: u32::try_from(at).ok()?,
        fx,
        fy,
    })
}

/// The layer the first four lookups of `look` share and its image in `layers`, when they
/// share one that `layers` has (not `u32::MAX`, no direction); else `None`.
#[inline(always)]
fn one_layer<'a>(layers: &'a [Image], look: &[Lookup]) -> Option<(u32, &'a Image)> {
    let layer = look[0].layer;
    if look[1..4].iter().any(|l| l.layer != layer) {
        return None;
    }
    Some((layer, layers.get(layer as usize)?))
}

/// One field of the first four [`Lookup`]s of `look` as lanes.
#[inline(always)]
fn lanes(look: &[Lookup], f: impl Fn(&Lookup) -> f32) -> F32x4 {
    let look = &look[..4];
    F32x4::from_array([f(&look[0]), f(&look[1]), f(&look[2]), f(&look[3])])
}

/// The [`Tap`]s of four lookups at `(u, v)` on `img` (layer `layer`), when all four lanes
/// of `ok` are set and every lookup is what [`inner_tap`] makes a tap of:
/// [`bilinear_corner4`] (so the same corners and fractions to the bit), the bounds as
/// `inner_tap` has them. Else `None`.
#[inline(always)]
fn corner_taps4<const C: usize>(
    img: &Image,
    layer: u32,
    u: F32x4,
    v: F32x4,
    ok: M32x4,
) -> Option<[Tap; 4]> {
    let c = bilinear_corner4(u, v, img.width(), img.height());
    if !(ok & c.inside).all() {
        return None;
    }
    let (xs, ys, fxs, fys) = (
        c.x0.to_array(),
        c.y0.to_array(),
        c.fx.to_array(),
        c.fy.to_array(),
    );
    // As inner_tap: the start, and the reads' end inside the layer.
    let (stride, len) = (img.width() as usize * C, img.data().len());
    let mut taps = [NO_TAP; 4];
    for (k, t) in taps.iter_mut().enumerate() {
        let at = ys[k] as usize * stride + xs[k] as usize * C;
        if at + stride + C + 4 > len {
            return None;
        }
        *t = Tap {
            layer,
            at: u32::try_from(at).ok()?,
            fx: fxs[k],
            fy: fys[k],
        };
    }
    Some(taps)
}

/// In [`PointScratch::staps`]: a point that adds nothing (no weight, or no direction).
const SKIP_POINT: u32 = u32::MAX;
/// In [`PointScratch::staps`]: a point whose lookup is no [`inner_tap`] (a seam, an edge),
/// which [`bilinear32_quad`]'s general path serves.
const SLOW_POINT: u32 = u32::MAX - 1;

/// Each integration point's lookup on the level `lv`, for the accumulation in
/// [`Job::integrate_run`]: an [`inner_tap`] (four points at a time with [`corner_taps4`]
/// where all four are plain), or [`SKIP_POINT`] where the point adds nothing (`weight ≤ 0`,
/// or no direction), or [`SLOW_POINT`]. The same lookups, to the bit, as
/// [`bilinear32_quad`] makes of each point.
#[inline(always)]
fn point_taps<const C: usize>(lv: &[Image], weight: &[f32], look: &[Lookup], taps: &mut [Tap]) {
    let one = |w: f32, lk: &Lookup| {
        if w <= 0.0 || lk.layer == u32::MAX {
            Tap {
                layer: SKIP_POINT,
                ..NO_TAP
            }
        } else {
            inner_tap::<C>(lv, lk).unwrap_or(Tap {
                layer: SLOW_POINT,
                ..NO_TAP
            })
        }
    };
    let mut k = 0;
    while k + 4 <= look.len() {
        let (w4, l4) = (&weight[k..k + 4], &look[k..k + 4]);
        let four = one_layer(lv, l4).and_then(|(layer, img)| {
            let ok = F32x4::load(w4).gt(F32x4::splat(0.0));
            corner_taps4::<C>(img, layer, lanes(l4, |l| l.u), lanes(l4, |l| l.v), ok)
        });
        match four {
            Some(t) => taps[k..k + 4].copy_from_slice(&t),
            None => {
                for j in k..k + 4 {
                    taps[j] = one(weight[j], &look[j]);
                }
            }
        }
        k += 4;
    }
    for j in k..look.len() {
        taps[j] = one(weight[j], &look[j]);
    }
}

/// Taps ahead of the current one whose source texels [`gather`] asks for.
const AHEAD: usize = 24;

/// Asks for the source texels of `tap` (its two rows) ahead of reading them (a hint:
/// nothing for [`NO_TAP`]).
#[inline(always)]
fn prefetch<const C: usize>(tap: &Tap, layers: &[Image]) {
    if let Some(img) = layers.get(tap.layer as usize) {
        let p = img.data().as_ptr().wrapping_add(tap.at as usize);
        prefetch_line(p);
        prefetch_line(p.wrapping_add(img.width() as usize * C));
    }
}

/// Writes every texel of `row`: its [`Tap`]'s bilinear blend, or zero for [`NO_TAP`].
#[inline(always)]
fn gather<const C: usize>(taps: &[Tap], layers: &[Image], row: &mut [f32]) {
    for (x, (t, out)) in taps.iter().zip(row.chunks_exact_mut(C)).enumerate() {
        if let Some(ahead) = taps.get(x + AHEAD) {
            prefetch::<C>(ahead, layers);
        }
        match layers.get(t.layer as usize) {
            Some(img) => {
                let stride = img.width() as usize * C;
                let q = lerp_quad::<C>(img.data(), t.at as usize, stride, t.fx, t.fy)
                    .expect("inner_tap keeps the reads inside the layer");
                out.copy_from_slice(&q[..C]);
            }
            None => out.fill(0.0),
        }
    }
}

/// Per-thread buffers for one texel's integration points: directions, weights, lookups.
pub(crate) struct PointScratch {
    /// One row of a texel's points (at most 16).
    row: Vec<Option<(DVec3, f64)>>,
    sx: Vec<f32>,
    sy: Vec<f32>,
    sz: Vec<f32>,
    pub(crate) sw: Vec<f32>,
    pub(crate) slook: Vec<Lookup>,
    /// Each point's bilinear lookup on the level ([`Job::point_taps`]).
    staps: Vec<Tap>,
}

impl RowScratch {
    pub(crate) fn new(w: usize) -> RowScratch {
        RowScratch {
            xs: vec![0.0; w],
            ys: vec![0.0; w],
            zs: vec![0.0; w],
            dens: vec![0.0; w],
            look: vec![Lookup::default(); w],
            grid: vec![NO_GRID; w],
            taps: vec![NO_TAP; w],
        }
    }
}

impl PointScratch {
    pub(crate) fn new() -> PointScratch {
        PointScratch {
            row: vec![None; 16],
            sx: vec![0.0; MAX_POINTS],
            sy: vec![0.0; MAX_POINTS],
            sz: vec![0.0; MAX_POINTS],
            sw: vec![0.0; MAX_POINTS],
            slook: vec![Lookup::default(); MAX_POINTS],
            staps: vec![NO_TAP; MAX_POINTS],
        }
    }
}

/// Everything one output row needs, shared by all rows.
#[derive(Clone)]
pub(crate) struct Job {
    pub(crate) dst: Projection,
    pub(crate) sproj: Projection,
    /// Mip levels the source needs (1: the source alone).
    pub(crate) levels: usize,
    rot: Rotation,
    rotate: bool,
    area: f32,
    cap: f64,
    max_n: u32,
    pub(crate) scale: f32,
    pub(crate) w: u32,
    pub(crate) h: u32,
    /// Texels outside the output's covered domain are left zero ([`Outside::Black`]).
    black: bool,
}

impl Job {
    /// Stages 1 and 2 of a row: the output row's directions (per-row work hoisted by the
    /// projection), turned into the source, and where they land in the source, as one batch.
    #[inline(always)]
    pub(crate) fn locate(&self, s: &mut RowScratch, layer: usize, y: usize) {
        self.locate_with(s, layer, y, None)
    }

    /// [`locate`](Self::locate), from a side face's [`SideColumns`] when given.
    #[inline(always)]
    fn locate_with(&self, s: &mut RowScratch, layer: usize, y: usize, side: Option<&SideColumns>) {
        if let Some(cols) = side {
            return cols.locate(s, y, self.h);
        }
        let (dst, sproj) = (&self.dst, &self.sproj);
        let run = DirRun {
            x: &mut s.xs,
            y: &mut s.ys,
            z: &mut s.zs,
            density: &mut s.dens,
        };
        dst.span_dirs_f32(layer, y as u32, self.w, self.h, 0, run);
        if self.black {
            // A texel given the rim's direction (density 0) whose centre lies outside the
            // domain has no direction of its own: it stays black.
            let v = (y as f64 + 0.5) / self.h as f64;
            for (x, d) in s.dens.iter_mut().enumerate() {
                if *d == 0.0 {
                    let uv = glam::DVec2::new((x as f64 + 0.5) / self.w as f64, v);
                    if dst.nearest_covered(layer, uv) != uv {
                        *d = -1.0;
                    }
                }
            }
        }
        if self.rotate {
            let m = self.rot.to_source.as_mat3();
            for ((x, y), z) in s.xs.iter_mut().zip(&mut s.ys).zip(&mut s.zs) {
                let d = m * glam::Vec3::new(*x, *y, *z);
                (*x, *y, *z) = (d.x, d.y, d.z);
            }
        }
        sproj.lookup_batch(&s.xs, &s.ys, &s.zs, &mut s.look);
    }

    /// [`SideColumns`] for `layer` when this conversion is a lat-long into a cube side face
    /// without rotation.
    fn side_columns(&self, layer: usize) -> Option<SideColumns> {
        let plain = matches!(self.dst, Projection::Cube(_))
            && matches!(self.sproj, Projection::LatLong(_))
            && !self.rotate;
        plain.then(|| SideColumns::new(layer, self.w)).flatten()
    }

    /// The footprint ratio of an output texel of density `ddens` whose centre landed at
    /// `lk`, when it is to be integrated; `None` when one bilinear lookup serves.
    #[inline(always)]
    pub(crate) fn integration_ratio(&self, ddens: f32, lk: &Lookup) -> Option<f64> {
        let ratio = if lk.density > 0.0 {
            ddens * self.area / lk.density
        } else {
            f32::INFINITY
        };
        if ratio < BILINEAR_MAX_RATIO as f32 || self.max_n == 1 || ddens == 0.0 {
            None
        } else {
            Some(ratio as f64)
        }
    }

    /// Fills output row `y` of `layer` (`C` channels per texel): first every texel one
    /// bilinear lookup serves (and those with no direction), then the texels to integrate,
    /// in runs that share a grid ([`integrate_run`](Self::integrate_run)).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn row<const C: usize>(
        &self,
        pyr: &Pyramid,
        s: &mut RowScratch,
        ps: &mut PointScratch,
        layer: usize,
        y: usize,
        side: Option<&SideColumns>,
        row: &mut [f32],
    ) {
        self.locate_with(s, layer, y, side);
        // Stage 3: filter, in passes. First each texel is sorted: one bilinear lookup whose
        // 2×2 source texels lie inside a layer (its corner and fractions kept in `taps`),
        // outside the projection (black), straddling a seam, or to integrate. Then the
        // lookups are made in one tight pass that asks for the source texels a few texels
        // ahead: the lookups wander over source rows in ways the hardware prefetcher does
        // not foresee, and computing and reading in separate passes let a 4096×2048 lat-long
        // go to a 1024² cube about 20% faster than one pass doing both. Last, the seams and
        // the integrated texels.
        let sproj = &self.sproj;
        let base = pyr.level(0);
        let mut special = false;
        // Four texels a step where all four are plain inner lookups (nearly all of them);
        // any other four, and the last few, one at a time.
        let n = s.look.len();
        let mut x = 0;
        while x + 4 <= n {
            let (dens, look) = (&s.dens[x..x + 4], &s.look[x..x + 4]);
            match self.inner_taps4::<C>(base, dens.try_into().expect("4"), look) {
                Some(taps) => {
                    s.taps[x..x + 4].copy_from_slice(&taps);
                    s.grid[x..x + 4].fill(NO_GRID);
                }
                None => {
                    for k in x..x + 4 {
                        special |= self.sort_texel::<C>(base, s, k);
                    }
                }
            }
            x += 4;
        }
        for k in x..n {
            special |= self.sort_texel::<C>(base, s, k);
        }
        gather::<C>(&s.taps, base, row);
        if special {
            let mut x = 0;
            while x < s.grid.len() {
                let g = s.grid[x];
                if g == NO_GRID {
                    x += 1;
                    continue;
                }
                if g == SEAM {
                    let (lk, out) = (&s.look[x], &mut row[x * C..(x + 1) * C]);
                    bilinear32::<C>(sproj, base, lk.layer as usize, lk.u, lk.v, out);
                    x += 1;
                    continue;
                }
                let n = g.1 as usize;
                // A run of texels with this grid, at most as many as the buffers hold.
                let mut end = x + 1;
                while end < s.grid.len() && s.grid[end] == g && (end + 1 - x) * n <= MAX_POINTS {
                    end += 1;
                }
                self.integrate_run::<C>(pyr, ps, layer, y, x..end, g, &s.look, row);
                x = end;
            }
        }
        if self.scale != 1.0 {
            for out in row.chunks_exact_mut(C) {
                for v in &mut out[..3] {
                    *v *= self.scale;
                }
            }
        }
    }

    /// Sorts texel `k` of a located row: sets its grid and tap in `s` (see [`row`]) and
    /// returns whether it needs a later pass (a seam or integration).
    #[inline(always)]
    fn sort_texel<const C: usize>(&self, base: &[Image], s: &mut RowScratch, k: usize) -> bool {
        let (ddens, lk) = (s.dens[k], &s.look[k]);
        (s.grid[k], s.taps[k]) = (NO_GRID, NO_TAP);
        if ddens < 0.0 || lk.layer == u32::MAX {
            return false; // outside the projection's domain: black
        }
        match self.integration_ratio(ddens, lk) {
            None => match inner_tap::<C>(base, lk) {
                Some(t) => {
                    s.taps[k] = t;
                    false
                }
                None => {
                    s.grid[k] = SEAM;
                    true
                }
            },
            Some(ratio) => {
                let (level, n) = self.grid(ratio);
                s.grid[k] = (level as u16, n as u16);
                true
            }
        }
    }

    /// The [`Tap`]s of four texels when all four are what [`sort_texel`](Self::sort_texel)
    /// makes a plain inner lookup of (a direction, one bilinear lookup, its 2×2 texels
    /// inside one layer), all on the same layer; else `None`, and they are sorted one at a
    /// time. The same arithmetic as [`bilinear_corner`] and
    /// [`integration_ratio`](Self::integration_ratio), four lanes at once, so the same taps
    /// to the bit (tested).
    #[inline(always)]
    fn inner_taps4<const C: usize>(
        &self,
        base: &[Image],
        dens: &[f32; 4],
        look: &[Lookup],
    ) -> Option<[Tap; 4]> {
        let (layer, img) = one_layer(base, look)?;
        let dd = F32x4::from_array(*dens);
        let d = lanes(look, |l| l.density);
        let zero = F32x4::splat(0.0);
        // A direction (ddens ≥ 0; NaN fails) and one bilinear lookup: ratio < 4, where
        // ratio = ddens·area/density (∞ where density ≤ 0), or max_n = 1, or ddens = 0.
        let mut ok = dd.ge(zero);
        if self.max_n != 1 {
            let ratio = dd * F32x4::splat(self.area) / d;
            let small = d.gt(zero) & ratio.lt(F32x4::splat(BILINEAR_MAX_RATIO as f32));
            ok = ok & (small | dd.eq(zero));
        }
        corner_taps4::<C>(img, layer, lanes(look, |l| l.u), lanes(look, |l| l.v), ok)
    }

    /// Integrates the output texels `xs` of row `y`, which share a `(level, n)` grid: their
    /// points (the texel centres of an n times finer grid) made a fine row at a time for the
    /// whole run, so that the directions and source lookups go in long batches, then each
    /// point's bilinear sample on the level added to its texel with its solid-angle weight.
    /// A texel none of whose points has a direction takes one bilinear lookup at its centre
    /// (`look`).
    #[allow(clippy::too_many_arguments)]
    #[inline(never)]
    fn integrate_run<const C: usize>(
        &self,
        pyr: &Pyramid,
        ps: &mut PointScratch,
        layer: usize,
        y: usize,
        xs: std::ops::Range<usize>,
        (level, n): (u16, u16),
        look: &[Lookup],
        row: &mut [f32],
    ) {
        let (level, n) = (level as usize, n as usize);
        let count = xs.len();
        let m = count * n;
        let (sproj, lv) = (&self.sproj, pyr.level(level));
        // Four lanes a texel (for RGB the fourth is ignored), and the weights' sum.
        let mut acc = [[0.0f32; 4]; MAX_POINTS];
        let mut wsum = [0.0f32; MAX_POINTS];
        for j in 0..n {
            let run = DirRun {
                x: &mut ps.sx[..m],
                y: &mut ps.sy[..m],
                z: &mut ps.sz[..m],
                density: &mut ps.sw[..m],
            };
            self.dst.span_dirs_f32(
                layer,
                (y * n + j) as u32,
                self.w * n as u32,
                self.h * n as u32,
                (xs.start * n) as u32,
                run,
            );
            if self.rotate {
                let r = self.rot.to_source.as_mat3();
                for k in 0..m {
                    let d = r * glam::Vec3::new(ps.sx[k], ps.sy[k], ps.sz[k]);
                    (ps.sx[k], ps.sy[k], ps.sz[k]) = (d.x, d.y, d.z);
                }
            }
            sproj.lookup_batch(&ps.sx[..m], &ps.sy[..m], &ps.sz[..m], &mut ps.slook[..m]);
            point_taps::<C>(lv, &ps.sw[..m], &ps.slook[..m], &mut ps.staps[..m]);
            // The points' samples, read as in `gather`: their source texels asked for a
            // few points ahead.
            for (t, (a, ws)) in acc[..count].iter_mut().zip(&mut wsum[..count]).enumerate() {
                for k in t * n..(t + 1) * n {
                    if let Some(ahead) = ps.staps[..m].get(k + AHEAD) {
                        prefetch::<C>(ahead, lv);
                    }
                    let (tap, wt) = (&ps.staps[k], ps.sw[k]);
                    let q = match tap.layer {
                        SKIP_POINT => continue,
                        SLOW_POINT => {
                            let sl = &ps.slook[k];
                            bilinear32_quad::<C>(sproj, lv, sl.layer as usize, sl.u, sl.v)
                        }
                        l => {
                            let img = &lv[l as usize];
                            let stride = img.width() as usize * C;
                            lerp_quad::<C>(img.data(), tap.at as usize, stride, tap.fx, tap.fy)
                                .expect("inner_tap keeps the reads inside the layer")
                        }
                    };
                    for (a, v) in a.iter_mut().zip(q) {
                        *a += wt * v;
                    }
                    *ws += wt;
                }
            }
        }
        for (t, x) in xs.enumerate() {
            let out = &mut row[x * C..(x + 1) * C];
            if wsum[t] > 0.0 {
                for k in 0..C {
                    out[k] = acc[t][k] / wsum[t];
                }
            } else {
                let lk = &look[x];
                bilinear32::<C>(sproj, pyr.level(0), lk.layer as usize, lk.u, lk.v, out);
            }
        }
    }

    /// The mip level and the points a side (`n`, an n×n grid) that integrate a footprint of
    /// `ratio` source texels: the level where it covers at most `cap` texels, and about one
    /// point a texel there.
    #[inline]
    fn grid(&self, ratio: f64) -> (usize, u32) {
        let level = if ratio > self.cap {
            (((ratio / self.cap).log2() * 0.5).ceil() as usize).min(self.levels - 1)
        } else {
            0
        };
        let r_l = ratio / 4f64.powi(level as i32);
        (level, (r_l.sqrt().round() as u32).clamp(1, self.max_n))
    }

    /// The integration points of output texel `(x, y)`, whose footprint covers `ratio`
    /// source texels: an n×n grid over the texel, with their solid-angle weights in `s.sw`
    /// and their source lookups in `s.slook`, on the returned mip level, where each stands
    /// for about one source texel. Returns `(level, number of points)`.
    pub(crate) fn points(
        &self,
        s: &mut PointScratch,
        layer: usize,
        x: usize,
        y: usize,
        ratio: f64,
    ) -> (usize, usize) {
        let (dst, sproj) = (&self.dst, &self.sproj);
        let (level, n) = self.grid(ratio);
        // The points are the texel centres of a grid n times finer: row j of them is a span
        // of n texels of fine row n·y + j (one call a row, per-row work hoisted).
        let mut m = 0;
        for j in 0..n {
            let row = &mut s.row[..n as usize];
            dst.span_dirs(
                layer,
                y as u32 * n + j,
                self.w * n,
                self.h * n,
                x as u32 * n,
                row,
            );
            for &(d, wt) in row.iter().flatten() {
                if wt <= 0.0 {
                    continue;
                }
                let d = if self.rotate {
                    self.rot.source_of(d)
                } else {
                    d
                };
                (s.sx[m], s.sy[m], s.sz[m], s.sw[m]) =
                    (d.x as f32, d.y as f32, d.z as f32, wt as f32);
                m += 1;
            }
        }
        sproj.lookup_batch(&s.sx[..m], &s.sy[..m], &s.sz[..m], &mut s.slook[..m]);
        (level, m)
    }

    /// Fills one layer.
    /// Fills `out` with rows `first_row ..` of `layer` (as many as it holds), in parallel
    /// over rows. `side` is [`side_columns`](Self::side_columns) of `layer`.
    #[allow(clippy::too_many_arguments)]
    fn rows<const C: usize>(
        &self,
        pyr: &Pyramid,
        layer: usize,
        first_row: usize,
        side: Option<&SideColumns>,
        out: &mut [f32],
        progress: Option<(&Arc<AtomicU64>, u64)>,
    ) {
        let w = self.w as usize;
        out.par_chunks_mut(w * C).enumerate().for_each_init(
            || (RowScratch::new(w), PointScratch::new()),
            |(s, ps), (k, row)| {
                self.row::<C>(pyr, s, ps, layer, first_row + k, side, row);
                if let Some((p, unit)) = progress {
                    p.fetch_add(unit, Ordering::Relaxed);
                }
            },
        );
    }

    /// The conversion from a `sw`×`sh` source in `sproj` to `w`×`h` layers of `dst`.
    pub(crate) fn new(
        sproj: Projection,
        (sw, sh): (u32, u32),
        dst: Projection,
        (w, h): (u32, u32),
        opts: &ResampleOptions,
    ) -> Job {
        let max_n = opts.max_samples.clamp(1, 16);
        let cap = (max_n * max_n) as f64;
        // Output texel area over source texel area, in uv units.
        let area = (sw as f64 * sh as f64) / (w as f64 * h as f64);
        let rot = opts.rotation;
        let depth = if max_n > 1 {
            levels_needed(&sproj, &dst, w, h, area, cap, &rot)
        } else {
            0
        };
        Job {
            dst,
            sproj,
            levels: pyramid_levels(sw, sh, depth),
            rot,
            rotate: !rot.is_identity(),
            area: area as f32,
            cap,
            max_n,
            scale: 2f32.powf(opts.exposure),
            w,
            h,
            black: opts.outside.unwrap_or(dst.kind().outside()) == Outside::Black,
        }
    }
}

/// How many levels (the source included) a pyramid `depth` deep over a `w`×`h` source has:
/// halving stops at 1×1, as [`Pyramid::new`] does.
pub(crate) fn pyramid_levels(w: u32, h: u32, depth: usize) -> usize {
    let (mut cw, mut ch, mut n) = (w, h, 1);
    for _ in 0..depth {
        if cw == 1 && ch == 1 {
            break;
        }
        (cw, ch, n) = ((cw / 2).max(1), (ch / 2).max(1), n + 1);
    }
    n
}

/// Converts `src` into projection `dst` with layers of `w`×`h` texels.
pub fn resample_to_extent(
    src: &EnvMap,
    dst: Projection,
    w: u32,
    h: u32,
    opts: &ResampleOptions,
) -> EnvMap {
    let r = Resampler::new(src, dst, w, h, opts);
    let layers = (0..dst.layer_count()).map(|layer| r.layer(layer)).collect();
    EnvMap::new(dst, layers).expect("layers built to the projection's shape")
}

/// A conversion planned once (filters chosen, source pyramid built as deep as needed) whose
/// output layers are made one at a time, each on all cores: a caller can write one cube
/// face to its file while the next is made, and need not hold them all.
/// [`resample_to_extent`] is `Resampler::new` and then every [`layer`](Resampler::layer).
///
/// ```
/// use mirrorball_core::{EnvMap, ProjectionKind, Resampler, ResampleOptions};
/// let src = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 64, 3, |d| {
///     [d.y as f32 + 1.0, 1.0, 1.0, 1.0]
/// });
/// let cube = ProjectionKind::Cube.default_projection();
/// let r = Resampler::new(&src, cube, 16, 16, &ResampleOptions::default());
/// let top = r.layer(2); // +Y
/// assert!(top.get(8, 8)[0] > 1.9);
/// ```
pub struct Resampler<'a> {
    job: Job,
    pyramid: Pyramid<'a>,
    channels: usize,
    progress: Option<Arc<AtomicU64>>,
    progress_unit: u64,
    /// Each layer's [`SideColumns`], where it has them: made once, not once a band.
    sides: Vec<Option<SideColumns>>,
}

impl<'a> Resampler<'a> {
    /// Plans the conversion of `src` into `dst` with layers of `w`×`h` texels.
    pub fn new(
        src: &'a EnvMap,
        dst: Projection,
        w: u32,
        h: u32,
        opts: &ResampleOptions,
    ) -> Resampler<'a> {
        let job = Job::new(
            *src.projection(),
            (src.width(), src.height()),
            dst,
            (w, h),
            opts,
        );
        let pyramid = Pyramid::new(src, job.levels - 1);
        let sides = (0..dst.layer_count())
            .map(|layer| job.side_columns(layer))
            .collect();
        Resampler {
            job,
            pyramid,
            channels: src.channels(),
            progress: opts.progress.clone(),
            progress_unit: opts.progress_unit,
            sides,
        }
    }

    /// The output projection.
    pub fn projection(&self) -> &Projection {
        &self.job.dst
    }

    /// Makes output layer `layer` (`0 .. projection().layer_count()`), `w`×`h` texels with
    /// the source's channel count.
    pub fn layer(&self, layer: usize) -> Image {
        let mut img = Image::new(self.job.w, self.job.h, self.channels);
        self.layer_into(layer, &mut img);
        img
    }

    /// Makes output layer `layer` into `img`, overwriting every texel, so that a caller
    /// making many layers can reuse one buffer (no allocation, and no first-touch page
    /// faults after the first layer).
    ///
    /// # Panics
    /// If `layer` is out of range, or `img` is not `w`×`h` texels with the source's channel
    /// count.
    pub fn layer_into(&self, layer: usize, img: &mut Image) {
        assert!(
            layer < self.job.dst.layer_count(),
            "layer {layer} of a {}-layer projection",
            self.job.dst.layer_count()
        );
        assert!(
            (img.width(), img.height(), img.channels()) == (self.job.w, self.job.h, self.channels),
            "layer_into: a {}x{}x{} buffer for {}x{}x{} layers",
            img.width(),
            img.height(),
            img.channels(),
            self.job.w,
            self.job.h,
            self.channels
        );
        self.rows_into(layer, 0, img.data_mut());
    }

    /// Makes rows `first_row ..` of output layer `layer` into `out`, as many as it holds
    /// (interleaved texels with the source's channel count, `w` a row), so that a caller can
    /// hand a layer on a band of rows at a time: to a file, say, while the next band is
    /// made. The rows are those [`layer_into`](Self::layer_into) makes, bit for bit.
    ///
    /// ```
    /// use mirrorball_core::{EnvMap, ProjectionKind, ResampleOptions, Resampler};
    /// let src = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 64, 3, |d| {
    ///     [d.x as f32, d.y as f32, d.z as f32, 1.0]
    /// });
    /// let cube = ProjectionKind::Cube.default_projection();
    /// let r = Resampler::new(&src, cube, 16, 16, &ResampleOptions::default());
    /// let mut band = vec![0.0; 4 * 16 * 3]; // four rows of +Y
    /// r.rows_into(2, 8, &mut band);
    /// assert_eq!(band, r.layer(2).data()[8 * 16 * 3..12 * 16 * 3]);
    /// ```
    ///
    /// # Panics
    /// If `layer` is out of range, `out` is not whole rows, or the rows run past the layer.
    pub fn rows_into(&self, layer: usize, first_row: u32, out: &mut [f32]) {
        let (w, h, c) = (self.job.w as usize, self.job.h as usize, self.channels);
        assert!(
            layer < self.job.dst.layer_count(),
            "layer {layer} of a {}-layer projection",
            self.job.dst.layer_count()
        );
        assert!(
            out.len().is_multiple_of(w * c) && first_row as usize + out.len() / (w * c) <= h,
            "rows_into: {} samples from row {first_row} are not whole rows of a {w}x{h}x{c} layer",
            out.len()
        );
        let progress = self.progress.as_ref().map(|p| (p, self.progress_unit));
        let side = self.sides[layer].as_ref();
        let first = first_row as usize;
        match c {
            3 => self
                .job
                .rows::<3>(&self.pyramid, layer, first, side, out, progress),
            _ => self
                .job
                .rows::<4>(&self.pyramid, layer, first, side, out, progress),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ProjectionKind;

    /// A deterministic generator of numbers in [0, 1) (xorshift).
    fn rng(mut seed: u64) -> impl FnMut() -> f32 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    /// The four-at-once sorting gives, wherever it answers, the very taps the one-at-a-time
    /// sorting gives (bit for bit), and answers for ordinary texels; edge cases (no
    /// direction, NaN, zero and negative densities, footprints to integrate, lookups at and
    /// past the layer's edges, mixed layers) it leaves to the one-at-a-time sorting.
    #[test]
    fn four_texels_at_once_sort_as_one_at_a_time() {
        let ll = ProjectionKind::LatLong.default_projection();
        let cube = ProjectionKind::Cube.default_projection();
        let src_l = EnvMap::from_fn(ll, 64, 3, |_| [1.0; 4]);
        let src_c = EnvMap::from_fn(cube, 16, 4, |_| [1.0; 4]);
        let mut next = rng(0x2545_f491_4f6c_dd1du64);
        let specials = [f32::NAN, -1.0, 0.0, -0.0, 1e-30, f32::INFINITY, 1.0, 2.0];
        // In odd cases, with probability p, one of the special values.
        let special = |next: &mut dyn FnMut() -> f32, odd: bool, p: f32| {
            (odd && next() < p).then(|| specials[(next() * 8.0) as usize % 8])
        };
        let (mut answered, mut declined) = (0, 0);
        for (src, max_n) in [(&src_l, 4), (&src_l, 1), (&src_c, 4)] {
            let opts = ResampleOptions {
                max_samples: max_n,
                ..Default::default()
            };
            let (sw, sh) = (src.width(), src.height());
            let job = Job::new(*src.projection(), (sw, sh), cube, (8, 8), &opts);
            let base = src.layers();
            let layers = base.len() as u32;
            let mut s = RowScratch::new(4);
            // Output over source texel area, in uv units, as Job::new has it.
            let area = (sw * sh) as f32 / 64.0;
            for case in 0..20_000 {
                let odd = case % 3 == 0;
                for k in 0..4 {
                    let density = special(&mut next, odd, 0.2).unwrap_or(0.1 + next() * 4.0);
                    // Footprint ratios from 0 to 5: most one lookup, some to integrate.
                    let dens =
                        special(&mut next, odd, 0.3).unwrap_or(next() * 5.0 * density.abs() / area);
                    let layer = match special(&mut next, odd, 0.1) {
                        Some(_) => [u32::MAX, layers - 1, 0][(next() * 3.0) as usize % 3],
                        None => (case as u32 / 7) % layers,
                    };
                    // Now and then right at or past the edges, or on a texel centre (where
                    // the corner's floor is exact).
                    let mut coord = |n: u32| {
                        let centre = next() < 0.2;
                        let at = ((next() * n as f32).floor() + 0.5) / n as f32;
                        special(&mut next, odd, 0.2).unwrap_or(if centre { at } else { next() })
                    };
                    let (u, v) = (coord(sw), coord(sh));
                    s.dens[k] = dens;
                    s.look[k] = Lookup {
                        layer,
                        u,
                        v,
                        density,
                    };
                }
                let dens: [f32; 4] = s.dens[..].try_into().unwrap();
                let four = match src.channels() {
                    3 => job.inner_taps4::<3>(base, &dens, &s.look),
                    _ => job.inner_taps4::<4>(base, &dens, &s.look),
                };
                let Some(four) = four else {
                    declined += 1;
                    continue;
                };
                answered += 1;
                for (k, a) in four.iter().enumerate() {
                    let special = match src.channels() {
                        3 => job.sort_texel::<3>(base, &mut s, k),
                        _ => job.sort_texel::<4>(base, &mut s, k),
                    };
                    assert!(!special && s.grid[k] == NO_GRID, "case {case} lane {k}");
                    let b = s.taps[k];
                    assert_eq!(
                        (a.layer, a.at, a.fx.to_bits(), a.fy.to_bits()),
                        (b.layer, b.at, b.fx.to_bits(), b.fy.to_bits()),
                        "case {case} lane {k}"
                    );
                }
            }
        }
        // Ordinary texels are answered four at a time; the odd ones are declined.
        assert!(
            answered > 15_000 && declined > 5_000,
            "{answered} {declined}"
        );
    }

    /// Integration points read through `point_taps` give each point the very sample
    /// `bilinear32_quad` gives it (bit for bit), skip exactly the points with no weight or
    /// no direction, and take the four-at-once path for ordinary points.
    #[test]
    fn point_taps_sample_as_bilinear32_quad() {
        let ll = ProjectionKind::LatLong.default_projection();
        let cube = ProjectionKind::Cube.default_projection();
        let ramp = |d: glam::DVec3| {
            [
                (1.5 + d.x) as f32,
                (2.0 + d.y) as f32,
                (d.z * d.z) as f32,
                0.5,
            ]
        };
        let src_l = EnvMap::from_fn(ll, 64, 3, ramp);
        let src_c = EnvMap::from_fn(cube, 16, 4, ramp);
        let mut next = rng(0x9e37_79b9_7f4a_7c15u64);
        let mut fast = 0;
        for src in [&src_l, &src_c] {
            let (proj, lv) = (src.projection(), src.layers());
            let layers = lv.len() as u32;
            let m = 64;
            let (mut weight, mut look, mut taps) =
                (vec![0.0; m], vec![Lookup::default(); m], vec![NO_TAP; m]);
            for case in 0..2000 {
                for k in 0..m {
                    let odd = next() < 0.05;
                    weight[k] = if odd {
                        [0.0, -1.0, f32::NAN][k % 3]
                    } else {
                        next()
                    };
                    let edge = |r: f32| if r < 0.05 { [0.0, 1.0, -0.1][k % 3] } else { r };
                    look[k] = Lookup {
                        layer: if next() < 0.03 {
                            u32::MAX
                        } else {
                            (case as u32) % layers
                        },
                        u: edge(next()),
                        v: edge(next()),
                        density: 1.0,
                    };
                }
                match src.channels() {
                    3 => point_taps::<3>(lv, &weight, &look, &mut taps),
                    _ => point_taps::<4>(lv, &weight, &look, &mut taps),
                }
                for k in 0..m {
                    let (t, lk) = (&taps[k], &look[k]);
                    let skip = weight[k] <= 0.0 || lk.layer == u32::MAX;
                    assert_eq!(t.layer == SKIP_POINT, skip, "case {case} point {k}");
                    if skip {
                        continue;
                    }
                    let (l, c) = (lk.layer as usize, src.channels());
                    let want = match c {
                        3 => bilinear32_quad::<3>(proj, lv, l, lk.u, lk.v),
                        _ => bilinear32_quad::<4>(proj, lv, l, lk.u, lk.v),
                    };
                    if t.layer == SLOW_POINT {
                        continue; // served by bilinear32_quad itself
                    }
                    fast += 1;
                    let img = &lv[t.layer as usize];
                    let stride = img.width() as usize * c;
                    let got = match c {
                        3 => lerp_quad::<3>(img.data(), t.at as usize, stride, t.fx, t.fy),
                        _ => lerp_quad::<4>(img.data(), t.at as usize, stride, t.fx, t.fy),
                    }
                    .unwrap();
                    assert_eq!(
                        got[..c].iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                        want[..c].iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                        "case {case} point {k}"
                    );
                }
            }
        }
        assert!(fast > 150_000, "{fast}");
    }

    #[test]
    fn side_columns_give_the_general_paths_lookups() {
        let ll = ProjectionKind::LatLong.default_projection();
        let cube = ProjectionKind::Cube.default_projection();
        for (face, sw) in [(16u32, 64u32), (100, 512), (1024, 4096)] {
            let job = Job::new(
                ll,
                (sw, sw / 2),
                cube,
                (face, face),
                &ResampleOptions::default(),
            );
            let (mut a, mut b) = (
                RowScratch::new(face as usize),
                RowScratch::new(face as usize),
            );
            for layer in 0..6 {
                let Some(side) = job.side_columns(layer) else {
                    assert!(layer == 2 || layer == 3, "only ±Y are pole faces");
                    continue;
                };
                for y in (0..face as usize).step_by((face as usize / 37).max(1)) {
                    job.locate(&mut a, layer, y);
                    job.locate_with(&mut b, layer, y, Some(&side));
                    for x in 0..face as usize {
                        let (p, q) = (&a.look[x], &b.look[x]);
                        assert_eq!(p.layer, q.layer);
                        // f32 rounding of two different formulas: ~1e-7 of a turn.
                        assert!(
                            (p.u - q.u).abs() < 5e-7,
                            "{face} {layer} {x} {y}: u {} {}",
                            p.u,
                            q.u
                        );
                        assert!(
                            (p.v - q.v).abs() < 5e-7,
                            "{face} {layer} {x} {y}: v {} {}",
                            p.v,
                            q.v
                        );
                        assert!((p.density / q.density - 1.0).abs() < 1e-5);
                        assert!((a.dens[x] / b.dens[x] - 1.0).abs() < 1e-5);
                    }
                }
            }
        }
        // Turned, or another pair of projections: the general path.
        let turned = ResampleOptions {
            rotation: Rotation::from_euler_deg(10.0, 0.0, 0.0),
            ..Default::default()
        };
        assert!(Job::new(ll, (64, 32), cube, (16, 16), &turned)
            .side_columns(0)
            .is_none());
        let cc = ProjectionKind::ContinuousCube.default_projection();
        let opts = ResampleOptions::default();
        assert!(Job::new(ll, (64, 32), cc, (16, 16), &opts)
            .side_columns(0)
            .is_none());
        assert!(Job::new(cube, (16, 16), cube, (16, 16), &opts)
            .side_columns(0)
            .is_none());
    }
}
