//! Prefiltered environment maps in any projection: the entry point.
//!
//! A [`Prefilterer`] is built once from a source map of any projection. It keeps a working
//! cube (the source itself when it is a power-of-two cube of the size chosen, an
//! antialiased conversion otherwise; as fine as the outputs need when they are known,
//! [`Prefilterer::for_outputs`], else at the source's texel density) and makes, each on
//! first use: for Phong and GGX, the
//! split into a bounded body (its seamless solid-angle-weighted pyramid is what importance
//! sampling reads) and the bright texels summed exactly as point sources; for Lambert, the
//! moment quadtree; for mirror lobes, the pyramid of the whole cube. Every output texel is
//! the lobe's prefiltered value *at its own centre direction*, computed on the sphere, so
//! the output may be any projection and any size, and a cube output has no seams: a texel
//! depends on its direction only.
//!
//! The work is parallel over output rows (rayon); the per-texel loops allocate nothing.

use crate::bright::{split, BrightKernel, BrightSet, BrightWalk};
use crate::cube::{needed_face, seamless_pyramid, working_cube, working_face, SeamlessCube};
use crate::irradiance::MomentPyramid;
use crate::lobe::{Lobe, LobeKind};
use crate::specular::{fis, sample_count, RoughnessMapping, SampleSet};
use glam::{DVec3, Vec3, Vec4};
use mirrorball_core::{EnvMap, Image, Projection, WorldProjection};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};

/// How to prefilter.
#[derive(Clone, Debug)]
pub struct PrefilterOptions {
    /// Importance samples per output texel for the sharpest Phong and GGX lobes (default
    /// 128; wider lobes take up to 16 times as many, see the crate docs).
    pub samples: u32,
    /// Added to every sample's mip level (Křivánek & Colbert use +1, which blurs; the
    /// default −0.5 was the most accurate against brute force on the bundled HDRs).
    pub lod_bias: f32,
    /// Face size of the working cube, rounded up to a power of two, at most 4096. Default:
    /// what the outputs need ([`Prefilterer::for_outputs`], [`Prefilterer::for_chain`]),
    /// never finer than the source's own texel density rounded up to a power of two
    /// ([`Prefilterer::new`]: that density).
    pub cube_size: Option<u32>,
    /// Largest working cube face chosen when [`cube_size`](Self::cube_size) is not given
    /// (default 2048; at most 4096).
    pub max_cube_size: u32,
    /// Tolerance of the Lambert moment hierarchy, relative to the map's total energy per
    /// horizon-cut node (default 1e-5; 0 makes it the exact brute-force sum).
    pub lambert_tolerance: f32,
    /// Texels brighter than this many times the mean luminance are filtered exactly, as
    /// point sources, instead of by importance sampling (default 8; `f32::INFINITY` turns
    /// the split off). See the crate docs.
    pub bright_factor: f32,
    /// At most this many level-0 texels are treated as point sources (default 2048); the
    /// threshold rises to keep to it.
    pub max_bright_texels: usize,
    /// Opening criterion κ of the point-source cluster tree: a cluster is summed as one point
    /// when it is smaller than κ times its distance from the lobe axis (default 0.1).
    pub bright_opening: f64,
    /// Counts the work done, for progress bars, in the units [`work`] estimates: each
    /// preparation once it is made, each output row as it is finished.
    pub progress: Option<Arc<AtomicU64>>,
}

impl Default for PrefilterOptions {
    fn default() -> Self {
        PrefilterOptions {
            samples: 128,
            lod_bias: -0.5,
            cube_size: None,
            max_cube_size: 2048,
            lambert_tolerance: 1e-5,
            bright_factor: 8.0,
            max_bright_texels: 2048,
            bright_opening: 0.1,
            progress: None,
        }
    }
}

