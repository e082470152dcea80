//! Disk-shaped (azimuthal) projections: the OpenGL sphere map, the dual paraboloid, the
//! angular light-probe map and fisheye lenses. They share one machine, [`RadialMap`]: a
//! direction at angle θ from the map's axis lands at radius `ρ(θ)` of the unit disk, in the
//! direction of its azimuth.
//!
//! Map coordinates: `a = 2u − 1` grows to the right, `b = 1 − 2v` grows upwards (row 0 is
//! the top of the picture), the disk is `a² + b² ≤ 1`.
//!
//! Solid angle: with `H(ρ) = 1 − cos θ(ρ)`, the solid angle inside radius ρ is `2π H(ρ)` and
//! the area element is `f(ρ) da db`, `f = H'(ρ)/ρ`. For a texel (any region `R`) Green's
//! theorem in polar form gives `∬_R f dA = ∮_∂R H(ρ) dψ`, an exact one-dimensional integral
//! along the four straight texel edges (on an edge `p(t) = p₀ + t·e`,
//! `dψ = (p₀ × e)/|p(t)|² dt`). `H` saturates at the rim, so the integral clips the texel to
//! the disk by itself; each edge is split where it crosses the rim and integrated with
//! 16-point Gauss–Legendre, which leaves errors near 1e-13.

use super::quadrature::gauss_legendre;
use super::{texel_range, Range, WorldProjection};
use glam::{DVec2, DVec3};
use std::f64::consts::{FRAC_PI_2, PI};

/// An orthonormal camera frame: where a map looks (`forward`) and which way is up and right
/// in its picture. `right = forward × up`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Image right.
    pub right: DVec3,
    /// Image up.
    pub up: DVec3,
    /// The direction the map looks along (its centre for fisheye and angular maps).
    pub forward: DVec3,
}

impl Default for Frame {
    /// Looking along −Z with +Y up and +X to the right, as an OpenGL camera does.
    fn default() -> Self {
        Frame {
            right: DVec3::X,
            up: DVec3::Y,
            forward: DVec3::NEG_Z,
        }
    }
}

impl Frame {
    /// The default frame (looking along −Z, +Y up) turned by the rotation `m`: its axes
    /// are `m`'s images of +X, +Y and −Z.
    pub fn turned(m: glam::DMat3) -> Frame {
        Frame {
            right: m * DVec3::X,
            up: m * DVec3::Y,
            forward: m * DVec3::NEG_Z,
        }
    }

    /// The frame looking along `forward` with up as close to +Y as possible (+Z… when
    /// `forward` is vertical: looking up (+Y) gets up = +Z, looking down gets up = −Z).
    /// Returns `None` for a zero or non-finite vector.
    ///
    /// ```
    /// use mirrorball_core::Frame;
    /// use glam::DVec3;
    /// let f = Frame::looking_along(DVec3::new(0.0, 0.0, -2.0)).unwrap();
    /// assert!((f.right - DVec3::X).length() < 1e-12 && (f.up - DVec3::Y).length() < 1e-12);
    /// ```
    pub fn looking_along(forward: DVec3) -> Option<Frame> {
        let f = forward.try_normalize()?;
        let hint = if f.y.abs() > 1.0 - 1e-9 {
            DVec3::new(0.0, 0.0, f.y.signum())
        } else {
            DVec3::Y
        };
        let right = f.cross(hint).normalize();
        let up = right.cross(f);
        Some(Frame {
            right,
            up,
            forward: f,
        })
    }

    /// The frame looking along `forward` whose up is `up` made perpendicular to it (right =
    /// forward × up). `None` for zero or non-finite vectors, or `up` along `forward`.
    pub fn looking_along_up(forward: DVec3, up: DVec3) -> Option<Frame> {
        let f = forward.try_normalize()?;
        let right = f.cross(up).try_normalize()?;
        Some(Frame {
            right,
            up: right.cross(f),
            forward: f,
        })
    }

