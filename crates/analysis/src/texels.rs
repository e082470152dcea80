//! Per-texel measures of a projection at a given size: how many texels are used, how much of
//! the world each one sees, how stretched each one is, and how they are shared between the
//! front and back hemispheres.
//!
//! Everything comes from the projection's own `WorldProjection` methods, the code the
//! converter uses:
//!
//! * **Solid angle per texel**: [`texel_solid_angle`](WorldProjection::texel_solid_angle),
//!   exact (closed forms, spherical polygons, or Green's theorem along the texel edges,
//!   clipped to the covered domain).
//! * **Full and partial texels**: a texel is *full* when its four corners are covered
//!   (`uv_to_dir` is `Some`; every domain here is convex, so then the whole texel is), and
//!   *partial* when it is not full but has a positive solid angle (a rim texel of a disk map).
//! * **Anisotropy**: `σ₁/σ₂` of the pixel-coordinate Jacobian at the texel centre (see
//!   [`crate::jacobian`]).
//! * **Front and back**: the texel centre's direction against the default camera's view axis
//!   (−Z): in front when `d·(−Z) > 0`.
//! * **Used area fraction** (exact, not counted): the covered part of each layer is
//!   star-shaped about the layer centre, so its area is `½∮ r(ψ)² dψ`, with the boundary
//!   radius `r(ψ)` found by bisection on `uv_to_dir(…).is_some()` (clipped to the layer's
//!   square) and the integral taken by 16-point Gauss–Legendre on each eighth of the turn
//!   (the square's corners are kinks at odd multiples of π/4). A disk map gives π/4 to
//!   rounding.
//! * **Crossover radius**: along eight rays from a layer's centre, the first radius where the
//!   direction crosses the plane perpendicular to the view axis (found by bisection). When
//!   all eight agree the crossover is a circle about the centre and its radius is reported
//!   (Zimmons: `1/(2√2)` for the sphere map); otherwise the projection has none.

use crate::jacobian;
use glam::{DVec2, DVec3};
use mirrorball_core::quadrature::gauss_legendre;
use mirrorball_core::{Projection, WorldProjection};
use rayon::prelude::*;
use serde::Serialize;
use std::f64::consts::{FRAC_PI_4, PI, TAU};

/// The view axis of the default camera: front is where `d · VIEW > 0`.
pub const VIEW: DVec3 = DVec3::NEG_Z;

/// A texel and a value measured there.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct TexelValue {
    /// The layer.
    pub layer: usize,
    /// Column.
    pub x: u32,
    /// Row (0 = top).
    pub y: u32,
    /// The value.
    pub value: f64,
}

/// Smallest and largest solid angle over a set of texels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Extremes {
    /// The texel with the smallest solid angle (sr).
    pub min: TexelValue,
    /// The texel with the largest solid angle (sr).
    pub max: TexelValue,
    /// `max / min`.
    pub ratio: f64,
}

impl Extremes {
    fn empty() -> Extremes {
        Extremes {
            min: TexelValue {
                value: f64::INFINITY,
                ..Default::default()
            },
            max: TexelValue {
                value: f64::NEG_INFINITY,
                ..Default::default()
            },
            ratio: f64::NAN,
        }
    }
    fn add(&mut self, t: TexelValue) {
        if t.value < self.min.value {
            self.min = t;
        }
        if t.value > self.max.value {
            self.max = t;
        }
    }
    fn merge(&mut self, o: &Extremes) {
        if o.min.value.is_finite() {
            self.add(o.min);
        }
        if o.max.value.is_finite() {
            self.add(o.max);
        }
    }
    fn finish(&mut self) {
        self.ratio = self.max.value / self.min.value;
    }
}

/// Where the front and back hemispheres meet on a layer, when that is a circle about the
/// layer's centre.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Crossover {
    /// The layer.
    pub layer: usize,
    /// Radius in texture units (`uv`; the layer is the unit square).
    pub radius_uv: f64,
    /// Radius in texels of the analysed size.
    pub radius_texels: f64,
    /// Whether the circle is the boundary of the covered domain (the rim), as for a
    /// paraboloid half or a hemispherical fisheye.
    pub at_rim: bool,
}

