//! Dual fisheye: two fisheye lenses back to back, as consumer 360° cameras record them, both
//! image circles in one 2:1 picture, each with its own lens model.
//!
//! **Picture coordinates.** The picture is 2:1; a point at texture coordinates `(u, v)` has
//! picture coordinates `p = (2u, v)`, in units of the picture's height (`x ∈ [0, 2]` to the
//! right, `y ∈ [0, 1]` downwards), so that circles are circles. A calibration in pixels
//! divides by the picture's height in pixels.
//!
//! **A lens** ([`FisheyeLens`]): its image circle's centre `c` and radius `r` (picture
//! units), the roll of its image (degrees, counter-clockwise in the picture), its whole field
//! of view `fov` (degrees, up to 360) and its model: one of the single fisheye's [`Lens`]es
//! (equidistant, equisolid, stereographic, orthographic: `ρ(θ)` with `ρ(fov/2) = 1`), or the
//! polynomial of OpenCV's fisheye model (Kannala & Brandt 2006; OpenCV `cv::fisheye`):
//! `θ_d(θ) = θ(1 + k₁θ² + k₂θ⁴ + k₃θ⁶ + k₄θ⁸)`, the image radius proportional to `θ_d`, here
//! normalised so that `ρ(θ) = θ_d(θ)/θ_d(fov/2)`. (From an OpenCV calibration `K`, `D`: the
//! centre is `(c_x, c_y)/height`, `k = D`, and the radius `f_x·θ_d(fov/2)/height`.) A point
//! at `ρ` on the disk, in the direction of azimuth `ψ` (with `ρ = |p − c|/r`, `ψ` measured
//! counter-clockwise from the picture's right, less the roll), is the direction at angle
//! `θ(ρ)` from the lens's axis at azimuth `ψ` about it. `θ(ρ)` of the polynomial is found by
//! Newton's method safeguarded by bisection; coefficients that make `θ_d` stop increasing
//! within the field of view are refused (`θ'_d(θ) = 1 + 3k₁θ² + 5k₂θ⁴ + 7k₃θ⁶ + 9k₄θ⁸ > 0`).
//!
//! **The rig** (as FFmpeg's `v360` `dfisheye`, `libavfilter/vf_v360.c`, `dfisheye_to_xyz`
//! and `xyz_to_dfisheye`): the front lens looks along the rig's `forward` (default −Z) with
//! the rig's right and up, the back lens the opposite way, seen as a camera turned half a
//! turn about up sees it (its right is the rig's left), as the dual paraboloid's back half.
//! The default is `v360`'s: two equidistant 180° lenses, the back one filling the left half
//! and the front one the right half, each circle touching the picture's edges.
//!
//! **Which lens.** A direction is looked up in the lens whose axis is closer to it (the
//! front for `forward·d ≥ 0`, as `v360` decides by the sign of `z`), or in the other where
//! the nearer one does not see it (its circle cropped by the picture's edge). A picture point
//! belongs to the circle it lies in (the circles may not overlap in the picture).
//!
//! **Solid angle.** Each lens is a [`RadialMap`]-style disk: with `H(ρ) = 1 − cos θ(ρ)`, the
//! area element of the unit disk is `H'(ρ)/ρ = sin θ · θ'(ρ)/ρ`, and `(a, b) = (p − c)/r`
//! (up positive) has `|∂(a, b)/∂(u, v)| = 2/r²`, so the density is `2/r² · sin θ θ'(ρ)/ρ`.
//! A texel's solid angle is Green's theorem along its four edges in each lens's disk (the
//! disk module's `edge_integral_of`, exact to ~1e-13), summed over the two lenses. With
//! fields of view that add up to more than 360° both lenses see a band around the equator:
//! the texels of both circles see it, so **the texels' solid angles sum to what each lens
//! sees inside the picture, added** ([`DualFisheye::seen_solid_angle`]), and
//! [`covered_solid_angle`](WorldProjection::covered_solid_angle) is their union (4π when the
//! fields of view add up to 360° or more and no circle is cropped).
//!
//! **The blend.** As the source of a conversion, a direction both lenses see is a weighted
//! mix of both lenses' pictures: with `m_i = fov_i/2 − θ_i` the angle inside lens `i`'s rim
//! and `t = m_i/(m_i + m_j)`, lens `i` weighs `t²(3 − 2t)` (smoothstep: 1 where the other
//! lens's rim is, 0 at its own, a continuous slope between; the weights add up to 1). It is
//! applied to the source's texels before any lookup ([`WorldProjection::overlap_blend`]):
//! each texel in the band becomes the mix of itself and the other lens's bilinear lookup at
//! its direction, so every lookup and integration point of the resampler and of `Remap`
//! reads the mix without a change to their loops. The band's weights and lookups are worked
//! out once for a picture size ([`OverlapBlend`]), so a frame pays one weighted sum per band
//! texel.

use super::azimuthal::{ab_to_dir_of, dir_to_ab_of, edge_integral_of};
use super::quadrature::gauss_legendre;
use super::{
    texel_range, Frame, Lens, OverlapBlend, Projection, RadialMap, Range, WorldProjection,
};
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

/// How a lens of a [`DualFisheye`] maps the angle from its axis to the radius on its image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LensModel {
    /// One of the single fisheye's lenses, `ρ(θ)` with `ρ(fov/2) = 1`.
    Standard(Lens),
    /// OpenCV's fisheye polynomial `θ_d = θ(1 + k₁θ² + k₂θ⁴ + k₃θ⁶ + k₄θ⁸)`, `[k₁, k₂, k₃, k₄]`
    /// (all zero: equidistant), normalised to `ρ = θ_d(θ)/θ_d(fov/2)`.
    Polynomial([f64; 4]),
}

impl LensModel {
    /// The whole fields of view the model covers, in degrees: a standard lens's
    /// [`Lens::fov_range`], the polynomial's `(0°, 360°]` (a lens sees at most the whole
    /// sphere).
    pub fn fov_range(self) -> Range {
        match self {
            LensModel::Standard(l) => l.fov_range(),
            LensModel::Polynomial(_) => Range::above(0.0).to(360.0).unit("°"),
        }
    }

    /// The model's name for messages: a lens's name, or `polynomial`.
    pub fn name(self) -> &'static str {
        match self {
            LensModel::Standard(l) => l.name(),
            LensModel::Polynomial(_) => "polynomial",
        }
    }
}