    /// `(right·d, up·d, forward·d)`.
    #[inline]
    pub fn to_local(&self, d: DVec3) -> DVec3 {
        DVec3::new(self.right.dot(d), self.up.dot(d), self.forward.dot(d))
    }

    /// The same frame turned half a turn about its up axis (looking backwards).
    pub fn turned_around(&self) -> Frame {
        Frame {
            right: -self.right,
            up: self.up,
            forward: -self.forward,
        }
    }
}

/// How a lens maps the angle θ from its axis to the radius ρ ∈ [0, 1] on the image, with
/// `θ_max` at the rim.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Lens {
    /// `ρ = θ/θ_max` (f-theta; the Omnimax lens, Debevec's angular map).
    Equidistant,
    /// `ρ = sin(θ/2)/sin(θ_max/2)`: equal-area (the sphere map is this with θ_max = π).
    Equisolid,
    /// `ρ = tan(θ/2)/tan(θ_max/2)`: conformal (a paraboloid half is this with θ_max = π/2).
    Stereographic,
    /// `ρ = sin θ / sin θ_max`, θ_max ≤ π/2.
    Orthographic,
}

impl crate::Choice for Lens {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (
            Lens::Equidistant,
            &["equidistant", "f-theta", "ftheta", "linear"],
        ),
        (
            Lens::Equisolid,
            &["equisolid", "equal-area", "equisolid-angle"],
        ),
        (Lens::Stereographic, &["stereographic", "conformal"]),
        (Lens::Orthographic, &["orthographic"]),
    ];
}

crate::choice_traits!(Lens);

impl Lens {
    /// The canonical name (see [`crate::Choice`]).
    pub fn name(self) -> &'static str {
        crate::Choice::name(self)
    }

    /// The largest half field of view the lens supports.
    pub fn max_half_fov(self) -> f64 {
        match self {
            Lens::Equidistant | Lens::Equisolid => PI,
            Lens::Stereographic => PI * (1.0 - 1e-6),
            Lens::Orthographic => FRAC_PI_2,
        }
    }

    /// The whole fields of view the lens covers, in degrees: `(0°, 2·max_half_fov]` (a
    /// stereographic lens stops just short of 360°, where the antipode would lie at
    /// infinity). [`Fisheye::new`] checks with it; messages print it.
    pub fn fov_range(self) -> Range {
        Range::above(0.0)
            .to(2.0 * self.max_half_fov().to_degrees())
            .unit("°")
    }
}

/// A disk map: a [`Lens`] with half field of view `theta_max` looking along a [`Frame`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadialMap {
    frame: Frame,
    lens: Lens,
    theta_max: f64,
    /// Lens constant: θ_max, sin(θ_max/2), tan(θ_max/2) or sin θ_max.
    k: f64,
}

impl RadialMap {
    /// A disk map, or `None` if `theta_max` is outside `(0, lens.max_half_fov()]`.
    pub fn new(frame: Frame, lens: Lens, theta_max: f64) -> Option<RadialMap> {
        if !(theta_max > 0.0 && theta_max <= lens.max_half_fov() + 1e-12) {
            return None;
        }
        let k = match lens {
            Lens::Equidistant => theta_max,
            Lens::Equisolid => (0.5 * theta_max).sin(),
            Lens::Stereographic => (0.5 * theta_max).tan(),
            Lens::Orthographic => theta_max.sin(),
        };
        Some(RadialMap {
            frame,
            lens,
            theta_max,
            k,
        })
    }

    /// The frame.
    pub fn frame(&self) -> &Frame {
        &self.frame
    }
    /// The lens.
    pub fn lens(&self) -> Lens {
        self.lens
    }
    /// The lens constant `k = f(θ_max)` (θ_max, sin(θ_max/2), tan(θ_max/2) or sin θ_max):
    /// `ρ = f(θ)/k`.
    pub fn lens_constant(&self) -> f64 {
        self.k
    }
    /// Half the field of view, radians.
    pub fn theta_max(&self) -> f64 {
        self.theta_max
    }