/// Everything [`texel_stats`] measures for one projection at one size.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TexelStats {
    /// Projection name.
    pub projection: String,
    /// The edge size asked for.
    pub size: u32,
    /// Number of layers.
    pub layers: usize,
    /// Layer width.
    pub width: u32,
    /// Layer height.
    pub height: u32,
    /// All texels, all layers.
    pub texels: u64,
    /// Exact fraction of the texel area inside the covered domain.
    pub used_area_fraction: f64,
    /// Texels wholly inside the covered domain.
    pub full_texels: u64,
    /// Texels partly inside (rim texels).
    pub partial_texels: u64,
    /// Texels wholly outside.
    pub empty_texels: u64,
    /// Sum of all texel solid angles (should equal `covered_solid_angle`).
    pub solid_angle_sum: f64,
    /// The projection's covered solid angle (4π for all but fisheye and Mercator).
    pub covered_solid_angle: f64,
    /// Solid angle per texel over full texels.
    pub full: Extremes,
    /// Solid angle per texel over full and partial texels.
    pub with_partial: Extremes,
    /// Largest anisotropy at a covered texel centre.
    pub anisotropy_max: TexelValue,
    /// Mean anisotropy over texels whose centre is covered.
    pub anisotropy_mean: f64,
    /// Mean anisotropy weighted by texel solid angle (the average over the sphere).
    pub anisotropy_mean_sphere: f64,
    /// Share of all texels whose centre looks into the front hemisphere (`d·(−Z) > 0`).
    pub front_share: f64,
    /// Share of all texels whose centre looks into the back hemisphere.
    pub back_share: f64,
    /// Share of all texels whose centre is not covered.
    pub unused_share: f64,
    /// The front/back crossover circle, where there is one.
    pub crossover: Option<Crossover>,
}

/// Per-texel values of one layer, row-major, top row first (for heat maps).
#[derive(Clone, Debug, PartialEq)]
pub struct LayerField {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Solid angle per texel (sr); 0 outside the domain.
    pub solid_angle: Vec<f64>,
    /// Anisotropy at the texel centre; NaN where the centre is not covered.
    pub anisotropy: Vec<f64>,
}

#[derive(Clone, Debug)]
struct RowAcc {
    full: Extremes,
    with_partial: Extremes,
    n_full: u64,
    n_partial: u64,
    n_empty: u64,
    omega_sum: f64,
    aniso_max: TexelValue,
    aniso_sum: f64,
    aniso_n: u64,
    aniso_wsum: f64,
    aniso_w: f64,
    front: f64,
    back: f64,
    unused: f64,
}

impl RowAcc {
    fn new() -> RowAcc {
        RowAcc {
            full: Extremes::empty(),
            with_partial: Extremes::empty(),
            n_full: 0,
            n_partial: 0,
            n_empty: 0,
            omega_sum: 0.0,
            aniso_max: TexelValue {
                value: f64::NEG_INFINITY,
                ..Default::default()
            },
            aniso_sum: 0.0,
            aniso_n: 0,
            aniso_wsum: 0.0,
            aniso_w: 0.0,
            front: 0.0,
            back: 0.0,
            unused: 0.0,
        }
    }
    fn merge(mut self, o: &RowAcc) -> RowAcc {
        self.full.merge(&o.full);
        self.with_partial.merge(&o.with_partial);
        self.n_full += o.n_full;
        self.n_partial += o.n_partial;
        self.n_empty += o.n_empty;
        self.omega_sum += o.omega_sum;
        if o.aniso_max.value > self.aniso_max.value {
            self.aniso_max = o.aniso_max;
        }
        self.aniso_sum += o.aniso_sum;
        self.aniso_n += o.aniso_n;
        self.aniso_wsum += o.aniso_wsum;
        self.aniso_w += o.aniso_w;
        self.front += o.front;
        self.back += o.back;
        self.unused += o.unused;
        self
    }
}

/// The values of one row, when fields are kept.
type RowField = (Vec<f64>, Vec<f64>);

/// Which texel corners of each layer are covered: `(h + 1)` rows of `(w + 1)`, or `None`
/// when the whole square is (the used area is 1 and the domain star-shaped).
type Corners = Option<Vec<Vec<bool>>>;

fn corners(p: &Projection, w: u32, h: u32) -> Corners {
    if used_area_fraction(p) > 1.0 - 1e-12 {
        return None;
    }
    Some(
        (0..p.layer_count())
            .map(|l| {
                (0..=h)
                    .into_par_iter()
                    .flat_map_iter(|y| {
                        let v = y as f64 / h as f64;
                        (0..=w).map(move |x| {
                            p.uv_to_dir(l, DVec2::new(x as f64 / w as f64, v)).is_some()
                        })
                    })
                    .collect()
            })
            .collect(),
    )
}