/// A source prepared for prefiltering.
///
/// ```
/// use mirrorball_core::{EnvMap, ProjectionKind};
/// use mirrorball_filter::{Lobe, PrefilterOptions, Prefilterer};
/// // A constant environment prefilters to the same constant, whatever the lobe.
/// let src = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 32, 3, |_| [0.5, 0.5, 0.5, 1.0]);
/// let p = Prefilterer::new(&src, PrefilterOptions::default());
/// let cube = ProjectionKind::Cube.default_projection();
/// let glossy = p.render(&Lobe::Ggx { roughness: 0.5 }, cube, 8);
/// assert_eq!(glossy.layers().len(), 6);
/// assert!(glossy.layers()[0].data().iter().all(|&v| (v - 0.5).abs() < 1e-4));
/// ```
pub struct Prefilterer {
    /// The working cube, whole.
    cube: EnvMap,
    /// Its pyramid (mirror lookups).
    full: OnceLock<SeamlessCube>,
    /// The pyramid of its body (bright texels capped), for importance sampling, and the
    /// bright set split off it.
    split: OnceLock<(SeamlessCube, Option<BrightSet>)>,
    moments: OnceLock<MomentPyramid>,
    opts: PrefilterOptions,
    channels: usize,
}

/// Point sources for a lobe: the set, how to walk it, `1/∫K`.
struct BrightEval<'a> {
    set: &'a BrightSet,
    walk: BrightWalk,
    inv_integral: f32,
}