    /// Radius on the image of a direction at angle θ from the axis.
    #[inline]
    pub fn rho_of_theta(&self, theta: f64) -> f64 {
        match self.lens {
            Lens::Equidistant => theta / self.k,
            Lens::Equisolid => (0.5 * theta).sin() / self.k,
            Lens::Stereographic => (0.5 * theta).tan() / self.k,
            Lens::Orthographic => theta.sin() / self.k,
        }
    }

    /// Angle from the axis at image radius ρ (may extend past the rim where the lens allows).
    #[inline]
    pub fn theta_of_rho(&self, rho: f64) -> f64 {
        match self.lens {
            Lens::Equidistant => rho * self.k,
            Lens::Equisolid => 2.0 * (rho * self.k).min(1.0).asin(),
            Lens::Stereographic => 2.0 * (rho * self.k).atan(),
            Lens::Orthographic => (rho * self.k).min(1.0).asin(),
        }
    }

    /// `H(ρ)/ρ² = (1 − cos θ(ρ))/ρ²`, saturating at the rim, finite at ρ = 0.
    #[inline]
    fn h_over_rho2(&self, rho2: f64) -> f64 {
        let k = self.k;
        let r2 = rho2.min(1.0);
        let h = match self.lens {
            Lens::Equisolid => 2.0 * k * k * r2,
            Lens::Stereographic => 2.0 * k * k * r2 / (1.0 + k * k * r2),
            Lens::Equidistant => {
                let half = 0.5 * k * r2.sqrt();
                if half < 1e-6 {
                    // 1 − cos θ = 2 sin²(θ/2) ≈ θ²/2 (1 − θ²/12)
                    return 0.5 * k * k * (1.0 - k * k * r2 / 12.0) * (r2 / rho2.max(1e-300));
                }
                2.0 * half.sin().powi(2)
            }
            Lens::Orthographic => {
                let s2 = k * k * r2;
                s2 / (1.0 + (1.0 - s2).sqrt())
            }
        };
        if rho2 < 1e-300 {
            // Limit ρ → 0 of H/ρ² = f(0)/2.
            return 0.5 * self.area_density_ab(0.0);
        }
        h / rho2
    }

    /// Solid angle per unit area of the `(a, b)` disk at radius ρ: `f(ρ) = H'(ρ)/ρ`.
    #[inline]
    pub fn area_density_ab(&self, rho: f64) -> f64 {
        if rho > 1.0 {
            return 0.0;
        }
        let k = self.k;
        match self.lens {
            Lens::Equisolid => 4.0 * k * k,
            Lens::Stereographic => {
                let q = 1.0 + k * k * rho * rho;
                4.0 * k * k / (q * q)
            }
            Lens::Equidistant => {
                let t = k * rho;
                if t < 1e-8 {
                    k * k
                } else {
                    k * t.sin() / rho
                }
            }
            Lens::Orthographic => {
                let s2 = (k * rho).powi(2);
                k * k / (1.0 - s2).max(1e-300).sqrt()
            }
        }
    }

    /// The solid angle the disk covers: `2π(1 − cos θ_max)`.
    pub fn covered_solid_angle(&self) -> f64 {
        2.0 * PI * (1.0 - self.theta_max.cos())
    }

    /// Disk coordinates `(a, b)` of unit direction `d`, or `None` beyond θ_max.
    #[inline]
    pub fn dir_to_ab(&self, d: DVec3) -> Option<DVec2> {
        dir_to_ab_of(&self.frame, self.theta_max, d, |t| self.rho_of_theta(t))
    }

    /// The direction at disk coordinates `(a, b)`; with `extend`, also past the rim as far as
    /// the lens formula goes (θ ≤ π).
    #[inline]
    pub fn ab_to_dir(&self, ab: DVec2, extend: bool) -> Option<DVec3> {
        ab_to_dir_of(&self.frame, ab, extend, |r| self.theta_of_rho(r))
    }

