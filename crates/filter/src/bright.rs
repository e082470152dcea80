//! Splitting an HDR environment into a bounded "body" and a sparse set of bright texels.
//!
//! Filtered importance sampling reads each sample from a mip level as large as the solid
//! angle the sample stands for. In a lobe's heavy tails (GGX falls off only as `θ⁻⁴`)
//! those footprints are wide, which is harmless where the radiance is smooth and badly
//! wrong where a sun or a studio light sits inside one: the light is smeared over the
//! footprint and weighted as if it were elsewhere. So the working cube is split:
//!
//! * texels whose luminance (mean of RGB) exceeds `τ` keep `τ` of it in the *body*,
//!   `L_body = L·min(1, τ/lum L)`, and give the rest, `L − L_body`, to the *bright set*;
//! * `τ` is `k` times the solid-angle-weighted mean luminance (default `k = 16`), raised
//!   if needed so that at most `max_texels` texels are bright.
//!
//! The body is filtered by importance sampling; the bright set exactly, as point sources:
//! `Σ_c K(n·d_c) E_c / ∫K`, where each bright texel (or cluster of them, see below) has
//! energy `E_c = Σ (L − L_body) Ω` and sits at its energy-weighted centroid `d_c`. For wide
//! lobes the texels are merged into the nodes of a coarser level (a cube texel `2^m` times
//! larger); placing each at its centroid leaves an error of second order in the node's size
//! over the lobe's scale.

use crate::cube::FaceGeometry;
use glam::{Vec3, Vec4};
use mirrorball_core::CubeFace;
use mirrorball_core::EnvMap;

/// Bright clusters at one level, structure-of-arrays; each cluster of level `m ≥ 1` owns a
/// contiguous run of clusters of level `m − 1`.
pub(crate) struct BrightLevel {
    /// Face size of this level.
    pub size: usize,
    pub x: Vec<f32>,
    pub y: Vec<f32>,
    pub z: Vec<f32>,
    /// Energy (RGB, `Σ excess · Ω`).
    pub e: Vec<Vec4>,
    /// First child in the level below, and how many.
    pub child: Vec<(u32, u32)>,
    /// Level 0 only: each texel's `(face, x, y)`.
    pub texel: Vec<[u16; 3]>,
}

impl BrightLevel {
    fn new(size: usize) -> BrightLevel {
        BrightLevel {
            size,
            x: Vec::new(),
            y: Vec::new(),
            z: Vec::new(),
            e: Vec::new(),
            child: Vec::new(),
            texel: Vec::new(),
        }
    }

    fn push(&mut self, d: Vec3, e: Vec4, child: (u32, u32)) {
        self.x.push(d.x);
        self.y.push(d.y);
        self.z.push(d.z);
        self.e.push(e);
        self.child.push(child);
    }

    /// The same clusters in the order `perm`.
    fn permuted(&self, perm: &[usize]) -> BrightLevel {
        let mut out = BrightLevel::new(self.size);
        for &i in perm {
            out.push(
                Vec3::new(self.x[i], self.y[i], self.z[i]),
                self.e[i],
                self.child[i],
            );
            if let Some(t) = self.texel.get(i) {
                out.texel.push(*t);
            }
        }
        out
    }
}

/// The bright set as a tree of clusters over the levels of the working cube.
pub(crate) struct BrightSet {
    /// `levels[m]`: clusters of level `m` (level 0: single texels).
    pub levels: Vec<BrightLevel>,
    /// Luminance threshold used.
    pub threshold: f32,
    /// Fraction of the total energy (luminance) moved to the bright set.
    pub fraction: f64,
}

/// Splits `cube` (power-of-two faces, 3 or 4 channels) in place into its body, returning
/// the bright set, or `None` when no texel exceeds the threshold.
pub(crate) fn split(cube: &mut EnvMap, k: f32, max_texels: usize) -> Option<BrightSet> {
    let size = cube.width() as usize;
    let geom = FaceGeometry::new(size);
    let (total, tau) = bright_threshold(cube, &geom, k, max_texels)?;
    let (level, keys, moved) = move_bright_texels(cube, &geom, tau);
    if level.e.is_empty() {
        return None;
    }
    let levels = cluster_levels(level, keys, size);
    Some(BrightSet {
        levels,
        threshold: tau,
        fraction: moved / total,
    })
}