/// What is evaluated per output texel.
enum Eval<'a> {
    Mirror(&'a SeamlessCube),
    Fis(SampleSet, &'a SeamlessCube, Option<BrightEval<'a>>),
    Lambert(&'a MomentPyramid, f32),
}

impl Prefilterer {
    /// Prepares `src` (any projection) for any output: unless
    /// [`PrefilterOptions::cube_size`] is given, the working cube has the source's own
    /// texel density (rounded up to a power of two, at most
    /// [`PrefilterOptions::max_cube_size`]). When the outputs are known,
    /// [`for_outputs`](Self::for_outputs) makes a working cube no finer than they need.
    pub fn new(src: &EnvMap, opts: PrefilterOptions) -> Prefilterer {
        let face = working_face(src, opts.cube_size, None, opts.max_cube_size);
        Prefilterer::with_face(src, face, opts)
    }

    /// Prepares `src` for rendering each `(lobe, projection, w, h)` of `outputs` (`w×h`
    /// layers): the working cube is the finest any of them needs (the rule is in
    /// `cube.rs`, `needed_face`: the larger of the output's texel and half the lobe's
    /// radius, as a cube face, at least 256²), never finer than the source's own density,
    /// unless [`PrefilterOptions::cube_size`] is given. Other outputs may still be
    /// rendered; finer ones are then limited by the working cube.
    pub fn for_outputs(
        src: &EnvMap,
        outputs: &[(Lobe, Projection, u32, u32)],
        opts: PrefilterOptions,
    ) -> Prefilterer {
        let face = face_for_outputs(src, outputs, &opts);
        Prefilterer::with_face(src, face, opts)
    }

    /// Prepares `src` for [`render_chain`](Self::render_chain)`(lobes, out, size)`: as
    /// [`for_outputs`](Self::for_outputs) with each level's lobe and extent.
    pub fn for_chain(
        src: &EnvMap,
        lobes: &[Lobe],
        out: Projection,
        size: u32,
        opts: PrefilterOptions,
    ) -> Prefilterer {
        Prefilterer::for_outputs(src, &chain_outputs(lobes, out, size), opts)
    }

    /// Bytes [`for_outputs`](Self::for_outputs)`(src, outputs, opts)` and the rendering of
    /// `outputs` hold at their peak besides `src` and the outputs themselves: the working
    /// cube (four `f32` channels), made from the source through a conversion (its pyramid,
    /// and the cube once more at the source's channels); then the seamless pyramids the
    /// lobes read (one of the map's body, made from a copy of the cube, for the rough lobes;
    /// one of the whole map for mirrors other than the cube itself) and Lambert's moment
    /// pyramid.
    pub fn memory_for_outputs(
        src: &EnvMap,
        outputs: &[(Lobe, Projection, u32, u32)],
        opts: &PrefilterOptions,
    ) -> u64 {
        let face = face_for_outputs(src, outputs, opts) as u64;
        let texel = 16u64;
        let cube = 6 * face * face * texel;
        let cube_proj = Projection::Cube(mirrorball_core::CubeMap);
        let made = match src.projection().kind() == mirrorball_core::ProjectionKind::Cube
            && src.width() as u64 == face
        {
            true => cube,
            false => {
                let converted = 6 * face * face * src.channels() as u64 * 4;
                let pyramid = mirrorball_core::resample_memory(
                    src,
                    cube_proj,
                    (face as u32, face as u32),
                    &Default::default(),
                );
                // The conversion's pyramid goes before the four-channel copy is made.
                let widened = if src.channels() == 4 { 0 } else { cube };
                converted + pyramid.max(widened)
            }
        };
        let mut pyramid = 0;
        let mut s = face;
        loop {
            pyramid += 6 * (s + 2) * (s + 2) * texel;
            if s <= 1 {
                break;
            }
            s /= 2;
        }
        let rough = outputs
            .iter()
            .any(|(l, ..)| !l.is_mirror() && *l != Lobe::Lambert);
        let mirror = outputs.iter().any(|(l, out, w, h)| {
            l.is_mirror()
                && !(out.kind() == mirrorball_core::ProjectionKind::Cube
                    && w == h
                    && *w as u64 == face)
        });
        let lambert = outputs.iter().any(|(l, ..)| *l == Lobe::Lambert);
        let mut working = cube;
        if rough {
            // The body's copy lives while its pyramid is made.
            working += cube + pyramid;
        }
        if mirror {
            working += pyramid;
        }
        if lambert {
            // Face geometry and radiance at level 0, four moments a node below it.
            working += face * face * texel + cube + cube * 4 / 3;
        }
        made.max(working)
    }

    /// [`memory_for_outputs`](Self::memory_for_outputs) of
    /// [`for_chain`](Self::for_chain)`(src, lobes, out, size, opts)` and its
    /// [`render_chain`](Self::render_chain).
    pub fn memory_for_chain(
        src: &EnvMap,
        lobes: &[Lobe],
        out: Projection,
        size: u32,
        opts: &PrefilterOptions,
    ) -> u64 {
        Prefilterer::memory_for_outputs(src, &chain_outputs(lobes, out, size), opts)
    }

    fn with_face(src: &EnvMap, face: u32, opts: PrefilterOptions) -> Prefilterer {
        // Counted row by row as it is resampled; a copy (a cube of the face asked for) at
        // once.
        let work = cost::working_cube(src, face);
        let before = opts.progress.as_ref().map(|p| p.load(Ordering::Relaxed));
        let rows = 6 * face as u64;
        let cube = working_cube(src, face, opts.progress.clone().map(|p| (p, work / rows)));
        if let (Some(p), Some(b)) = (&opts.progress, before) {
            // What the rows did not count (a copy, and the division's remainder).
            let counted = p.load(Ordering::Relaxed).saturating_sub(b);
            count(&opts, work.saturating_sub(counted.min(work)));
        }
        Prefilterer {
            cube,
            full: OnceLock::new(),
            split: OnceLock::new(),
            moments: OnceLock::new(),
            opts,
            channels: src.channels(),
        }
    }

    /// The working cube (four channels).
    pub fn working_cube(&self) -> &EnvMap {
        &self.cube
    }

    /// The options.
    pub fn options(&self) -> &PrefilterOptions {
        &self.opts
    }

    /// The body pyramid and bright set, made on first use.
    fn split(&self) -> &(SeamlessCube, Option<BrightSet>) {
        self.split.get_or_init(|| {
            let mut body = self.cube.clone();
            let bright = if self.opts.bright_factor.is_finite() {
                split(
                    &mut body,
                    self.opts.bright_factor.max(1.0),
                    self.opts.max_bright_texels,
                )
            } else {
                None
            };
            let made = (seamless_pyramid(&body), bright);
            count(&self.opts, cost::pyramid(self.cube.width()));
            made
        })
    }

    /// The share of the source's energy filtered as point sources (0 when none).
    pub fn bright_fraction(&self) -> f64 {
        self.split().1.as_ref().map_or(0.0, |b| b.fraction)
    }

    /// The luminance above which texels were split off as point sources (`None` when no
    /// texel was).
    pub fn bright_threshold(&self) -> Option<f32> {
        self.split().1.as_ref().map(|b| b.threshold)
    }

    fn full(&self) -> &SeamlessCube {
        if let Some((body, None)) = self.split.get() {
            return body; // nothing was split off: the body is the whole map
        }
        self.full.get_or_init(|| {
            let made = seamless_pyramid(&self.cube);
            count(&self.opts, cost::pyramid(self.cube.width()));
            made
        })
    }

    fn moments(&self) -> &MomentPyramid {
        self.moments.get_or_init(|| {
            let made = MomentPyramid::new(self.cube.layers());
            count(&self.opts, cost::moments(self.cube.width()));
            made
        })
    }

    fn evaluator(&self, lobe: &Lobe) -> Eval<'_> {
        if lobe.is_mirror() {
            return Eval::Mirror(self.full());
        }
        let set = || {
            SampleSet::new(
                lobe,
                sample_count(self.opts.samples, lobe),
                self.opts.lod_bias,
            )
        };
        let bright = |kernel| {
            self.split().1.as_ref().map(|b| BrightEval {
                set: b,
                walk: BrightWalk::new(b, kernel, lobe.angular_scale(), self.opts.bright_opening),
                inv_integral: (1.0 / lobe.integral()) as f32,
            })
        };
        match *lobe {
            Lobe::Lambert => Eval::Lambert(self.moments(), self.opts.lambert_tolerance),
            Lobe::Ggx { .. } => {
                let a = lobe.alpha().expect("ggx");
                Eval::Fis(
                    set(),
                    &self.split().0,
                    bright(BrightKernel::Ggx((a * a) as f32)),
                )
            }
            Lobe::Phong { exponent } => Eval::Fis(
                set(),
                &self.split().0,
                bright(BrightKernel::Phong(exponent as f32)),
            ),
        }
    }

    #[inline]
    fn eval_with(&self, e: &Eval<'_>, n: Vec3, floor: f32) -> Vec4 {
        match e {
            Eval::Mirror(p) => p.lookup(n, floor),
            Eval::Fis(set, body, bright) => {
                let mut v = fis(body, set, n, floor);
                if let Some(b) = bright {
                    v += b.set.sum(&b.walk, n) * b.inv_integral;
                }
                v
            }
            Eval::Lambert(m, tol) => m.irradiance_over_pi(n, *tol),
        }
    }

    /// The prefiltered value (RGB) of `lobe` about each unit direction in `dirs`, with no
    /// output-texel footprint (point evaluation).
    pub fn eval(&self, lobe: &Lobe, dirs: &[DVec3]) -> Vec<[f32; 3]> {
        let e = self.evaluator(lobe);
        dirs.par_iter()
            .map(|d| {
                let v = self.eval_with(&e, d.normalize().as_vec3(), f32::NEG_INFINITY);
                [v.x, v.y, v.z]
            })
            .collect()
    }

    /// The map of `lobe` in projection `out` at edge `size` (see
    /// [`WorldProjection::layer_extent`]).
    pub fn render(&self, lobe: &Lobe, out: Projection, size: u32) -> EnvMap {
        let (w, h) = out.layer_extent(size.max(1));
        self.render_extent(lobe, out, w, h)
    }

    /// The map of `lobe` in projection `out` with `w×h` layers.
    pub fn render_extent(&self, lobe: &Lobe, out: Projection, w: u32, h: u32) -> EnvMap {
        if is_copy(lobe, &out, w, h, self.cube.width()) {
            // A mirror at the working cube's own resolution: the cube itself.
            let layers = self
                .cube
                .layers()
                .iter()
                .map(|l| l.with_channels(self.channels))
                .collect();
            count(&self.opts, 6 * cost::COPY * w as u64 * h as u64);
            return EnvMap::new(out, layers).expect("a cube");
        }
        let e = self.evaluator(lobe);
        let row_cost = w as u64 * cost::texel(lobe, &self.opts);
        let c = self.channels;
        let layers = out.layer_count();
        let (wu, hu) = (w as usize, h as usize);
        let mut buf = vec![0.0f32; layers * wu * hu * c];
        // Antialiasing floor: a lobe narrower than the output texel is widened to it, by
        // letting no sample stand for less than the difference of their solid angles
        // (blurs add, roughly, in solid angle). Lobes wider than the texel are evaluated
        // at the texel's centre as they are (the map samples a smooth function).
        let uv_area = 1.0 / (w as f64 * h as f64);
        let scale = lobe.angular_scale();
        let lobe_omega = if lobe.is_mirror() {
            0.0
        } else {
            std::f64::consts::PI * scale * scale
        };
        buf.par_chunks_mut(wu * c).enumerate().for_each_init(
            || vec![None; wu],
            |dirs, (row, px)| {
                let (layer, y) = (row / hu, row % hu);
                out.row_dirs(layer, y as u32, w, h, dirs);
                for (x, d) in dirs.iter().enumerate() {
                    let Some((d, dens)) = *d else { continue };
                    let excess = dens * uv_area - lobe_omega;
                    let floor = if excess > 0.0 {
                        (0.5 * excess.log2()) as f32
                    } else {
                        f32::NEG_INFINITY
                    };
                    let v = self.eval_with(&e, d.as_vec3(), floor);
                    let o = &mut px[x * c..(x + 1) * c];
                    o[0] = v.x;
                    o[1] = v.y;
                    o[2] = v.z;
                    if c == 4 {
                        o[3] = 1.0;
                    }
                }
                count(&self.opts, row_cost);
            },
        );
        let images: Vec<Image> = buf
            .chunks_exact(wu * hu * c)
            .map(|d| Image::from_vec(w, h, c, d.to_vec()).expect("sized"))
            .collect();
        EnvMap::new(out, images).expect("built to the projection's shape")
    }

    /// A prefiltered chain: level `i` holds `lobes[i]` at half the size of level `i − 1`
    /// (level 0 at edge `size`).
    pub fn render_chain(&self, lobes: &[Lobe], out: Projection, size: u32) -> Vec<EnvMap> {
        chain_outputs(lobes, out, size)
            .iter()
            .map(|(lobe, out, w, h)| self.render_extent(lobe, *out, *w, *h))
            .collect()
    }
}