    #[inline]
    fn uv_to_ab(uv: DVec2) -> DVec2 {
        DVec2::new(2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y)
    }
    #[inline]
    fn ab_to_uv(ab: DVec2) -> DVec2 {
        DVec2::new(0.5 * (ab.x + 1.0), 0.5 * (1.0 - ab.y))
    }

    /// Exact solid angle of the `uv` rectangle `[u0,u1]×[v0,v1]` clipped to the disk.
    pub fn rect_solid_angle(&self, u0: f64, u1: f64, v0: f64, v1: f64) -> f64 {
        let (a0, a1) = (2.0 * u0 - 1.0, 2.0 * u1 - 1.0);
        let (b0, b1) = (1.0 - 2.0 * v1, 1.0 - 2.0 * v0);
        let corners = [
            DVec2::new(a0, b0),
            DVec2::new(a1, b0),
            DVec2::new(a1, b1),
            DVec2::new(a0, b1),
        ];
        let mut total = 0.0;
        for i in 0..4 {
            total += self.edge_integral(corners[i], corners[(i + 1) % 4]);
        }
        total.abs()
    }

    /// `∫ H(ρ) dψ` along the segment `p0 → p1`: summed around a polygon of the `(a, b)`
    /// plane, its solid angle inside the disk (signed by its orientation).
    pub(super) fn edge_integral(&self, p0: DVec2, p1: DVec2) -> f64 {
        edge_integral_of(p0, p1, |r2| self.h_over_rho2(r2))
    }
}

/// The disk coordinates `(a, b)` of unit direction `d` for a lens looking along `frame` whose
/// radius at angle θ from its axis is `rho_of_theta(θ)`, or `None` beyond `theta_max`: the
/// radius in the direction of `d`'s azimuth. [`RadialMap`] and the dual fisheye's lenses
/// share it.
#[inline]
pub(super) fn dir_to_ab_of(
    frame: &Frame,
    theta_max: f64,
    d: DVec3,
    rho_of_theta: impl Fn(f64) -> f64,
) -> Option<DVec2> {
    let l = frame.to_local(d);
    let s = (l.x * l.x + l.y * l.y).sqrt();
    let theta = s.atan2(l.z);
    if theta > theta_max * (1.0 + 1e-12) {
        return None;
    }
    let rho = rho_of_theta(theta);
    if s > 0.0 {
        Some(DVec2::new(l.x, l.y) * (rho / s))
    } else {
        Some(DVec2::new(rho, 0.0))
    }
}

/// The inverse of [`dir_to_ab_of`], with `theta_of_rho` the lens's inverse; past the unit
/// rim only with `extend` (θ clamped to π).
#[inline]
pub(super) fn ab_to_dir_of(
    frame: &Frame,
    ab: DVec2,
    extend: bool,
    theta_of_rho: impl Fn(f64) -> f64,
) -> Option<DVec3> {
    let rho = ab.length();
    if rho > 1.0 + 1e-12 && !extend {
        return None;
    }
    let theta = theta_of_rho(rho).min(PI);
    let (st, ct) = theta.sin_cos();
    let f = frame;
    if rho == 0.0 {
        return Some(f.forward);
    }
    let k = st / rho;
    Some((f.forward * ct + f.right * (ab.x * k) + f.up * (ab.y * k)).normalize())
}