/// A texel's luminance, the mean of its first three channels.
#[inline]
fn texel_lum(p: &[f32]) -> f32 {
    (p[0] + p[1] + p[2]) * (1.0 / 3.0)
}

/// The total energy (solid-angle-weighted luminance) of `cube` and the luminance threshold
/// of the bright set: `k` times the mean radiance, raised so that at most `max_texels`
/// texels exceed it. `None` when the total is not positive and finite, `max_texels` is 0
/// or no texel exceeds `k` times the mean.
fn bright_threshold(
    cube: &EnvMap,
    geom: &FaceGeometry,
    k: f32,
    max_texels: usize,
) -> Option<(f64, f32)> {
    let c = cube.channels();
    let lum = texel_lum;
    let mut total = 0.0f64;
    for img in cube.layers() {
        for (p, g) in img.data().chunks_exact(c).zip(&geom.texels) {
            total += lum(p) as f64 * g[3] as f64;
        }
    }
    if total <= 0.0 || !total.is_finite() || max_texels == 0 {
        return None;
    }
    let mean = (total / (4.0 * std::f64::consts::PI)) as f32;
    let mut tau = k * mean;
    let mut lums: Vec<f32> = cube
        .layers()
        .iter()
        .flat_map(|img| img.data().chunks_exact(c).map(lum))
        .filter(|&l| l > tau)
        .collect();
    if lums.is_empty() {
        return None;
    }
    if lums.len() > max_texels {
        let n = lums.len();
        let (_, t, _) = lums.select_nth_unstable_by(n - max_texels - 1, f32::total_cmp);
        tau = tau.max(*t);
    }
    Some((total, tau))
}

/// Level 0 of the bright set: every texel of `cube` brighter than `tau` is scaled down to
/// luminance `tau` in place, and what it loses (times its solid angle) becomes a cluster at
/// its direction. Returns the level, each texel's (face, x, y) and the energy moved.
fn move_bright_texels(
    cube: &mut EnvMap,
    geom: &FaceGeometry,
    tau: f32,
) -> (BrightLevel, Vec<(usize, usize, usize)>, f64) {
    let size = cube.width() as usize;
    let c = cube.channels();
    let lum = texel_lum;
    // Level 0: the bright texels themselves, keyed by (face, x, y).
    let mut level = BrightLevel::new(size);
    let mut keys: Vec<(usize, usize, usize)> = Vec::new();
    let mut moved = 0.0f64;
    for (f, img) in cube.layers_mut().iter_mut().enumerate() {
        for (i, (p, g)) in img
            .data_mut()
            .chunks_exact_mut(c)
            .zip(&geom.texels)
            .enumerate()
        {
            let l = lum(p);
            if l <= tau {
                continue;
            }
            let s = tau / l;
            let ex = Vec4::new(p[0] * (1.0 - s), p[1] * (1.0 - s), p[2] * (1.0 - s), 0.0);
            for v in &mut p[..3] {
                *v *= s;
            }
            let d = CubeFace::from_face(f, Vec3::new(g[0], g[1], g[2]));
            level.push(d, ex * g[3], (0, 0));
            level
                .texel
                .push([f as u16, (i % size) as u16, (i / size) as u16]);
            moved += ((ex.x + ex.y + ex.z) / 3.0 * g[3]) as f64;
            keys.push((f, i % size, i / size));
        }
    }
    (level, keys, moved)
}

/// The levels of the cluster tree from level 0 (`level`, its texels' `keys`, faces of
/// `size` texels) up to one cluster per face: each level is sorted by parent, and its runs
/// merged into the level above ([`merge_runs`]).
fn cluster_levels(
    mut level: BrightLevel,
    mut keys: Vec<(usize, usize, usize)>,
    size: usize,
) -> Vec<BrightLevel> {
    // Coarser levels: sort the level below by parent, merge runs, energy-weighted centroid.
    let mut levels = Vec::new();
    let mut s = size;
    loop {
        let mut perm: Vec<usize> = (0..keys.len()).collect();
        perm.sort_by_key(|&i| parent_key(&keys[i]));
        let sorted = level.permuted(&perm);
        let sorted_keys: Vec<_> = perm.iter().map(|&i| keys[i]).collect();
        if s == 1 {
            levels.push(sorted);
            break;
        }
        let (up, up_keys) = merge_runs(&sorted, &sorted_keys, s);
        levels.push(sorted);
        level = up;
        keys = up_keys;
        s /= 2;
    }
    levels
}