/// One lens of a [`DualFisheye`]: where its image circle lies in the picture and how it
/// maps directions onto it. Picture units: the picture's height (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FisheyeLens {
    /// The image circle's centre, `(x, y)` in picture units (`x ∈ [0, 2]`, `y` down).
    pub centre: DVec2,
    /// The image circle's radius (where `fov/2` lands), in picture units.
    pub radius: f64,
    /// The roll of the lens's image, degrees counter-clockwise in the picture.
    pub roll_deg: f64,
    /// The whole field of view, degrees, in `(0, 360]`.
    pub fov_deg: f64,
    /// The lens model.
    pub model: LensModel,
}

impl FisheyeLens {
    /// `v360`'s front lens: the right half's circle, equidistant, 180°.
    pub const FRONT: FisheyeLens = FisheyeLens {
        centre: DVec2::new(1.5, 0.5),
        radius: 0.5,
        roll_deg: 0.0,
        fov_deg: 180.0,
        model: LensModel::Standard(Lens::Equidistant),
    };
    /// `v360`'s back lens: the left half's circle, equidistant, 180°.
    pub const BACK: FisheyeLens = FisheyeLens {
        centre: DVec2::new(0.5, 0.5),
        radius: 0.5,
        roll_deg: 0.0,
        fov_deg: 180.0,
        model: LensModel::Standard(Lens::Equidistant),
    };

    /// Picture coordinates → this lens's disk coordinates `(a, b)` (b up, unit rim).
    #[inline]
    fn ab_of(&self, p: DVec2) -> DVec2 {
        DVec2::new(p.x - self.centre.x, self.centre.y - p.y) / self.radius
    }

    /// Disk coordinates → picture coordinates.
    #[inline]
    fn picture_of(&self, ab: DVec2) -> DVec2 {
        DVec2::new(
            self.centre.x + self.radius * ab.x,
            self.centre.y - self.radius * ab.y,
        )
    }

    /// Whether the circle lies wholly inside the picture.
    fn uncropped(&self) -> bool {
        let (c, r, e) = (self.centre, self.radius, 1e-12);
        c.x - r >= -e && c.x + r <= 2.0 + e && c.y - r >= -e && c.y + r <= 1.0 + e
    }
}

/// The polynomial lens: OpenCV's `θ_d(θ)`, normalised by `d_max = θ_d(θ_max)`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct PolyLens {
    frame: Frame,
    theta_max: f64,
    k: [f64; 4],
    d_max: f64,
}

impl PolyLens {
    #[inline]
    fn theta_d(&self, t: f64) -> f64 {
        let [k1, k2, k3, k4] = self.k;
        let t2 = t * t;
        t * (1.0 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4))))
    }

    /// `θ_d'(θ)`.
    #[inline]
    fn slope(k: &[f64; 4], t: f64) -> f64 {
        let [k1, k2, k3, k4] = *k;
        let t2 = t * t;
        1.0 + t2 * (3.0 * k1 + t2 * (5.0 * k2 + t2 * (7.0 * k3 + t2 * 9.0 * k4)))
    }

    /// The smallest `θ_d'` over `[0, θ_max]` and where it is: 4096 samples, then a golden
    /// section search around the smallest.
    fn min_slope(k: &[f64; 4], theta_max: f64) -> (f64, f64) {
        const N: usize = 4096;
        let at = |i: usize| theta_max * i as f64 / N as f64;
        let i = (0..=N)
            .min_by(|&a, &b| Self::slope(k, at(a)).total_cmp(&Self::slope(k, at(b))))
            .unwrap_or(0);
        let (mut lo, mut hi) = (at(i.saturating_sub(1)), at((i + 1).min(N)));
        let g = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..60 {
            let (a, b) = (hi - g * (hi - lo), lo + g * (hi - lo));
            if Self::slope(k, a) < Self::slope(k, b) {
                hi = b;
            } else {
                lo = a;
            }
        }
        let t = 0.5 * (lo + hi);
        let (s_t, s_i) = (Self::slope(k, t), Self::slope(k, at(i)));
        if s_t < s_i {
            (s_t, t)
        } else {
            (s_i, at(i))
        }
    }

    #[inline]
    fn rho_of_theta(&self, t: f64) -> f64 {
        self.theta_d(t) / self.d_max
    }

    /// θ at radius ρ ∈ [0, 1]: `θ_d(θ) = ρ·d_max` by Newton's method, kept inside a
    /// bracket that bisection shrinks where a step would leave it (`θ_d` is increasing).
    fn theta_of_rho(&self, rho: f64) -> f64 {
        let target = rho.clamp(0.0, 1.0) * self.d_max;
        let (mut lo, mut hi) = (0.0, self.theta_max);
        let mut t = rho.clamp(0.0, 1.0) * self.theta_max;
        for _ in 0..100 {
            let g = self.theta_d(t) - target;
            if g > 0.0 {
                hi = t;
            } else {
                lo = t;
            }
            let step = g / Self::slope(&self.k, t);
            let mut next = t - step;
            if !(next > lo && next < hi) {
                next = 0.5 * (lo + hi);
            }
            if (next - t).abs() <= 1e-16 * (1.0 + t) || hi - lo <= 1e-16 {
                return next;
            }
            t = next;
        }
        t
    }

    /// `H(ρ)/ρ²`, saturating at the rim; `d_max²/2` at the centre (θ ≈ d_max·ρ there).
    #[inline]
    fn h_over_rho2(&self, rho2: f64) -> f64 {
        if rho2 < 1e-300 {
            return 0.5 * self.d_max * self.d_max;
        }
        let half = 0.5 * self.theta_of_rho(rho2.min(1.0).sqrt());
        2.0 * half.sin().powi(2) / rho2
    }

    /// Solid angle per unit disk area: `sin θ · θ'(ρ)/ρ`, `θ'(ρ) = d_max/θ_d'(θ)`.
    #[inline]
    fn area_density_ab(&self, rho: f64) -> f64 {
        if rho > 1.0 {
            return 0.0;
        }
        let t = self.theta_of_rho(rho);
        let sin_over_rho = if t < 1e-8 { self.d_max } else { t.sin() / rho };
        sin_over_rho * self.d_max / Self::slope(&self.k, t)
    }
}