/// `∫ H(ρ) dψ` along the segment `p0 → p1` of the `(a, b)` plane (the module's Green's
/// theorem), for a lens whose `H(ρ)/ρ²` is `h_over_rho2(ρ²)`, saturating at the rim.
pub(super) fn edge_integral_of(p0: DVec2, p1: DVec2, h_over_rho2: impl Fn(f64) -> f64) -> f64 {
    let e = p1 - p0;
    let c = p0.perp_dot(e);
    if c == 0.0 {
        return 0.0; // radial segment: ψ is constant
    }
    // Split at the rim: |p0 + t e|² = 1.
    let (qa, qb, qc) = (
        e.length_squared(),
        2.0 * p0.dot(e),
        p0.length_squared() - 1.0,
    );
    let mut cuts = [0.0, 1.0, 1.0, 1.0];
    let mut n = 1;
    let disc = qb * qb - 4.0 * qa * qc;
    if disc > 0.0 {
        let sq = disc.sqrt();
        for t in [(-qb - sq) / (2.0 * qa), (-qb + sq) / (2.0 * qa)] {
            if t > 0.0 && t < 1.0 {
                cuts[n] = t;
                n += 1;
            }
        }
    }
    cuts[n] = 1.0;
    let mut s = 0.0;
    for i in 0..n {
        let (t0, t1) = (cuts[i], cuts[i + 1]);
        if t1 > t0 {
            s += gauss_legendre(t0, t1, |t| {
                let p = p0 + e * t;
                h_over_rho2(p.length_squared())
            });
        }
    }
    s * c
}

macro_rules! radial_impl {
    ($t:ty) => {
        impl WorldProjection for $t {
            fn layer_count(&self) -> usize {
                1
            }
            fn layer_extent(&self, size: u32) -> (u32, u32) {
                (size, size)
            }
            #[inline]
            fn dir_to_uv(&self, d: DVec3) -> Option<(usize, DVec2)> {
                self.map.dir_to_ab(d).map(|ab| (0, RadialMap::ab_to_uv(ab)))
            }
            #[inline]
            fn uv_to_dir(&self, _layer: usize, uv: DVec2) -> Option<DVec3> {
                self.map.ab_to_dir(RadialMap::uv_to_ab(uv), false)
            }
            #[inline]
            fn density(&self, _layer: usize, uv: DVec2) -> f64 {
                4.0 * self.map.area_density_ab(RadialMap::uv_to_ab(uv).length())
            }
            fn texel_solid_angle(&self, _layer: usize, x: u32, y: u32, w: u32, h: u32) -> f64 {
                let (u0, u1) = texel_range(x, w);
                let (v0, v1) = texel_range(y, h);
                self.map.rect_solid_angle(u0, u1, v0, v1)
            }
            fn covered_solid_angle(&self) -> f64 {
                self.map.covered_solid_angle()
            }
            fn nearest_covered(&self, _layer: usize, uv: DVec2) -> DVec2 {
                clamp_to_disk(uv)
            }
        }
    };
}

/// Moves `uv` radially onto the disk if it lies outside.
#[inline]
pub(super) fn clamp_to_disk(uv: DVec2) -> DVec2 {
    let ab = RadialMap::uv_to_ab(uv);
    let r = ab.length();
    if r <= 1.0 {
        uv
    } else {
        RadialMap::ab_to_uv(ab * ((1.0 - 1e-9) / r))
    }
}

/// The OpenGL sphere map (`GL_SPHERE_MAP`, OpenGL 1.x–4.x compatibility profile §12.1.3):
/// for the eye-space reflection vector `r`, `m = 2√(r_x² + r_y² + (r_z + 1)²)`,
/// `s = r_x/m + ½`, `t = r_y/m + ½`.
///
/// As a world projection it is the picture of a mirror ball taken by a camera looking along
/// `view` (default −Z, up +Y). Its centre shows what is behind the camera (`r = +z_eye`),
/// its rim the single direction straight ahead (`r = −z_eye`). OpenGL's `t` grows upwards,
/// and pictures are stored top row first, so `(u, v) = (s, 1 − t)`.
///
/// Writing θ for the angle between `r` and `+z_eye`, `m = 4 cos(θ/2)` and the radius on the
/// `[-1, 1]` disk is `ρ = sin(θ/2)`: the sphere map is the Lambert azimuthal equal-area
/// projection (an equisolid lens with θ_max = π): `4π` is spread evenly over the disk, whose
/// area in `uv` is π/4, so every texel fully inside the disk holds exactly `16/(w·h)` sr.
///
/// ```
/// use mirrorball_core::{SphereMap, WorldProjection};
/// use glam::{DVec2, DVec3};
/// let r = DVec3::new(0.3, -0.4, 0.5).normalize();
/// let st = SphereMap::gl_st(r);
/// let (_, uv) = SphereMap::default().dir_to_uv(r).unwrap();
/// assert!((uv - DVec2::new(st.x, 1.0 - st.y)).length() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereMap {
    eye: Frame,
    map: RadialMap,
}