/// The key of a cluster's parent: the same face, half the coordinates.
#[inline]
fn parent_key(k: &(usize, usize, usize)) -> (usize, usize, usize) {
    (k.0, k.1 / 2, k.2 / 2)
}

/// The level above `sorted` (a level of faces of `s` texels, sorted by parent, with its
/// `sorted_keys`): each run of clusters with one parent becomes a cluster at their
/// energy-weighted centroid with their summed energy, pointing at the run. Returns the
/// level and its keys.
fn merge_runs(
    sorted: &BrightLevel,
    sorted_keys: &[(usize, usize, usize)],
    s: usize,
) -> (BrightLevel, Vec<(usize, usize, usize)>) {
    let parent = parent_key;
    let mut up = BrightLevel::new(s / 2);
    let mut up_keys = Vec::new();
    let mut i = 0;
    while i < sorted_keys.len() {
        let pk = parent(&sorted_keys[i]);
        let mut j = i;
        let (mut d, mut e) = (Vec3::ZERO, Vec4::ZERO);
        while j < sorted_keys.len() && parent(&sorted_keys[j]) == pk {
            let w = (sorted.e[j].x + sorted.e[j].y + sorted.e[j].z).max(1e-30);
            d += Vec3::new(sorted.x[j], sorted.y[j], sorted.z[j]) * w;
            e += sorted.e[j];
            j += 1;
        }
        up.push(d.normalize_or_zero(), e, (i as u32, (j - i) as u32));
        up_keys.push(pk);
        i = j;
    }
    (up, up_keys)
}

/// A zonal kernel `K(c)` evaluated in `f32` for the bright sum.
#[derive(Clone, Copy, Debug)]
pub(crate) enum BrightKernel {
    /// GGX with `α²` ([`crate::lobe::ggx::kernel_f32`]).
    Ggx(f32),
    /// Phong with exponent `s`: `K(c) = c^s`.
    Phong(f32),
}

impl BrightKernel {
    #[inline(always)]
    fn eval(self, c: f32) -> f32 {
        match self {
            BrightKernel::Ggx(a2) => crate::lobe::ggx::kernel_f32(c, a2),
            BrightKernel::Phong(s) => c.powf(s),
        }
    }
}

/// How a lobe walks the cluster tree: a cluster of level `m` and angular size `s` is opened
/// (replaced by its children) when `s > κ·max(θ, 2.5·scale)`, `θ` its angle from the axis
/// and `scale` the lobe's angular scale (i.e. when `s` exceeds `2.5 κ scale` and its cosine
/// from the axis exceeds `cos(s/κ)`), and when the horizon `n·l = 0`, where every kernel
/// here has a kink, may cut it. Each unopened cluster is a point
/// source at its energy centroid, whose error is of second order in size/distance
/// (≈ 0.8 κ² of its contribution for a `θ⁻⁴` tail).
pub(crate) struct BrightWalk {
    kernel: BrightKernel,
    open_cos: Vec<f32>,
    /// Whether clusters of level `m` are large against the lobe core (`s > 2.5 κ scale`).
    open_always: Vec<bool>,
    /// A cluster of level `m` may straddle the horizon when `|n·d| < span[m]` (0 where the
    /// kernel there is negligible, below 1e-6 of its peak).
    span: Vec<f32>,
    /// Single texels within `acos(near_cos)` of the axis are integrated on a `q×q` grid
    /// when the lobe is narrow against them (`q > 1`), as the reference does.
    q: u32,
    near_cos: f32,
    size0: f32,
}