/// A lens's disk: a standard [`RadialMap`] or the polynomial.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Optic {
    Radial(RadialMap),
    Poly(PolyLens),
}

impl Optic {
    fn frame(&self) -> &Frame {
        match self {
            Optic::Radial(m) => m.frame(),
            Optic::Poly(p) => &p.frame,
        }
    }
    fn theta_max(&self) -> f64 {
        match self {
            Optic::Radial(m) => m.theta_max(),
            Optic::Poly(p) => p.theta_max,
        }
    }
    #[inline]
    fn dir_to_ab(&self, d: DVec3) -> Option<DVec2> {
        match self {
            Optic::Radial(m) => m.dir_to_ab(d),
            Optic::Poly(p) => dir_to_ab_of(&p.frame, p.theta_max, d, |t| p.rho_of_theta(t)),
        }
    }
    #[inline]
    fn ab_to_dir(&self, ab: DVec2) -> Option<DVec3> {
        match self {
            Optic::Radial(m) => m.ab_to_dir(ab, false),
            Optic::Poly(p) => ab_to_dir_of(&p.frame, ab, false, |r| p.theta_of_rho(r)),
        }
    }
    #[inline]
    fn area_density_ab(&self, rho: f64) -> f64 {
        match self {
            Optic::Radial(m) => m.area_density_ab(rho),
            Optic::Poly(p) => p.area_density_ab(rho),
        }
    }
    /// The solid angle this disk sees inside the polygon `corners` of its `(a, b)` plane,
    /// each edge integrated in `pieces` equal parts (more where an edge is long beside the
    /// disk, so that a rim it grazes without crossing does not spoil the quadrature).
    fn polygon_solid_angle(&self, corners: &[DVec2; 4], pieces: usize) -> f64 {
        let mut total = 0.0;
        for i in 0..4 {
            let (a, b) = (corners[i], corners[(i + 1) % 4]);
            for j in 0..pieces {
                let p0 = a + (b - a) * (j as f64 / pieces as f64);
                let p1 = a + (b - a) * ((j + 1) as f64 / pieces as f64);
                total += match self {
                    Optic::Radial(m) => m.edge_integral(p0, p1),
                    Optic::Poly(p) => edge_integral_of(p0, p1, |r2| p.h_over_rho2(r2)),
                };
            }
        }
        total.abs()
    }
}

/// A dual fisheye picture: two [`FisheyeLens`]es back to back in one 2:1 layer (see the
/// module documentation for the coordinates, the lens models, the solid angles and the
/// blend). Default: `v360`'s `dfisheye`.
///
/// ```
/// use mirrorball_core::{DualFisheye, WorldProjection};
/// use glam::{DVec2, DVec3};
/// let p = DualFisheye::default();
/// // The front lens (−Z) is the right half's centre, the back lens (+Z) the left half's.
/// let (_, uv) = p.dir_to_uv(DVec3::NEG_Z).unwrap();
/// assert!((uv - DVec2::new(0.75, 0.5)).length() < 1e-12);
/// let (_, uv) = p.dir_to_uv(DVec3::Z).unwrap();
/// assert!((uv - DVec2::new(0.25, 0.5)).length() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DualFisheye {
    rig: Frame,
    lenses: [FisheyeLens; 2],
    optics: [Optic; 2],
}

impl Default for DualFisheye {
    fn default() -> Self {
        DualFisheye::new(Frame::default(), FisheyeLens::FRONT, FisheyeLens::BACK).expect("valid")
    }
}

/// The name of lens `i` in messages.
fn lens_name(i: usize) -> &'static str {
    ["front", "back"][i]
}

impl DualFisheye {
    /// A dual fisheye whose front lens looks along `rig.forward` (with the rig's right and
    /// up before its roll) and back lens the opposite way. Refuses, naming the lens and the
    /// value: a field of view outside `(0, 360]` or beyond what the lens model reaches,
    /// a radius that is not positive, a circle wholly outside the picture (its centre more
    /// than a radius away from it), circles that overlap in the picture, non-finite values,
    /// and polynomial coefficients that make `θ_d` stop increasing within the field of view.
    /// What it refuses is the request's fault.
    pub fn new(
        rig: Frame,
        front: FisheyeLens,
        back: FisheyeLens,
    ) -> Result<DualFisheye, crate::Error> {
        DualFisheye::checked(rig, front, back).map_err(crate::Error::request)
    }

    fn checked(rig: Frame, front: FisheyeLens, back: FisheyeLens) -> Result<DualFisheye, String> {
        let lenses = [front, back];
        let frames = [rig, rig.turned_around()];
        let mut optics = Vec::with_capacity(2);
        for (i, (lens, frame)) in lenses.iter().zip(frames).enumerate() {
            optics.push(
                Self::optic(lens, frame)
                    .map_err(|e| format!("{} lens ({}): {e}", lens_name(i), lens.model.name()))?,
            );
        }
        let (a, b) = (&lenses[0], &lenses[1]);
        let gap = (a.centre - b.centre).length() - (a.radius + b.radius);
        if gap < -1e-9 {
            return Err(format!(
                "the front and back image circles overlap in the picture (centres {},{} and \
                 {},{}, radii {} and {}): each point of the picture belongs to one lens",
                a.centre.x, a.centre.y, b.centre.x, b.centre.y, a.radius, b.radius
            ));
        }
        Ok(DualFisheye {
            rig,
            lenses,
            optics: [optics[0], optics[1]],
        })
    }