impl Default for SphereMap {
    fn default() -> Self {
        SphereMap::new(Frame::default())
    }
}

impl SphereMap {
    /// The sphere map seen by a camera with frame `eye` (its `forward` is the view
    /// direction).
    pub fn new(eye: Frame) -> SphereMap {
        let centre = Frame {
            right: eye.right,
            up: eye.up,
            forward: -eye.forward,
        };
        SphereMap {
            eye,
            map: RadialMap::new(centre, Lens::Equisolid, PI).expect("valid"),
        }
    }

    /// The camera frame the map was taken with.
    pub fn eye(&self) -> &Frame {
        &self.eye
    }

    /// OpenGL's `GL_SPHERE_MAP` texture coordinates for an eye-space reflection vector,
    /// verbatim from the specification (the formula, not our projection code).
    pub fn gl_st(r: DVec3) -> DVec2 {
        let m = 2.0 * (r.x * r.x + r.y * r.y + (r.z + 1.0) * (r.z + 1.0)).sqrt();
        DVec2::new(r.x / m + 0.5, r.y / m + 0.5)
    }
}
radial_impl!(SphereMap);

/// Debevec's angular map (light probe): the centre looks along `forward` (default −Z), the
/// radius is proportional to the angle from it, `ρ = θ/π`, the rim is the direction straight
/// behind. An equidistant lens with θ_max = π.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AngularMap {
    map: RadialMap,
}

impl Default for AngularMap {
    fn default() -> Self {
        AngularMap::new(Frame::default())
    }
}

impl AngularMap {
    /// An angular map looking along `frame.forward`.
    pub fn new(frame: Frame) -> AngularMap {
        AngularMap {
            map: RadialMap::new(frame, Lens::Equidistant, PI).expect("valid"),
        }
    }
    /// The underlying disk map.
    pub fn radial(&self) -> &RadialMap {
        &self.map
    }
}
radial_impl!(AngularMap);

/// A fisheye picture (Greene §10, Omnimax frames): any [`Lens`], any field of view up to the
/// lens's limit, looking along a frame. Default: equidistant, 180° (a hemisphere), looking
/// along −Z. For an Omnimax dome looking up, use `Frame::looking_along(+Y)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fisheye {
    map: RadialMap,
}

impl Default for Fisheye {
    fn default() -> Self {
        Fisheye::new(Frame::default(), Lens::Equidistant, 180.0).expect("valid")
    }
}

impl Fisheye {
    /// A fisheye with total field of view `fov_deg` (the rim is `fov/2` from the axis), or
    /// `None` outside the lens's [`Lens::fov_range`].
    pub fn new(frame: Frame, lens: Lens, fov_deg: f64) -> Option<Fisheye> {
        if !lens.fov_range().contains(fov_deg) {
            return None;
        }
        RadialMap::new(frame, lens, 0.5 * fov_deg.to_radians()).map(|map| Fisheye { map })
    }
    /// The underlying disk map.
    pub fn radial(&self) -> &RadialMap {
        &self.map
    }
}
radial_impl!(Fisheye);