#[allow(clippy::too_many_arguments)]
fn scan_row(
    p: &Projection,
    corners: &Corners,
    layer: usize,
    y: u32,
    w: u32,
    h: u32,
    keep: bool,
) -> (RowAcc, Option<RowField>) {
    let mut acc = RowAcc::new();
    // Below this a "solid angle" is quadrature rounding on a texel that only touches the
    // domain at a point (10⁻¹² of an equal share).
    let floor = 1e-12 * equal_share(p.layer_count() as u64 * w as u64 * h as u64);
    let stride = w as usize + 1;
    let corner = |x: usize, yy: u32| match corners {
        Some(c) => c[layer][yy as usize * stride + x],
        None => true,
    };
    let mut field = keep.then(|| {
        (
            Vec::with_capacity(w as usize),
            Vec::with_capacity(w as usize),
        )
    });
    let vc = (y as f64 + 0.5) / h as f64;
    for x in 0..w {
        let xi = x as usize;
        let full = corner(xi, y) && corner(xi + 1, y) && corner(xi, y + 1) && corner(xi + 1, y + 1);
        let omega = p.texel_solid_angle(layer, x, y, w, h);
        let tv = |value| TexelValue { layer, x, y, value };
        acc.omega_sum += omega;
        if full {
            acc.n_full += 1;
            acc.full.add(tv(omega));
            acc.with_partial.add(tv(omega));
        } else if omega > floor {
            acc.n_partial += 1;
            acc.with_partial.add(tv(omega));
        } else {
            acc.n_empty += 1;
        }
        let uv = DVec2::new((x as f64 + 0.5) / w as f64, vc);
        let centre = p.uv_to_dir(layer, uv);
        let mut an = f64::NAN;
        match centre {
            Some(d) => {
                let s = d.dot(VIEW);
                if s.abs() < 1e-12 {
                    acc.front += 0.5;
                    acc.back += 0.5;
                } else if s > 0.0 {
                    acc.front += 1.0;
                } else {
                    acc.back += 1.0;
                }
                if let Some(a) = jacobian::anisotropy_at(p, layer, uv, d, w, h) {
                    an = a;
                    acc.aniso_sum += a;
                    acc.aniso_n += 1;
                    acc.aniso_wsum += a * omega;
                    acc.aniso_w += omega;
                    if a > acc.aniso_max.value {
                        acc.aniso_max = tv(a);
                    }
                }
            }
            None => acc.unused += 1.0,
        }
        if let Some(f) = field.as_mut() {
            f.0.push(if omega > floor { omega } else { 0.0 });
            f.1.push(an);
        }
    }
    (acc, field)
}

/// The layer extent and texel count of `p` at edge `size`.
pub fn texel_count(p: &Projection, size: u32) -> u64 {
    let (w, h) = p.layer_extent(size);
    p.layer_count() as u64 * w as u64 * h as u64
}