    /// One lens's disk, looking along `frame` before its roll; or what is wrong with it.
    fn optic(lens: &FisheyeLens, frame: Frame) -> Result<Optic, String> {
        let fov = lens
            .model
            .fov_range()
            .check("fov", lens.fov_deg)
            .map_err(|e| e.message)?;
        let (c, r) = (lens.centre, lens.radius);
        if !(c.x.is_finite() && c.y.is_finite() && lens.roll_deg.is_finite()) {
            return Err(format!(
                "the centre {},{} and roll {} must be finite",
                c.x, c.y, lens.roll_deg
            ));
        }
        if !(r.is_finite() && r > 0.0) {
            return Err(format!("radius {r} must be over 0 (picture heights)"));
        }
        let outside = DVec2::new(
            (-c.x).max(c.x - 2.0).max(0.0),
            (-c.y).max(c.y - 1.0).max(0.0),
        )
        .length();
        if outside >= r {
            return Err(format!(
                "the image circle (centre {},{}, radius {r}) lies outside the 2×1 picture \
                 (its centre is {outside} picture heights beyond the edge, more than its radius)",
                c.x, c.y
            ));
        }
        // The roll: the lens's right appears at `roll` counter-clockwise in the picture, so
        // picture (a, b) = R(roll)·(x, y) and the picture's axes are these directions.
        let (s, co) = lens.roll_deg.to_radians().sin_cos();
        let rolled = Frame {
            right: frame.right * co - frame.up * s,
            up: frame.right * s + frame.up * co,
            forward: frame.forward,
        };
        let theta_max = 0.5 * fov.to_radians();
        match lens.model {
            LensModel::Standard(l) => RadialMap::new(rolled, l, theta_max)
                .map(Optic::Radial)
                .ok_or_else(|| format!("fov={fov}: outside the {} lens's reach", l.name())),
            LensModel::Polynomial(k) => {
                if k.iter().any(|v| !v.is_finite()) {
                    return Err(format!("k={k:?}: the coefficients must be finite"));
                }
                let (slope, at) = PolyLens::min_slope(&k, theta_max);
                if slope <= 1e-9 {
                    return Err(format!(
                        "k={},{},{},{}: θ_d(θ) = θ(1 + k1θ² + k2θ⁴ + k3θ⁶ + k4θ⁸) stops \
                         increasing at θ = {:.2}°, inside the field of view (fov/2 = {}°), so \
                         the radius on the picture would not tell the angle",
                        k[0],
                        k[1],
                        k[2],
                        k[3],
                        at.to_degrees(),
                        0.5 * fov
                    ));
                }
                let mut p = PolyLens {
                    frame: rolled,
                    theta_max,
                    k,
                    d_max: 1.0,
                };
                p.d_max = p.theta_d(theta_max);
                Ok(Optic::Poly(p))
            }
        }
    }

    /// The rig's frame: the front lens looks along its `forward`.
    pub fn rig(&self) -> &Frame {
        &self.rig
    }

    /// The lenses: front (0) and back (1).
    pub fn lenses(&self) -> &[FisheyeLens; 2] {
        &self.lenses
    }

    /// Whether some directions are seen by both lenses (fields of view adding up to more
    /// than 360°).
    pub fn overlaps(&self) -> bool {
        self.optics[0].theta_max() + self.optics[1].theta_max() > PI + 1e-12
    }

    /// The picture-coordinate `uv` where lens `i` sees unit direction `d`, when it does
    /// (within its field of view, and inside the picture).
    #[inline]
    pub fn lens_dir_to_uv(&self, i: usize, d: DVec3) -> Option<DVec2> {
        let ab = self.optics[i].dir_to_ab(d)?;
        let p = self.lenses[i].picture_of(ab);
        let uv = DVec2::new(0.5 * p.x, p.y);
        let e = 1e-12;
        ((-e..=1.0 + e).contains(&uv.x) && (-e..=1.0 + e).contains(&uv.y)).then_some(uv)
    }

    /// The direction lens `i` sees at `uv`, when `uv` is inside its circle.
    #[inline]
    pub fn lens_uv_to_dir(&self, i: usize, uv: DVec2) -> Option<DVec3> {
        let ab = self.lenses[i].ab_of(DVec2::new(2.0 * uv.x, uv.y));
        self.optics[i].ab_to_dir(ab)
    }

    /// The lens whose circle holds `uv`.
    #[inline]
    pub fn lens_at(&self, uv: DVec2) -> Option<usize> {
        let p = DVec2::new(2.0 * uv.x, uv.y);
        (0..2).find(|&i| self.lenses[i].ab_of(p).length_squared() <= 1.0 + 2e-12)
    }

    /// The weights of the front and back lenses in the blend at unit direction `d` (see the
    /// module docs): `[1, 0]` or `[0, 1]` where one lens alone sees it, smoothstep of the
    /// angles inside the two rims where both do, always adding up to 1; `None` where
    /// neither sees it.
    pub fn blend_weights(&self, d: DVec3) -> Option<[f64; 2]> {
        let seen = [0, 1].map(|i| self.lens_dir_to_uv(i, d).is_some());
        match seen {
            [false, false] => None,
            [true, false] => Some([1.0, 0.0]),
            [false, true] => Some([0.0, 1.0]),
            [true, true] => {
                let m = [0, 1].map(|i| {
                    let o = &self.optics[i];
                    (o.theta_max() - o.frame().forward.dot(d).clamp(-1.0, 1.0).acos()).max(0.0)
                });
                let sum = m[0] + m[1];
                let t = if sum > 0.0 { m[0] / sum } else { 0.5 };
                let w = t * t * (3.0 - 2.0 * t);
                Some([w, 1.0 - w])
            }
        }
    }

    /// The solid angle lens `i` sees inside the picture: its whole cap `2π(1 − cos(fov/2))`
    /// unless its circle is cropped, else Green's theorem around the picture's edges in its
    /// disk.
    pub fn lens_solid_angle(&self, i: usize) -> f64 {
        let l = &self.lenses[i];
        if l.uncropped() {
            return 2.0 * PI * (1.0 - self.optics[i].theta_max().cos());
        }
        let corners = [
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(2.0, 1.0),
            DVec2::new(0.0, 1.0),
        ]
        .map(|p| l.ab_of(p));
        self.optics[i].polygon_solid_angle(&corners, 512)
    }

    /// What the texels' solid angles add up to: each lens's solid angle inside the picture,
    /// added (the directions both lenses see counted twice, once by each lens's texels).
    pub fn seen_solid_angle(&self) -> f64 {
        self.lens_solid_angle(0) + self.lens_solid_angle(1)
    }