/// Heidrich & Seidel's dual paraboloid map (1998): two disks, layer 0 the front hemisphere
/// around `forward` (default −Z), layer 1 the back hemisphere around `−forward`.
///
/// In each half's own frame `(x, y, z)` with `z` along its axis, the paraboloid
/// `f(x, y) = ½ − ½(x² + y²)` reflects direction `d` from the point
/// `(a, b) = (d_x, d_y)/(1 + d_z)`: a stereographic lens with θ_max = 90°.
///
/// **The back half's mirroring.** Heidrich & Seidel write the back map as
/// `(d_x, d_y)/(1 − d_z)` in the *front* frame, which shows the back hemisphere mirrored left
/// to right. mirrorball stores the back half as a camera turned half a turn about up sees it
/// (right = −forward × … = the front's −X), i.e. `a_back = −d_x/(1 − d_z)`. Both halves then
/// look like ordinary fisheye photographs, and side by side (front | back) they touch at the
/// +right equator point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DualParaboloid {
    front: RadialMap,
    back: RadialMap,
}

impl Default for DualParaboloid {
    fn default() -> Self {
        DualParaboloid::new(Frame::default())
    }
}

impl DualParaboloid {
    /// A dual paraboloid whose front half looks along `frame.forward`.
    pub fn new(frame: Frame) -> DualParaboloid {
        let front = RadialMap::new(frame, Lens::Stereographic, FRAC_PI_2).expect("valid");
        let back =
            RadialMap::new(frame.turned_around(), Lens::Stereographic, FRAC_PI_2).expect("valid");
        DualParaboloid { front, back }
    }

    /// The frame of the front half (layer 0); the back half looks the other way.
    pub fn frame(&self) -> &Frame {
        self.front.frame()
    }

    #[inline]
    fn half(&self, layer: usize) -> &RadialMap {
        if layer == 0 {
            &self.front
        } else {
            &self.back
        }
    }
}

impl WorldProjection for DualParaboloid {
    fn layer_count(&self) -> usize {
        2
    }
    fn layer_extent(&self, size: u32) -> (u32, u32) {
        (size, size)
    }
    #[inline]
    fn dir_to_uv(&self, d: DVec3) -> Option<(usize, DVec2)> {
        let layer = if self.front.frame.forward.dot(d) >= 0.0 {
            0
        } else {
            1
        };
        self.half(layer)
            .dir_to_ab(d)
            .map(|ab| (layer, RadialMap::ab_to_uv(ab)))
    }
    #[inline]
    fn uv_to_dir(&self, layer: usize, uv: DVec2) -> Option<DVec3> {
        if layer > 1 {
            return None;
        }
        self.half(layer).ab_to_dir(RadialMap::uv_to_ab(uv), false)
    }
    #[inline]
    fn density(&self, layer: usize, uv: DVec2) -> f64 {
        4.0 * self
            .half(layer)
            .area_density_ab(RadialMap::uv_to_ab(uv).length())
    }
    fn texel_solid_angle(&self, layer: usize, x: u32, y: u32, w: u32, h: u32) -> f64 {
        let (u0, u1) = texel_range(x, w);
        let (v0, v1) = texel_range(y, h);
        self.half(layer).rect_solid_angle(u0, u1, v0, v1)
    }
    fn nearest_covered(&self, _layer: usize, uv: DVec2) -> DVec2 {
        clamp_to_disk(uv)
    }
    fn wrap_texel(&self, layer: usize, x: i64, y: i64, w: u32, h: u32) -> (usize, u32, u32) {
        // Past the rim the paraboloid formula continues into the other hemisphere.
        let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
        let d = self
            .half(layer.min(1))
            .ab_to_dir(RadialMap::uv_to_ab(uv), true);
        if let Some((l, t)) = d.and_then(|d| self.dir_to_uv(d)) {
            let tx = ((t.x * w as f64) as i64).clamp(0, w as i64 - 1);
            let ty = ((t.y * h as f64) as i64).clamp(0, h as i64 - 1);
            return (l, tx as u32, ty as u32);
        }
        (
            layer,
            x.clamp(0, w as i64 - 1) as u32,
            y.clamp(0, h as i64 - 1) as u32,
        )
    }
}