/// Each level of a chain as `(lobe, projection, w, h)`: level `i` at half the size of level
/// `i − 1`, level 0 at edge `size`.
fn chain_outputs(lobes: &[Lobe], out: Projection, size: u32) -> Vec<(Lobe, Projection, u32, u32)> {
    let (w0, h0) = out.layer_extent(size.max(1));
    lobes
        .iter()
        .enumerate()
        .map(|(i, lobe)| (*lobe, out, (w0 >> i).max(1), (h0 >> i).max(1)))
        .collect()
}

/// Whether rendering `lobe` into `out` at `w`×`h` is the working cube (of face `face`)
/// itself: a mirror cube at its resolution.
fn is_copy(lobe: &Lobe, out: &Projection, w: u32, h: u32, face: u32) -> bool {
    lobe.is_mirror() && out.kind() == mirrorball_core::ProjectionKind::Cube && w == h && w == face
}

/// Adds `units` of work done to the options' progress counter, if any.
fn count(opts: &PrefilterOptions, units: u64) {
    if let Some(p) = &opts.progress {
        p.fetch_add(units, Ordering::Relaxed);
    }
}

/// The working cube's face for `outputs` from `src` (the rule is `cube.rs`'s
/// `needed_face` and `working_face`): what [`Prefilterer::for_outputs`] makes, and what
/// [`work`] and [`Prefilterer::memory_for_outputs`] count.
fn face_for_outputs(
    src: &EnvMap,
    outputs: &[(Lobe, Projection, u32, u32)],
    opts: &PrefilterOptions,
) -> u32 {
    let need = outputs
        .iter()
        .map(|(lobe, out, w, h)| needed_face(lobe, out, *w, *h))
        .max();
    working_face(src, opts.cube_size, need, opts.max_cube_size)
}