impl BrightWalk {
    pub fn new(set: &BrightSet, kernel: BrightKernel, scale: f64, kappa: f64) -> BrightWalk {
        let mut open_cos = Vec::with_capacity(set.levels.len());
        let mut open_always = Vec::with_capacity(set.levels.len());
        let mut span = Vec::with_capacity(set.levels.len());
        for (m, lv) in set.levels.iter().enumerate() {
            // A cube texel of this level spans at most 2/size radians (at a face centre).
            let s = (2.0 / lv.size as f64).min(std::f64::consts::PI);
            let t = s / kappa;
            open_cos.push(if t >= std::f64::consts::PI {
                -2.0
            } else {
                t.cos() as f32
            });
            // Clusters already small against the lobe's core are never opened.
            open_always.push(m > 0 && s > kappa * 2.5 * scale);
            let peak = kernel.eval(1.0);
            let at_horizon = kernel.eval((s as f32).min(1.0));
            span.push(if at_horizon > 1e-6 * peak {
                s as f32
            } else {
                0.0
            });
        }
        // Level-0 texels: radius ≈ 0.71·(2/size) at most; a sub-texel may span a fifth of
        // the lobe's scale (the criterion of `crate::reference`).
        let size0 = set.levels[0].size as f64;
        let radius = 0.71 * 2.0 / size0;
        let q = ((radius / (0.2 * scale.max(1e-9))).ceil() as u32).clamp(1, 8);
        BrightWalk {
            kernel,
            open_cos,
            open_always,
            span,
            q,
            near_cos: (6.0 * radius).min(std::f64::consts::PI).cos() as f32,
            size0: size0 as f32,
        }
    }
}

impl BrightWalk {
    /// The mean of the kernel over a level-0 texel, `q×q` midpoint rule weighted by the
    /// cube's area element `(1 + a² + b²)^{−3/2}`.
    fn texel_mean(&self, t: [u16; 3], n: Vec3) -> f32 {
        let q = self.q;
        let (mut kw, mut ws) = (0.0f32, 0.0f32);
        for j in 0..q {
            for i in 0..q {
                let a = 2.0 * (t[1] as f32 + (i as f32 + 0.5) / q as f32) / self.size0 - 1.0;
                let b = 2.0 * (t[2] as f32 + (j as f32 + 0.5) / q as f32) / self.size0 - 1.0;
                let r2 = 1.0 + a * a + b * b;
                let inv = r2.sqrt().recip();
                let w = inv * inv * inv;
                let d = CubeFace::from_face(t[0] as usize, Vec3::new(a, b, 1.0) * inv);
                let c = n.dot(d);
                if c > 0.0 {
                    kw += w * self.kernel.eval(c);
                }
                ws += w;
            }
        }
        kw / ws
    }
}

impl BrightSet {
    /// `Σ K(n·d_c) E_c` over the clusters the walk stops at.
    pub fn sum(&self, walk: &BrightWalk, n: Vec3) -> Vec4 {
        let mut acc = Vec4::ZERO;
        // Depth-first on a fixed stack: each opened cluster adds at most four children.
        let mut stack = [(0u8, 0u32); 96];
        let mut sp = 0usize;
        let top = self.levels.len() - 1;
        for i in 0..self.levels[top].e.len() {
            stack[sp] = (top as u8, i as u32);
            sp += 1;
        }
        while sp > 0 {
            sp -= 1;
            let (m, i) = stack[sp];
            let (m, i) = (m as usize, i as usize);
            let lv = &self.levels[m];
            let c = n.x * lv.x[i] + n.y * lv.y[i] + n.z * lv.z[i];
            // Open clusters that are large for their distance, and those the horizon
            // (where every kernel here is clamped to 0) may cut.
            let (first, count) = if m > 0 { lv.child[i] } else { (0, 0) };
            if m > 0
                && sp + count as usize <= stack.len()
                && ((walk.open_always[m] && c > walk.open_cos[m]) || c.abs() < walk.span[m])
            {
                for j in first..first + count {
                    stack[sp] = ((m - 1) as u8, j);
                    sp += 1;
                }
                continue;
            }
            if m == 0 && walk.q > 1 && c > walk.near_cos {
                acc += lv.e[i] * walk.texel_mean(lv.texel[i], n);
            } else if c > 0.0 {
                acc += lv.e[i] * walk.kernel.eval(c);
            }
        }
        acc
    }
}