/// The edge size at which `p` holds as close to `budget` texels (all layers together) as
/// possible: a 512² sphere map and six 209² cube faces hold the same budget. Found by
/// bisection on [`WorldProjection::layer_extent`], so it works for any projection.
pub fn size_for_budget(p: &Projection, budget: u64) -> u32 {
    let (mut lo, mut hi) = (1u32, 1u32 << 17);
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if texel_count(p, mid) <= budget {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // lo fits; hi does not: take whichever is nearer the budget.
    let (a, b) = (texel_count(p, lo), texel_count(p, hi));
    if budget.abs_diff(a) <= budget.abs_diff(b) {
        lo
    } else {
        hi
    }
}

/// Distance from the layer centre to the edge of the unit square along azimuth `psi`.
fn square_radius(psi: f64) -> f64 {
    0.5 / psi.cos().abs().max(psi.sin().abs())
}

/// The point at radius `r` along azimuth `psi` from the layer centre, in `uv`.
fn ray_point(r: f64, psi: f64) -> DVec2 {
    DVec2::new(0.5 + r * psi.cos(), 0.5 + r * psi.sin())
}

/// Radius of the covered domain of `layer` along azimuth `psi` (clipped to the layer's
/// square), by bisection on `uv_to_dir(…).is_some()`. Assumes the domain is star-shaped
/// about the centre, which holds for every projection in mirrorball.
pub fn boundary_radius<P: WorldProjection + ?Sized>(p: &P, layer: usize, psi: f64) -> f64 {
    let rs = square_radius(psi);
    let inside = |r: f64| p.uv_to_dir(layer, ray_point(r, psi)).is_some();
    if inside(rs) {
        return rs;
    }
    let (mut lo, mut hi) = (0.0, rs);
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if inside(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Exact fraction of the layers' area that is covered: `½∮ r(ψ)² dψ` per layer, averaged.
pub fn used_area_fraction<P: WorldProjection + ?Sized>(p: &P) -> f64 {
    let n = p.layer_count();
    let mut total = 0.0;
    for layer in 0..n {
        for k in 0..8 {
            let (a, b) = (k as f64 * FRAC_PI_4, (k + 1) as f64 * FRAC_PI_4);
            total += gauss_legendre(a, b, |psi| {
                let r = boundary_radius(p, layer, psi);
                0.5 * r * r
            });
        }
    }
    total / n as f64
}

/// The front/back crossover along azimuth `psi` of `layer`: the first radius at which
/// `d·VIEW` changes sign or reaches zero, and whether that is at the domain's rim.
fn crossover_along<P: WorldProjection + ?Sized>(
    p: &P,
    layer: usize,
    psi: f64,
) -> Option<(f64, bool)> {
    let rmax = boundary_radius(p, layer, psi);
    let g = |r: f64| p.uv_to_dir(layer, ray_point(r, psi)).map(|d| d.dot(VIEW));
    let g0 = g(0.0)?;
    if g0.abs() < 1e-12 {
        return Some((0.0, false));
    }
    const STEPS: usize = 512;
    let mut prev = 0.0;
    for i in 1..=STEPS {
        let r = rmax * i as f64 / STEPS as f64;
        let gi = g(r)?;
        if gi.abs() < 1e-10 && i == STEPS {
            return Some((rmax, true));
        }
        if gi.signum() != g0.signum() {
            let (mut lo, mut hi) = (prev, r);
            for _ in 0..80 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                match g(mid) {
                    Some(v) if v.signum() == g0.signum() => lo = mid,
                    _ => hi = mid,
                }
            }
            return Some((0.5 * (lo + hi), false));
        }
        prev = r;
    }
    None
}

/// The crossover circle of `p`, if one of its layers has one: the radius found along eight
/// azimuths must agree to 10⁻⁹.
pub fn crossover<P: WorldProjection + ?Sized>(p: &P, size_texels: u32) -> Option<Crossover> {
    for layer in 0..p.layer_count() {
        let mut radii = Vec::with_capacity(8);
        for k in 0..8 {
            // Off the axes and diagonals by an irrational fraction, so no ray runs along a
            // crease or a seam.
            let psi = TAU * (k as f64 + 0.137) / 8.0;
            match crossover_along(p, layer, psi) {
                Some(r) => radii.push(r),
                None => break,
            }
        }
        if radii.len() < 8 {
            continue;
        }
        let r0 = radii[0].0;
        if r0 > 0.0 && radii.iter().all(|&(r, _)| (r - r0).abs() < 1e-9) {
            return Some(Crossover {
                layer,
                radius_uv: r0,
                radius_texels: r0 * size_texels as f64,
                at_rim: radii.iter().all(|&(_, rim)| rim),
            });
        }
    }
    None
}

/// Scans every texel of `p` at edge `size`: statistics, and per-layer fields if `keep`.
pub fn scan(p: &Projection, size: u32, keep: bool) -> (TexelStats, Option<Vec<LayerField>>) {
    let (w, h) = p.layer_extent(size);
    let n = p.layer_count();
    let rows: Vec<(usize, u32)> = (0..n).flat_map(|l| (0..h).map(move |y| (l, y))).collect();
    let corners = corners(p, w, h);
    let results: Vec<(RowAcc, Option<RowField>)> = rows
        .par_iter()
        .map(|&(l, y)| scan_row(p, &corners, l, y, w, h, keep))
        .collect();
    let mut acc = RowAcc::new();
    for (r, _) in &results {
        acc = acc.merge(r);
    }
    let fields = keep.then(|| {
        let mut out: Vec<LayerField> = (0..n)
            .map(|_| LayerField {
                width: w,
                height: h,
                solid_angle: Vec::with_capacity((w * h) as usize),
                anisotropy: Vec::with_capacity((w * h) as usize),
            })
            .collect();
        for ((l, _), (_, f)) in rows.iter().zip(results) {
            let (o, a) = f.expect("kept");
            out[*l].solid_angle.extend(o);
            out[*l].anisotropy.extend(a);
        }
        out
    });
    acc.full.finish();
    acc.with_partial.finish();
    let texels = n as u64 * w as u64 * h as u64;
    let t = texels as f64;
    let stats = TexelStats {
        projection: p.name().to_string(),
        size,
        layers: n,
        width: w,
        height: h,
        texels,
        used_area_fraction: used_area_fraction(p),
        full_texels: acc.n_full,
        partial_texels: acc.n_partial,
        empty_texels: acc.n_empty,
        solid_angle_sum: acc.omega_sum,
        covered_solid_angle: p.covered_solid_angle(),
        full: acc.full,
        with_partial: acc.with_partial,
        anisotropy_max: acc.aniso_max,
        anisotropy_mean: acc.aniso_sum / acc.aniso_n.max(1) as f64,
        anisotropy_mean_sphere: acc.aniso_wsum / acc.aniso_w,
        front_share: acc.front / t,
        back_share: acc.back / t,
        unused_share: acc.unused / t,
        crossover: crossover(p, w),
    };
    (stats, fields)
}

/// [`scan`] without fields.
pub fn texel_stats(p: &Projection, size: u32) -> TexelStats {
    scan(p, size, false).0
}

/// The mean solid angle per texel if the whole budget were spread evenly over the sphere:
/// `4π / texels`. Heat maps show solid angles relative to it, so projections compare.
pub fn equal_share(texels: u64) -> f64 {
    4.0 * PI / texels as f64
}