    /// The solid angle both lenses see inside the picture, where a circle is cropped: the
    /// band `θ_front ∈ [π − fov_back/2, fov_front/2]`, integrated over `sin θ dθ dψ` with
    /// 16-point Gauss–Legendre on 32 pieces in θ and 2048 steps in ψ (the crop makes the
    /// integrand a step, so this is good to about 1e-4 of the band).
    fn cropped_overlap(&self) -> f64 {
        let (t0, t1) = (PI - self.optics[1].theta_max(), self.optics[0].theta_max());
        let f = self.optics[0].frame();
        const PSI: usize = 2048;
        const PIECES: usize = 32;
        let mut total = 0.0;
        for k in 0..PIECES {
            let (a, b) = (
                t0 + (t1 - t0) * k as f64 / PIECES as f64,
                t0 + (t1 - t0) * (k + 1) as f64 / PIECES as f64,
            );
            total += gauss_legendre(a, b, |t| {
                let (st, ct) = t.sin_cos();
                let seen = (0..PSI)
                    .filter(|&j| {
                        let psi = 2.0 * PI * (j as f64 + 0.5) / PSI as f64;
                        let (sp, cp) = psi.sin_cos();
                        let d = f.forward * ct + (f.right * cp + f.up * sp) * st;
                        self.lens_dir_to_uv(0, d).is_some() && self.lens_dir_to_uv(1, d).is_some()
                    })
                    .count();
                st * 2.0 * PI * seen as f64 / PSI as f64
            });
        }
        total
    }

    /// Lens `i`'s share of texel `(x, y)` of a `w`×`h` picture: Green's theorem along the
    /// texel's edges in its disk (zero where the texel's box misses the circle's).
    fn texel_part(&self, i: usize, u: (f64, f64), v: (f64, f64)) -> f64 {
        let l = &self.lenses[i];
        let (x0, x1) = (2.0 * u.0, 2.0 * u.1);
        if x1 < l.centre.x - l.radius
            || x0 > l.centre.x + l.radius
            || v.1 < l.centre.y - l.radius
            || v.0 > l.centre.y + l.radius
        {
            return 0.0;
        }
        let corners = [
            DVec2::new(x0, v.0),
            DVec2::new(x1, v.0),
            DVec2::new(x1, v.1),
            DVec2::new(x0, v.1),
        ]
        .map(|p| l.ab_of(p));
        self.optics[i].polygon_solid_angle(&corners, 1)
    }
}

impl WorldProjection for DualFisheye {
    fn layer_count(&self) -> usize {
        1
    }

    /// `size`×`size/2`: the two circles side by side.
    fn layer_extent(&self, size: u32) -> (u32, u32) {
        (size, (size / 2).max(1))
    }

    #[inline]
    fn dir_to_uv(&self, d: DVec3) -> Option<(usize, DVec2)> {
        let order = if self.rig.forward.dot(d) >= 0.0 {
            [0, 1]
        } else {
            [1, 0]
        };
        order
            .into_iter()
            .find_map(|i| self.lens_dir_to_uv(i, d))
            .map(|uv| (0, uv))
    }

    #[inline]
    fn uv_to_dir(&self, layer: usize, uv: DVec2) -> Option<DVec3> {
        if layer != 0 {
            return None;
        }
        (0..2).find_map(|i| self.lens_uv_to_dir(i, uv))
    }

    #[inline]
    fn density(&self, layer: usize, uv: DVec2) -> f64 {
        if layer != 0 {
            return 0.0;
        }
        let p = DVec2::new(2.0 * uv.x, uv.y);
        for (l, o) in self.lenses.iter().zip(&self.optics) {
            let rho = l.ab_of(p).length();
            if rho <= 1.0 {
                return 2.0 / (l.radius * l.radius) * o.area_density_ab(rho);
            }
        }
        0.0
    }

    fn texel_solid_angle(&self, layer: usize, x: u32, y: u32, w: u32, h: u32) -> f64 {
        if layer != 0 {
            return 0.0;
        }
        let (u, v) = (texel_range(x, w), texel_range(y, h));
        self.texel_part(0, u, v) + self.texel_part(1, u, v)
    }

    /// The union of what the two lenses see inside the picture: 4π when the fields of view
    /// add up to 360° or more and neither circle is cropped; the two caps when they do not
    /// overlap; else both less their overlap (numerically, see `cropped_overlap`).
    fn covered_solid_angle(&self) -> f64 {
        let seen = self.seen_solid_angle();
        if !self.overlaps() {
            return seen;
        }
        if self.lenses.iter().all(FisheyeLens::uncropped) {
            return 4.0 * PI;
        }
        (seen - self.cropped_overlap()).min(4.0 * PI)
    }

    /// Outside both circles: the nearest circle's rim.
    fn nearest_covered(&self, _layer: usize, uv: DVec2) -> DVec2 {
        let p = DVec2::new(2.0 * uv.x, uv.y);
        let mut best = (f64::INFINITY, uv);
        for l in &self.lenses {
            let off = p - l.centre;
            let dist = off.length();
            if dist <= l.radius {
                return uv;
            }
            let gap = dist - l.radius;
            if gap < best.0 {
                let q = l.centre + off * (l.radius * (1.0 - 1e-9) / dist);
                best = (gap, DVec2::new(0.5 * q.x, q.y));
            }
        }
        best.1
    }

    fn blends_overlap(&self) -> bool {
        self.overlaps()
    }