/// The work of preparing `src` for `outputs` ([`Prefilterer::for_outputs`]) and rendering
/// each of them ([`Prefilterer::render_extent`]), in the units
/// [`PrefilterOptions::progress`] counts: the total a progress bar runs to.
pub fn work(
    src: &EnvMap,
    outputs: &[(Lobe, Projection, u32, u32)],
    opts: &PrefilterOptions,
) -> u64 {
    let face = face_for_outputs(src, outputs, opts);
    let uses = |f: &dyn Fn(&Lobe) -> bool| outputs.iter().any(|(l, ..)| f(l));
    let fis = |l: &Lobe| !l.is_mirror() && *l != Lobe::Lambert;
    let mut units = cost::working_cube(src, face);
    if uses(&fis) {
        units += cost::pyramid(face);
    }
    if outputs
        .iter()
        .any(|(l, o, w, h)| l.is_mirror() && !is_copy(l, o, *w, *h, face))
    {
        units += cost::pyramid(face);
    }
    if uses(&|l| *l == Lobe::Lambert) {
        units += cost::moments(face);
    }
    for (lobe, out, w, h) in outputs {
        let texels = *w as u64 * *h as u64 * out.layer_count() as u64;
        units += texels
            * match is_copy(lobe, out, *w, *h, face) {
                true => cost::COPY,
                false => cost::texel(lobe, opts),
            };
    }
    units
}