    /// The texels in the band both lenses see, each mixed with the other lens's bilinear
    /// lookup at its direction by [`DualFisheye::blend_weights`]; `None` when the lenses
    /// do not overlap.
    fn overlap_blend(&self, (w, h): (u32, u32), layers: usize) -> Option<OverlapBlend> {
        if !self.overlaps() || layers != 1 {
            return None;
        }
        let proj = Projection::DualFisheye(*self);
        Some(OverlapBlend::from_fn((w, h), |x, y| {
            let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
            let own = self.lens_at(uv)?;
            let d = self.lens_uv_to_dir(own, uv)?;
            let ouv = self.lens_dir_to_uv(1 - own, d)?;
            let w_own = self.blend_weights(d)?[own] as f32;
            if w_own >= 1.0 {
                return None;
            }
            let taps = crate::envmap::lookup_taps(&proj, 0, (w, h), ouv);
            Some((w_own, taps.map(|(_, tx, ty, wt)| (ty * w + tx, wt))))
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Image;

    /// SplitMix64 in [0, 1).
    fn rng(mut s: u64) -> impl FnMut() -> f64 {
        move || {
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn lens(cx: f64, cy: f64, r: f64, roll: f64, fov: f64, model: LensModel) -> FisheyeLens {
        FisheyeLens {
            centre: DVec2::new(cx, cy),
            radius: r,
            roll_deg: roll,
            fov_deg: fov,
            model,
        }
    }

    /// A camera-like rig: 200° lenses, one equisolid, one polynomial, rolled, off centre,
    /// the polynomial's circle cropped at the top and bottom.
    fn camera() -> DualFisheye {
        let rig = Frame::looking_along(DVec3::new(0.2, -0.1, -1.0)).unwrap();
        DualFisheye::new(
            rig,
            lens(
                1.49,
                0.51,
                0.47,
                1.5,
                200.0,
                LensModel::Standard(Lens::Equisolid),
            ),
            lens(
                0.5,
                0.5,
                0.52,
                -2.0,
                204.0,
                LensModel::Polynomial([0.02, -0.004, 0.0003, 0.0]),
            ),
        )
        .unwrap()
    }

    fn cases() -> Vec<DualFisheye> {
        vec![DualFisheye::default(), camera()]
    }

    #[test]
    fn round_trips_inside_each_lens_within_1e_10() {
        for p in cases() {
            for i in 0..2 {
                let mut r = rng(5 + i as u64);
                let (mut worst_dir, mut worst_uv, mut n) = (0.0f64, 0.0f64, 0);
                let l = p.lenses()[i];
                while n < 100_000 {
                    // A uniform point of the circle's box; keep those inside the circle and
                    // the picture.
                    let q = l.centre + l.radius * DVec2::new(2.0 * r() - 1.0, 2.0 * r() - 1.0);
                    let uv = DVec2::new(0.5 * q.x, q.y);
                    if (q - l.centre).length() > l.radius * (1.0 - 1e-9)
                        || !(0.0..=1.0).contains(&uv.x)
                        || !(0.0..=1.0).contains(&uv.y)
                    {
                        continue;
                    }
                    n += 1;
                    let d = p.lens_uv_to_dir(i, uv).expect("inside the circle");
                    assert!((d.length() - 1.0).abs() < 1e-12);
                    let back = p.lens_dir_to_uv(i, d).expect("seen by its lens");
                    worst_uv = worst_uv.max((back - uv).length());
                    let again = p.lens_uv_to_dir(i, back).unwrap();
                    worst_dir = worst_dir.max((d - again).length());
                }
                assert!(worst_uv < 1e-10, "lens {i}: uv round trip {worst_uv:e}");
                assert!(
                    worst_dir < 1e-10,
                    "lens {i}: direction round trip {worst_dir:e}"
                );
            }
        }
    }

    #[test]
    fn directions_pick_the_nearer_axis_and_come_back() {
        for p in cases() {
            let mut r = rng(9);
            let mut worst = 0.0f64;
            for _ in 0..100_000 {
                let z = 2.0 * r() - 1.0;
                let phi = 2.0 * PI * r();
                let s = (1.0 - z * z).sqrt();
                let d = DVec3::new(s * phi.cos(), z, s * phi.sin());
                let Some((_, uv)) = p.dir_to_uv(d) else {
                    continue;
                };
                let lens = p.lens_at(uv).unwrap();
                let nearer = if p.rig().forward.dot(d) >= 0.0 { 0 } else { 1 };
                if p.lens_dir_to_uv(nearer, d).is_some() {
                    assert_eq!(lens, nearer, "{d}");
                }
                worst = worst.max((d - p.uv_to_dir(0, uv).unwrap()).length());
            }
            assert!(worst < 1e-10, "{worst:e}");
        }
    }

    #[test]
    fn v360_layout_by_hand() {
        // v360's dfisheye (5.1 `xyz_to_dfisheye`): the front lens (−Z ours, +z v360's) is
        // the right half with +X to the right; the back lens the left half with −X to the
        // right; a direction at θ from the axis lies θ/90° of the half-height from the
        // centre.
        let p = DualFisheye::default();
        let t = 30f64.to_radians();
        let d = DVec3::new(t.sin(), 0.0, -t.cos());
        let (_, uv) = p.dir_to_uv(d).unwrap();
        assert!((uv - DVec2::new(0.75 + 0.25 * 30.0 / 90.0, 0.5)).length() < 1e-12);
        let d = DVec3::new(t.sin(), 0.0, t.cos());
        let (_, uv) = p.dir_to_uv(d).unwrap();
        assert!((uv - DVec2::new(0.25 - 0.25 * 30.0 / 90.0, 0.5)).length() < 1e-12);
        let d = DVec3::new(0.0, t.sin(), -t.cos());
        let (_, uv) = p.dir_to_uv(d).unwrap();
        assert!((uv - DVec2::new(0.75, 0.5 - 0.5 * 30.0 / 90.0)).length() < 1e-12);
    }

    #[test]
    fn polynomial_with_zero_coefficients_is_equidistant() {
        let a = DualFisheye::default();
        let poly = |l: FisheyeLens| FisheyeLens {
            model: LensModel::Polynomial([0.0; 4]),
            ..l
        };
        let b = DualFisheye::new(
            Frame::default(),
            poly(FisheyeLens::FRONT),
            poly(FisheyeLens::BACK),
        )
        .unwrap();
        let mut r = rng(3);
        for _ in 0..1000 {
            let uv = DVec2::new(r(), r());
            match (a.uv_to_dir(0, uv), b.uv_to_dir(0, uv)) {
                (Some(x), Some(y)) => assert!((x - y).length() < 1e-13),
                (None, None) => {}
                other => panic!("{uv}: {other:?}"),
            }
            assert!((a.density(0, uv) - b.density(0, uv)).abs() < 1e-9 * a.density(0, uv).max(1.0));
        }
    }

    /// The density is `|∂d/∂u × ∂d/∂v|`: central differences of `uv_to_dir`.
    #[test]
    fn density_is_the_jacobian() {
        for p in cases() {
            let mut r = rng(17);
            let mut checked = 0;
            while checked < 2000 {
                let uv = DVec2::new(r(), r());
                let e = 1e-6;
                let at = |du: f64, dv: f64| p.uv_to_dir(0, uv + DVec2::new(du, dv));
                let (Some(xp), Some(xm), Some(yp), Some(ym)) =
                    (at(e, 0.0), at(-e, 0.0), at(0.0, e), at(0.0, -e))
                else {
                    continue;
                };
                if p.lens_at(uv + DVec2::splat(3e-6)) != p.lens_at(uv - DVec2::splat(3e-6)) {
                    continue;
                }
                checked += 1;
                let fd = ((xp - xm) / (2.0 * e))
                    .cross((yp - ym) / (2.0 * e))
                    .length();
                let exact = p.density(0, uv);
                assert!(
                    (fd - exact).abs() < 1e-5 * exact,
                    "{uv}: finite differences {fd}, density {exact}"
                );
            }
        }
    }

    #[test]
    fn texel_solid_angles_sum_to_what_each_lens_sees() {
        for p in cases() {
            for size in [16u32, 37] {
                let (w, h) = p.layer_extent(size);
                let mut total = 0.0;
                for y in 0..h {
                    for x in 0..w {
                        let s = p.texel_solid_angle(0, x, y, w, h);
                        assert!(s >= 0.0 && s.is_finite());
                        total += s;
                    }
                }
                let want = p.seen_solid_angle();
                assert!(
                    (total - want).abs() < 1e-9 * want,
                    "size {size}: {total} vs {want}"
                );
            }
        }
        // Uncropped: each lens sees its whole cap, 2π(1 − cos(fov/2)); together 4π.
        let d = DualFisheye::default();
        assert!((d.seen_solid_angle() - 4.0 * PI).abs() < 1e-12);
        assert!((d.covered_solid_angle() - 4.0 * PI).abs() < 1e-12);
        let wide = |fov| FisheyeLens {
            fov_deg: fov,
            ..FisheyeLens::FRONT
        };
        let w = DualFisheye::new(
            Frame::default(),
            wide(200.0),
            FisheyeLens {
                fov_deg: 220.0,
                ..FisheyeLens::BACK
            },
        )
        .unwrap();
        let cap = |deg: f64| 2.0 * PI * (1.0 - (0.5 * deg).to_radians().cos());
        assert!((w.seen_solid_angle() - cap(200.0) - cap(220.0)).abs() < 1e-10);
        assert_eq!(w.covered_solid_angle(), 4.0 * PI);
        // Narrow lenses leave a band unseen: the two caps.
        let n = DualFisheye::new(Frame::default(), wide(150.0), FisheyeLens::BACK).unwrap();
        assert!((n.covered_solid_angle() - cap(150.0) - cap(180.0)).abs() < 1e-10);
    }

    /// The cropped rig's union against a brute-force count of directions seen.
    #[test]
    fn covered_solid_angle_of_a_cropped_rig_against_counting() {
        // The back circle cropped at the top and bottom to θ ≈ 85°, the front lens seeing
        // the back's θ ≥ 88°: slivers of sky and ground are seen by neither.
        let p = DualFisheye::new(
            Frame::default(),
            lens(
                1.55,
                0.5,
                0.45,
                0.0,
                184.0,
                LensModel::Standard(Lens::Equisolid),
            ),
            lens(
                0.5,
                0.5,
                0.6,
                3.0,
                204.0,
                LensModel::Polynomial([0.02, -0.004, 0.0, 0.0]),
            ),
        )
        .unwrap();
        let mut r = rng(21);
        let n = 400_000;
        let seen = (0..n)
            .filter(|_| {
                let z = 2.0 * r() - 1.0;
                let phi = 2.0 * PI * r();
                let s = (1.0 - z * z).sqrt();
                p.dir_to_uv(DVec3::new(s * phi.cos(), z, s * phi.sin()))
                    .is_some()
            })
            .count();
        let counted = 4.0 * PI * seen as f64 / n as f64;
        let exact = p.covered_solid_angle();
        // Standard error of the count: 4π·√(q(1 − q)/n) ≈ 0.003 sr here.
        assert!((counted - exact).abs() < 0.015, "{counted} vs {exact}");
        assert!(exact < 4.0 * PI && exact < p.seen_solid_angle());
    }

    #[test]
    fn blend_weights_add_to_one_and_are_continuous() {
        let p = camera();
        let mut r = rng(33);
        let mut mixed = 0;
        for _ in 0..50_000 {
            let z = 2.0 * r() - 1.0;
            let phi = 2.0 * PI * r();
            let s = (1.0 - z * z).sqrt();
            let d = DVec3::new(s * phi.cos(), z, s * phi.sin());
            let Some(w) = p.blend_weights(d) else {
                continue;
            };
            assert!((w[0] + w[1] - 1.0).abs() < 1e-15 && w[0] >= 0.0 && w[1] >= 0.0);
            if w[0] > 0.0 && w[1] > 0.0 {
                mixed += 1;
            }
            // A step of 1e-6 rad moves the weights by at most the smoothstep's slope
            // (1.5) over the band's width (≥ 10° here): no jumps inside the band.
            let e = DVec3::new(-d.z, 0.0, d.x).normalize_or(DVec3::X);
            let d2 = (d + e * 1e-6).normalize();
            if let Some(w2) = p.blend_weights(d2) {
                let both = |w: [f64; 2]| w[0] > 0.0 && w[1] > 0.0;
                if both(w) && both(w2) {
                    assert!((w[0] - w2[0]).abs() < 1e-5, "{d}: {w:?} → {w2:?}");
                }
            }
        }
        assert!(mixed > 1000, "{mixed} directions in the band");
        // At the middle of the band of equal lenses, half and half.
        let eq = DualFisheye::new(
            Frame::default(),
            FisheyeLens {
                fov_deg: 200.0,
                ..FisheyeLens::FRONT
            },
            FisheyeLens {
                fov_deg: 200.0,
                ..FisheyeLens::BACK
            },
        )
        .unwrap();
        let w = eq.blend_weights(DVec3::X).unwrap();
        assert!((w[0] - 0.5).abs() < 1e-12);
        // Near the front rim (θ = 99.9°), the back lens carries nearly all.
        let t = 99.9f64.to_radians();
        let w = eq
            .blend_weights(DVec3::new(t.sin(), 0.0, -t.cos()))
            .unwrap();
        assert!(w[0] < 1e-4, "{w:?}");
    }

    #[test]
    fn blend_of_a_constant_is_the_constant() {
        let p = camera();
        let mut img = Image::new(64, 32, 4);
        for v in img.data_mut().chunks_exact_mut(4) {
            v.copy_from_slice(&[0.25, 0.5, 2.0, 1.0]);
        }
        let blend = p.overlap_blend((64, 32), 1).expect("overlap");
        assert!(!blend.is_empty());
        let out = blend.apply(&img);
        for v in out.data().chunks_exact(4) {
            for (a, b) in v.iter().zip([0.25, 0.5, 2.0, 1.0]) {
                assert!((a - b).abs() < 1e-6, "{v:?}");
            }
        }
        // No overlap, no blend.
        assert!(DualFisheye::default().overlap_blend((64, 32), 1).is_none());
    }

    /// The planned blend is each texel's mix worked out directly: its lens, its direction,
    /// the other lens's bilinear lookup there (`envmap::bilinear`, the resampler's own) and
    /// the two lenses' weights, for a map of random texels, at one, three and four channels.
    #[test]
    fn the_planned_blend_is_the_blend_worked_out_texel_by_texel() {
        let mut r = rng(7);
        for p in cases().into_iter().filter(|p| p.overlaps()) {
            let proj = Projection::DualFisheye(p);
            for (w, h, c) in [(96u32, 48u32, 3usize), (61, 40, 1), (64, 32, 4)] {
                let mut img = Image::new(w, h, c);
                img.data_mut().iter_mut().for_each(|v| *v = r() as f32);
                let got = p.overlap_blend((w, h), 1).unwrap().apply(&img);
                let layers = std::slice::from_ref(&img);
                let mut mixed = 0;
                let mut other = [0.0f32; 4];
                for y in 0..h {
                    for x in 0..w {
                        let uv =
                            DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                        let mut want = img.get(x, y).to_vec();
                        let own = p.lens_at(uv);
                        let d = own.and_then(|i| p.lens_uv_to_dir(i, uv));
                        if let (Some(i), Some(d)) = (own, d) {
                            let wt = p.blend_weights(d).unwrap()[i] as f32;
                            if let Some(ouv) = p.lens_dir_to_uv(1 - i, d).filter(|_| wt < 1.0) {
                                crate::envmap::bilinear(&proj, layers, 0, ouv, &mut other[..c]);
                                for (t, o) in want.iter_mut().zip(&other) {
                                    *t = wt * *t + (1.0 - wt) * o;
                                }
                                mixed += 1;
                            }
                        }
                        for (a, b) in got.get(x, y).iter().zip(&want) {
                            assert!((a - b).abs() < 1e-5, "({x}, {y}): {a} vs {b}");
                        }
                    }
                }
                assert!(mixed > 0);
            }
        }
    }

    /// The resampler's hook reads every other projection's layers as they are (the same
    /// slice, so the same bits), and a dual fisheye's without overlap too.
    #[test]
    fn the_hook_leaves_other_projections_alone() {
        use crate::{EnvMap, ProjectionKind};
        for k in ProjectionKind::ALL {
            let m = EnvMap::from_fn(k.default_projection(), 8, 3, |d| {
                [d.x as f32, d.y as f32, d.z as f32, 1.0]
            });
            assert!(
                m.projection()
                    .overlap_blend((m.width(), m.height()), m.layers().len())
                    .is_none(),
                "{k}"
            );
        }
        // And where it blends, the resampler reads the blend: a dual fisheye whose lenses
        // disagree (front 1, back 0) converted to a lat-long shows the mix in the band.
        let p = DualFisheye::new(
            Frame::default(),
            FisheyeLens {
                fov_deg: 220.0,
                ..FisheyeLens::FRONT
            },
            FisheyeLens {
                fov_deg: 220.0,
                ..FisheyeLens::BACK
            },
        )
        .unwrap();
        let mut img = Image::new(128, 64, 3);
        for (i, t) in img.data_mut().chunks_exact_mut(3).enumerate() {
            t.fill(if i % 128 >= 64 { 1.0 } else { 0.0 });
        }
        let src = EnvMap::new(p.into(), vec![img]).unwrap();
        let ll = crate::resample(
            &src,
            ProjectionKind::LatLong.default_projection(),
            64,
            &Default::default(),
        );
        // Near the equator point +X (the band's middle) the front lens's weight:
        // 0.396 at texel (48, 16), 2.8° past +X towards the back lens.
        let ll_proj = ProjectionKind::LatLong.default_projection();
        for x in [44u32, 46, 47, 48, 50] {
            let uv = DVec2::new((x as f64 + 0.5) / 64.0, 16.5 / 32.0);
            let d = ll_proj.uv_to_dir(0, uv).unwrap();
            let want = p.blend_weights(d).unwrap()[0] as f32;
            let got = ll.layers()[0].get(x, 16)[0];
            assert!((got - want).abs() < 0.02, "{x}: {got} vs {want}");
        }
    }

    #[test]
    fn bad_lenses_are_refused_with_the_reason() {
        let try_front = |l: FisheyeLens| {
            DualFisheye::new(Frame::default(), l, FisheyeLens::BACK)
                .unwrap_err()
                .message
        };
        let f = FisheyeLens::FRONT;
        let e = try_front(FisheyeLens {
            fov_deg: 400.0,
            ..f
        });
        assert!(
            e.contains("front lens") && e.contains("fov=400") && e.contains("(0°, 360°]"),
            "{e}"
        );
        assert!(try_front(FisheyeLens { fov_deg: 0.0, ..f }).contains("fov=0"));
        assert!(try_front(FisheyeLens {
            fov_deg: f64::NAN,
            ..f
        })
        .contains("fov=NaN"));
        assert!(try_front(FisheyeLens { radius: -1.0, ..f }).contains("radius -1"));
        assert!(try_front(FisheyeLens {
            centre: DVec2::new(3.6, 0.5),
            ..f
        })
        .contains("outside"));
        assert!(try_front(FisheyeLens {
            centre: DVec2::new(0.9, 0.5),
            ..f
        })
        .contains("overlap"));
        let e = try_front(FisheyeLens {
            fov_deg: 200.0,
            model: LensModel::Polynomial([0.0, -0.2, 0.0, 0.0]),
            ..f
        });
        assert!(e.contains("stops increasing"), "{e}");
        let e = try_front(FisheyeLens {
            fov_deg: 200.0,
            model: LensModel::Standard(Lens::Orthographic),
            ..f
        });
        assert!(
            e.contains("front lens (orthographic): fov must be in (0°, 180°]; fov=200 was given"),
            "{e}"
        );
    }
}