/// The work of resampling `src` into a cube of face `face` (as the working cube is made),
/// in [`work`]'s units: for whoever makes such a cube beside the prefilter (a bake's sky).
pub fn cube_work(src: &EnvMap, face: u32) -> u64 {
    cost::working_cube(src, face)
}

/// [`work`] for a chain ([`Prefilterer::for_chain`] and
/// [`Prefilterer::render_chain`]): `lobes[i]` at level `i`.
pub fn chain_work(
    src: &EnvMap,
    lobes: &[Lobe],
    out: Projection,
    size: u32,
    opts: &PrefilterOptions,
) -> u64 {
    work(src, &chain_outputs(lobes, out, size), opts)
}

/// What each step of prefiltering costs, in units of about a nanosecond of one core, so
/// that a progress bar fed by [`PrefilterOptions::progress`] moves at an even pace and its
/// time left holds from the start. Only the ratios matter: they are fitted to the pace
/// `bench/progress_eta.py --pace` measures on release bakes of 4K and 8K sources.
mod cost {
    use super::{sample_count, Lobe, PrefilterOptions};
    use mirrorball_core::EnvMap;

    /// A working cube texel copied into a mirror output.
    pub const COPY: u64 = 1;
    /// A mirror lookup (one trilinear fetch of the pyramid).
    const MIRROR: u64 = 40;
    /// One importance sample of a glossy lobe (a pyramid fetch and its weight).
    const SAMPLE: u64 = 25;
    /// The point sources' walk per glossy output texel.
    const BRIGHT: u64 = 600;
    /// An irradiance texel from the moment hierarchy.
    const LAMBERT: u64 = 2500;
    /// A pyramid (with the bright split) per working cube texel.
    const PYRAMID: u64 = 120;
    /// The moment hierarchy per working cube texel.
    const MOMENTS: u64 = 300;

    fn cube_texels(face: u32) -> u64 {
        6 * face as u64 * face as u64
    }

    /// Making the working cube of face `face` from `src`.
    pub fn working_cube(src: &EnvMap, face: u32) -> u64 {
        let src_texels = src.width() as u64 * src.height() as u64 * src.layers().len() as u64;
        mirrorball_core::work::resample(src_texels, cube_texels(face))
    }

    /// A pyramid of the working cube of face `face`.
    pub fn pyramid(face: u32) -> u64 {
        cube_texels(face) * PYRAMID
    }

    /// The moment hierarchy of the working cube of face `face`.
    pub fn moments(face: u32) -> u64 {
        cube_texels(face) * MOMENTS
    }

    /// One output texel of `lobe`.
    pub fn texel(lobe: &Lobe, opts: &PrefilterOptions) -> u64 {
        if lobe.is_mirror() {
            MIRROR
        } else if *lobe == Lobe::Lambert {
            LAMBERT
        } else {
            sample_count(opts.samples, lobe) as u64 * SAMPLE + BRIGHT
        }
    }
}

/// The lobes of an `levels`-level chain: GGX with `mapping`'s roughness per level; Phong
/// with the matching exponents `2/α² − 2` ([`crate::lobe::phong_exponent_from_roughness`];
/// roughness 0 is a mirror); Lambert on every level.
pub fn chain_lobes(kind: LobeKind, mapping: &RoughnessMapping, levels: usize) -> Vec<Lobe> {
    (0..levels)
        .map(|m| {
            let r = mapping.roughness(m, levels);
            match kind {
                LobeKind::Lambert => Lobe::Lambert,
                LobeKind::Ggx => Lobe::Ggx { roughness: r },
                LobeKind::Phong => Lobe::Phong {
                    exponent: if r <= 0.0 {
                        f64::INFINITY
                    } else {
                        crate::lobe::phong_exponent_from_roughness(r)
                    },
                },
            }
        })
        .collect()
}
