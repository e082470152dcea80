//! Filtered lookups over any projection, given a direction and its footprint on the sphere.
//!
//! # Footprints
//!
//! A [`Footprint`] is an ellipse on the sphere about the lookup direction `d`, described by
//! two conjugate semi-diameters `p`, `q` in the tangent plane at `d` (radians):
//!
//! * [`Footprint::Cone`]: a reflection cone of half-angle β (Greene 1986, fig. 1): `p`, `q`
//!   two perpendicular tangent vectors of length β;
//! * [`Footprint::Differentials`]: ray differentials `∂d/∂x`, `∂d/∂y` (Igehy 1999), taken
//!   as the conjugate radii of the pixel's filter ellipse as in Heckbert's EWA (their
//!   components along `d` are dropped).
//!
//! The ellipse is carried to texture space through the projection's Jacobian at `d`:
//! with `∂d/∂u`, `∂d/∂v` from [`mirrorball_core::derivative`] (differences of [`WorldProjection::uv_to_dir`]) and an
//! orthonormal tangent frame `(t₁, t₂)`, `M = [tᵢ·∂d/∂u, tᵢ·∂d/∂v]` maps `uv` steps to
//! tangent steps, and `J = M⁻¹` maps the footprint's semi-diameters to `uv` (then to texels
//! of the level used). `|det M|` is the projection's area element, which the tests check.
//! So one cone covers the same piece of sphere whatever the projection: a few texels of a
//! lat-long map at the equator, a long ellipse near its poles, a small ellipse in the middle
//! of a sphere map and a long thin one near its rim.
//!
//! # Filters
//!
//! * [`Filter::Nearest`], [`Filter::Bilinear`]: the footprint is ignored (bilinear is
//!   seamless across every seam, as [`EnvMap::bilinear_at`]).
//! * [`Filter::Trilinear`]: two bilinear lookups in the solid-angle-weighted pyramid, at
//!   `lod = log₂ λ_max` (the ellipse's major semi-axis in level-0 texels, as OpenGL takes
//!   the longer derivative), blended.
//! * [`Filter::Ewa`]: Heckbert's elliptical weighted average (Greene & Heckbert 1986;
//!   Heckbert 1989 §3.5.8): with the ellipse's conjugate radii `(u_x, v_x)`, `(u_y, v_y)`
//!   in texels, `A = v_x² + v_y² + δ`, `B = −2(u_x v_x + u_y v_y)`, `C = u_x² + u_y² + δ`,
//!   `F = AC − B²/4`; each texel within `Q = A Δu² + B Δu Δv + C Δv² < F` gets weight
//!   `exp(−2Q/F) − exp(−2)` (pbrt's: zero on the ellipse, so no jump as texels enter it)
//!   times its exact solid angle, so the average is over the sphere, not over texels.
//!   Heckbert's `δ = 1` adds a reconstruction filter; here `δ` (along the level's texel
//!   axes) adds up to one texel only when the minor semi-axis is under a texel, so a
//!   magnified map is a smooth interpolation of its texel centres, as bilinear's, and
//!   otherwise takes off the `1/12` texel² variance per axis that the box-averaged texels
//!   add (`δ = −1/3`, as the Gaussian's covariance is `S/4`), so the filter on the sphere
//!   does not depend on the texel size. The ellipse's eccentricity is limited to [`Sampler::max_anisotropy`], and
//!   the level is chosen so that its minor semi-axis spans about four texels (the two
//!   nearest levels are blended), bounding the cost at about `π·8·8·max_anisotropy`
//!   texels. Texels beyond a layer's edge come from
//!   [`WorldProjection::wrap_texel`] (seamless across cube edges and corners, the
//!   longitude wrap and the poles).
//! * [`Filter::SummedArea`]: Crow's box filter through a [`SummedAreaTable`] over the
//!   ellipse's bounding box at level 0, solid-angle weighted.

use crate::mip::{texel_solid_angles, MipChain, MipFilter};
use crate::sat::SummedAreaTable;
use glam::{DVec2, DVec3};
use mirrorball_core::{EnvMap, Projection, WorldProjection};

/// Where and how wide to look.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Footprint {
    /// A single direction.
    Point,
    /// A cone of this half-angle (radians) about the direction.
    Cone(f64),
    /// Ray differentials: the change of the (unit) direction per pixel in x and in y.
    Differentials {
        /// `∂d/∂x`.
        dx: DVec3,
        /// `∂d/∂y`.
        dy: DVec3,
    },
}

/// The filter of a [`Sampler`] (and of the renderer's environment lookups).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Filter {
    /// The texel the direction falls in.
    Nearest,
    /// Bilinear interpolation, seamless.
    #[default]
    Bilinear,
    /// Two bilinear lookups in the mip pyramid, blended.
    Trilinear,
    /// Elliptical weighted average over the footprint.
    Ewa,
    /// Box over the footprint's bounding box, by summed-area table.
    SummedArea,
}

impl mirrorball_core::Choice for Filter {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (Filter::Nearest, &["nearest", "point"]),
        (Filter::Bilinear, &["bilinear", "linear"]),
        (Filter::Trilinear, &["trilinear", "mip", "mipmap"]),
        (Filter::Ewa, &["ewa", "anisotropic"]),
        (Filter::SummedArea, &["sat", "summed-area", "box"]),
    ];
}
mirrorball_core::choice_traits!(Filter);

impl Filter {
    /// Whether the filter reads the footprint (and so needs a mip pyramid or a table).
    pub fn uses_footprint(self) -> bool {
        matches!(self, Filter::Trilinear | Filter::Ewa | Filter::SummedArea)
    }
}

/// A footprint carried into a layer's texture coordinates: the centre and two conjugate
/// semi-diameters, in `uv` units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvEllipse {
    /// The layer.
    pub layer: usize,
    /// The centre.
    pub uv: DVec2,
    /// First conjugate semi-diameter (`uv` units).
    pub a: DVec2,
    /// Second conjugate semi-diameter.
    pub b: DVec2,
}

/// An orthonormal tangent frame at unit `d` (`t₁ = normalize(ŷ × d)`, `t₂ = d × t₁`).
fn tangent_frame(d: DVec3) -> (DVec3, DVec3) {
    let t = DVec3::new(d.z, 0.0, -d.x);
    let t = if t.length_squared() > 1e-20 {
        t.normalize()
    } else {
        DVec3::X
    };
    (t, d.cross(t))
}

pub use mirrorball_core::derivative::uv_derivatives;

/// The footprint of `dir` carried into texture coordinates through the projection's
/// Jacobian (`None` where the projection does not cover `dir` or is singular there).
pub fn footprint_ellipse(proj: &Projection, dir: DVec3, fp: &Footprint) -> Option<UvEllipse> {
    let d = dir.try_normalize()?;
    let (layer, uv) = proj.dir_to_uv(d)?;
    let (t1, t2) = tangent_frame(d);
    let (p, q) = match *fp {
        Footprint::Point => (DVec2::ZERO, DVec2::ZERO),
        Footprint::Cone(beta) => (DVec2::new(beta, 0.0), DVec2::new(0.0, beta)),
        Footprint::Differentials { dx, dy } => (
            DVec2::new(t1.dot(dx), t2.dot(dx)),
            DVec2::new(t1.dot(dy), t2.dot(dy)),
        ),
    };
    if p == DVec2::ZERO && q == DVec2::ZERO {
        return Some(UvEllipse {
            layer,
            uv,
            a: DVec2::ZERO,
            b: DVec2::ZERO,
        });
    }
    let (du, dv) = uv_derivatives(proj, layer, uv)?;
    // M: uv step → tangent step.
    let (m00, m01, m10, m11) = (t1.dot(du), t1.dot(dv), t2.dot(du), t2.dot(dv));
    let det = m00 * m11 - m01 * m10;
    if !det.is_finite() || det.abs() < 1e-300 {
        return None;
    }
    // J = M⁻¹: tangent step → uv step.
    let j = |t: DVec2| DVec2::new(m11 * t.x - m01 * t.y, -m10 * t.x + m00 * t.y) / det;
    Some(UvEllipse {
        layer,
        uv,
        a: j(p),
        b: j(q),
    })
}

/// Singular values `(λ_max, λ_min)` of the 2×2 matrix with columns `a`, `b`: the semi-axes
/// of the ellipse with conjugate semi-diameters `a`, `b`.
pub fn semi_axes(a: DVec2, b: DVec2) -> (f64, f64) {
    // Eigenvalues of M Mᵀ, M = [a b].
    let (s00, s01, s11) = (
        a.x * a.x + b.x * b.x,
        a.x * a.y + b.x * b.y,
        a.y * a.y + b.y * b.y,
    );
    let tr = s00 + s11;
    let disc = ((s00 - s11) * (s00 - s11) + 4.0 * s01 * s01).sqrt();
    (
        (0.5 * (tr + disc)).max(0.0).sqrt(),
        (0.5 * (tr - disc)).max(0.0).sqrt(),
    )
}

/// A filtered sampler over one environment map (any projection).
pub struct Sampler {
    chain: MipChain,
    /// Per level, per layer (one shared table for cube faces), texel solid angles.
    omega: Vec<Vec<Vec<f64>>>,
    sat: Option<SummedAreaTable>,
    filter: Filter,
    /// EWA: the largest ratio of the footprint's axes before the minor one is widened
    /// (default 16).
    pub max_anisotropy: f64,
}

impl Sampler {
    /// Prepares `env` for `filter` (the pyramid for trilinear and EWA, summed-area tables
    /// for box filtering).
    pub fn new(env: &EnvMap, filter: Filter) -> Sampler {
        let chain = match filter {
            Filter::Trilinear | Filter::Ewa => MipChain::build(env, MipFilter::Box),
            _ => MipChain::build_levels(env, MipFilter::Box, 1),
        };
        Sampler::from_chain(chain, filter)
    }

    /// Uses an existing pyramid.
    pub fn from_chain(chain: MipChain, filter: Filter) -> Sampler {
        let omega = if filter == Filter::Ewa {
            chain
                .levels()
                .iter()
                .map(|l| texel_solid_angles(l.projection(), l.width(), l.height()))
                .collect()
        } else {
            Vec::new()
        };
        let sat = (filter == Filter::SummedArea).then(|| SummedAreaTable::new(chain.level(0)));
        Sampler {
            chain,
            omega,
            sat,
            filter,
            max_anisotropy: 16.0,
        }
    }

    /// The pyramid.
    pub fn chain(&self) -> &MipChain {
        &self.chain
    }

    /// The filtered radiance (RGB and alpha, or 1) in direction `dir` over `footprint`.
    /// Directions the projection does not cover read as zero.
    pub fn sample(&self, dir: DVec3, footprint: &Footprint) -> [f32; 4] {
        let base = self.chain.level(0);
        let proj = base.projection();
        let c = base.channels();
        let Some(d) = dir.try_normalize() else {
            return [0.0; 4];
        };
        let mut out = [0.0, 0.0, 0.0, 1.0];
        match self.filter {
            Filter::Nearest => {
                if let Some((layer, uv)) = proj.dir_to_uv(d) {
                    let (w, h) = (base.width(), base.height());
                    let x = ((uv.x * w as f64) as i64).clamp(0, w as i64 - 1) as u32;
                    let y = ((uv.y * h as f64) as i64).clamp(0, h as i64 - 1) as u32;
                    out[..c].copy_from_slice(base.layers()[layer].get(x, y));
                }
                out
            }
            Filter::Bilinear => base.sample(d),
            Filter::Trilinear => {
                let Some(e) = footprint_ellipse(proj, d, footprint) else {
                    return base.sample(d);
                };
                let (w, h) = (base.width() as f64, base.height() as f64);
                let (major, _) = semi_axes(e.a * DVec2::new(w, h), e.b * DVec2::new(w, h));
                let lod = if major > 1.0 { major.log2() } else { 0.0 };
                self.trilinear(e.layer, e.uv, lod, c)
            }
            Filter::Ewa => match footprint_ellipse(proj, d, footprint) {
                Some(e) => {
                    let mut t = Tangent::new(d, footprint);
                    let (major, minor) = semi_axes(t.p, t.q);
                    let max_aniso = self.max_anisotropy.max(1.0);
                    if minor * max_aniso < major {
                        // Widen the minor axis, as in texel space.
                        let (v, _) = principal_directions(t.p, t.q);
                        let v2 = DVec2::new(-v.y, v.x);
                        t.p = v * major;
                        t.q = v2 * (major / max_aniso);
                    }
                    self.ewa(&e, &t, c)
                }
                None => base.sample(d),
            },
            Filter::SummedArea => {
                let Some(e) = footprint_ellipse(proj, d, footprint) else {
                    return base.sample(d);
                };
                let sat = self.sat.as_ref().expect("built for SummedArea");
                let (w, h) = (base.width() as f64, base.height() as f64);
                // Bounding box of the ellipse: half-extents √(a_x² + b_x²), √(a_y² + b_y²).
                let ex = (e.a.x * e.a.x + e.b.x * e.b.x).sqrt() * w;
                let ey = (e.a.y * e.a.y + e.b.y * e.b.y).sqrt() * h;
                let (cx, cy) = (e.uv.x * w, e.uv.y * h);
                // At least the texel the centre is in.
                let (fx, fy) = (cx.floor() as i64, cy.floor() as i64);
                let x0 = ((cx - ex).round() as i64).min(fx);
                let x1 = ((cx + ex).round() as i64).max(fx + 1);
                let y0 = ((cy - ey).round() as i64).min(fy);
                let y1 = ((cy + ey).round() as i64).max(fy + 1);
                // A box wider than a whole layer row (near a lat-long pole) is the row.
                let (x0, x1) = if x1 - x0 >= base.width() as i64 {
                    (0, base.width() as i64)
                } else {
                    (x0, x1)
                };
                match sat.box_mean(e.layer, x0, y0, x1, y1) {
                    Some(v) => [v[0] as f32, v[1] as f32, v[2] as f32, 1.0],
                    None => base.sample(d),
                }
            }
        }
    }

    fn trilinear(&self, layer: usize, uv: DVec2, lod: f64, c: usize) -> [f32; 4] {
        let last = (self.chain.len() - 1) as f64;
        let lod = lod.clamp(0.0, last);
        let l0 = lod.floor() as usize;
        let f = (lod - l0 as f64) as f32;
        let mut a = [0.0, 0.0, 0.0, 1.0];
        self.chain.level(l0).bilinear_at(layer, uv, &mut a[..c]);
        if f > 0.0 {
            let mut b = [0.0, 0.0, 0.0, 1.0];
            self.chain.level(l0 + 1).bilinear_at(layer, uv, &mut b[..c]);
            for k in 0..4 {
                a[k] += f * (b[k] - a[k]);
            }
        }
        a
    }

    fn ewa(&self, e: &UvEllipse, fp: &Tangent, c: usize) -> [f32; 4] {
        let base = self.chain.level(0);
        let (w, h) = (base.width() as f64, base.height() as f64);
        let (a, b) = (e.a * DVec2::new(w, h), e.b * DVec2::new(w, h));
        let (major, minor) = semi_axes(a, b);
        if major <= 0.0 {
            let mut out = [0.0, 0.0, 0.0, 1.0];
            base.bilinear_at(e.layer, e.uv, &mut out[..c]);
            return out;
        }
        // Limit the eccentricity: widen the minor axis.
        let aniso = (major / minor.max(1e-300)).min(self.max_anisotropy.max(1.0));
        let minor = major / aniso;
        // The level where the minor semi-axis spans about four texels; blend two levels.
        let lod = (minor / 4.0)
            .max(1.0)
            .log2()
            .min((self.chain.len() - 1) as f64);
        let l0 = lod.floor() as usize;
        let f = lod - l0 as f64;
        let mut acc = self.ewa_level(e, fp, minor, l0, c);
        if f > 1e-6 && l0 + 1 < self.chain.len() {
            let hi = self.ewa_level(e, fp, minor, l0 + 1, c);
            for k in 0..4 {
                acc[k] = acc[k] * (1.0 - f) + hi[k] * f;
            }
        }
        let mut out = [0.0, 0.0, 0.0, 1.0];
        for k in 0..c.min(4) {
            out[k] = acc[k] as f32;
        }
        out
    }

    /// EWA on level `l`: every texel within the footprint's reach in this level (`minor`,
    /// the minor semi-axis, in level-0 texels) is weighted by `(exp(−2r²) − exp(−2))·Ω` (zero at the
    /// ellipse, so the result is continuous as texels enter and leave it), with `r` its
    /// elliptical radius measured on the sphere about the texel's centre direction.
    fn ewa_level(&self, e: &UvEllipse, fp: &Tangent, minor: f64, l: usize, c: usize) -> [f64; 4] {
        let lv = self.chain.level(l);
        let proj = lv.projection();
        let (w, h) = (lv.width(), lv.height());
        let base = self.chain.level(0);
        let scale = w as f64 / base.width() as f64;
        let minor_t = minor * scale;
        let delta = reconstruction_delta(minor_t);
        let (cu, cv, a, b) = level_footprint(proj, e, fp, w, h);
        let q = fp.quadratic_form([
            delta * (cu.x * cu.x + cv.x * cv.x),
            delta * (cu.x * cu.y + cv.x * cv.y),
            delta * (cu.y * cu.y + cv.y * cv.y),
        ]);
        let rows = EllipseRows::new(proj, e.uv, a, b, delta, w, h);
        let omega = &self.omega[l];
        let mut acc = [0.0f64; 4];
        let mut wsum = 0.0;
        let add = |layer: usize, px: u32, py: u32| {
            let om = omega[layer.min(omega.len() - 1)][(py * w + px) as usize];
            if om <= 0.0 {
                return;
            }
            let uv = DVec2::new((px as f64 + 0.5) / w as f64, (py as f64 + 0.5) / h as f64);
            let Some(dir) = proj.uv_to_dir(layer, uv) else {
                return;
            };
            let r2 = q.r2(fp.log(dir));
            if r2 >= 1.0 {
                return;
            }
            let wt = ((-2.0 * r2).exp() - EXP_M2) * om;
            let t = lv.layers()[layer].get(px, py);
            for k in 0..c.min(4) {
                acc[k] += wt * t[k] as f64;
            }
            wsum += wt;
        };
        visit_texels(&rows, proj, e.layer, w, h, add);
        if wsum > 0.0 {
            for v in &mut acc {
                *v /= wsum;
            }
            if c == 3 {
                acc[3] = 1.0;
            }
            acc
        } else {
            let mut out = [0.0f32, 0.0, 0.0, 1.0];
            lv.bilinear_at(e.layer, e.uv, &mut out[..c]);
            out.map(|v| v as f64)
        }
    }
}

/// The reconstruction filter of [`Sampler::ewa_level`], `δ` texel² added to the
/// footprint's covariance along both texel axes of the level, for a minor semi-axis of
/// `minor_t` of the level's texels: up to one texel when the minor semi-axis is under a
/// texel (magnification: the filter is then at least one texel in radius, a smooth
/// interpolation of the texel centres as in Heckbert's and pbrt's EWA), and once the
/// footprint spans a few texels, minus the `texel²/12` of variance per axis that the
/// box-averaged texels add (the footprint's covariance is `S/4` for `exp(−2r²)`).
#[inline]
fn reconstruction_delta(minor_t: f64) -> f64 {
    if minor_t < 1.0 {
        1.0 - minor_t * minor_t
    } else {
        -(minor_t * minor_t - 1.0).min(1.0) / 3.0
    }
}

/// A level's texel steps in the tangent plane and the footprint in its texels, for a
/// `w`×`h` level of `proj`: `(cu, cv)` are `M`'s columns over `w`, `h`, and `(a, b)` the
/// footprint `M⁻¹` of the tangent semi-diameters (so widened as `fp` was), or `e`'s `uv`
/// semi-diameters scaled to texels where `M` is singular.
#[inline]
fn level_footprint(
    proj: &Projection,
    e: &UvEllipse,
    fp: &Tangent,
    w: u32,
    h: u32,
) -> (DVec2, DVec2, DVec2, DVec2) {
    let (cu, cv) = match uv_derivatives(proj, e.layer, e.uv) {
        Some((du, dv)) => (
            DVec2::new(fp.t1.dot(du), fp.t2.dot(du)) / w as f64,
            DVec2::new(fp.t1.dot(dv), fp.t2.dot(dv)) / h as f64,
        ),
        None => (DVec2::ZERO, DVec2::ZERO),
    };
    let det_c = cu.x * cv.y - cv.x * cu.y;
    let (a, b) = if det_c.abs() > 1e-300 {
        let to_texels =
            |t: DVec2| DVec2::new(cv.y * t.x - cv.x * t.y, -cu.y * t.x + cu.x * t.y) / det_c;
        (to_texels(fp.p), to_texels(fp.q))
    } else {
        (
            e.a * DVec2::new(w as f64, h as f64),
            e.b * DVec2::new(w as f64, h as f64),
        )
    };
    (cu, cv, a, b)
}

/// The texels [`Sampler::ewa_level`] visits: the footprint ellipse in the level's texels,
/// `S = a aᵀ + b bᵀ + δ I`, grown a little (the map is not linear across the footprint),
/// its bounding box `x0..=x1` × `y0..=y1` about the centre `(cx, cy)`, and per row the span
/// inside it ([`EllipseRows::span`]).
struct EllipseRows {
    s00: f64,
    s01: f64,
    s11: f64,
    /// `det S`.
    det_s: f64,
    cx: f64,
    cy: f64,
    x0: i64,
    x1: i64,
    y0: i64,
    y1: i64,
    /// The box is wider than a whole row (near a pole) and was cut to each column once.
    whole_rows: bool,
    /// The map is smooth inside a layer (cube faces, lat-long), so rows may be cut to the
    /// ellipse's span.
    smooth: bool,
}

impl EllipseRows {
    /// The rows of the ellipse with conjugate radii `a`, `b` (texels) plus `delta` texel²,
    /// centred at `uv` of a `w`×`h` level of `proj`.
    #[inline]
    fn new(
        proj: &Projection,
        uv: DVec2,
        a: DVec2,
        b: DVec2,
        delta: f64,
        w: u32,
        h: u32,
    ) -> EllipseRows {
        let grow2 = 1.25f64 * 1.25;
        let s00 = (a.x * a.x + b.x * b.x + delta) * grow2;
        let s01 = (a.x * a.y + b.x * b.y) * grow2;
        let s11 = (a.y * a.y + b.y * b.y + delta) * grow2;
        let ru = s00.max(0.0).sqrt() + 1.0;
        let rv = s11.max(0.0).sqrt() + 1.0;
        let (cx, cy) = (uv.x * w as f64 - 0.5, uv.y * h as f64 - 0.5);
        let (mut x0, mut x1) = ((cx - ru).ceil() as i64, (cx + ru).floor() as i64);
        let (y0, y1) = ((cy - rv).ceil() as i64, (cy + rv).floor() as i64);
        let mut whole_rows = false;
        if x1 - x0 + 1 > w as i64 && proj.layer_count() == 1 {
            // Wider than a whole row (near a pole): each column once.
            x0 = 0;
            x1 = w as i64 - 1;
            whole_rows = true;
        }
        // The disk and octahedral maps fold their parametrisation, and a footprint across a
        // fold reaches texels far from its linearised ellipse, which the whole box keeps.
        let smooth = matches!(proj, Projection::Cube(_) | Projection::LatLong(_));
        let det_s = s00 * s11 - s01 * s01;
        EllipseRows {
            s00,
            s01,
            s11,
            det_s,
            cx,
            cy,
            x0,
            x1,
            y0,
            y1,
            whole_rows,
            smooth,
        }
    }

    /// The columns row `ty` visits. Each row visits only the span of the ellipse, not its
    /// whole bounding box: a point `p` from the centre is inside when `pᵀ S⁻¹ p ≤ 1`, i.e.
    /// for the row's `py`, `s11·px² − 2 s01 py·px + s00 py² − det S ≤ 0`, plus a texel of
    /// margin each side (a thin diagonal ellipse covers a small part of its box). Only
    /// where the map is smooth inside a layer; otherwise, and for whole rows or a
    /// degenerate ellipse, the whole box's columns.
    #[inline]
    fn span(&self, ty: i64) -> (i64, i64) {
        let (s00, s01, s11, det_s) = (self.s00, self.s01, self.s11, self.det_s);
        let (x0, x1, cx) = (self.x0, self.x1, self.cx);
        if !self.smooth || self.whole_rows || det_s < 1e-18 || s11 < 1e-18 {
            return (x0, x1);
        }
        let py = ty as f64 - self.cy;
        let qb = -2.0 * py * s01;
        let qc = py * py * s00 - det_s;
        let disc = qb * qb - 4.0 * s11 * qc;
        if disc < 0.0 {
            // The row passes beyond the ellipse: only the margin's texel.
            let m = (-qb / (2.0 * s11) + cx).round() as i64;
            return (m.max(x0), m.min(x1));
        }
        let r = disc.sqrt();
        let (lo, hi) = ((-qb - r) / (2.0 * s11) + cx, (-qb + r) / (2.0 * s11) + cx);
        (
            ((lo - 1.0).ceil() as i64).max(x0),
            ((hi + 1.0).floor() as i64).min(x1),
        )
    }
}

/// Calls `add(layer, x, y)` for each texel of `rows` once, for a `w`×`h` level of `proj`
/// whose footprint is centred in `layer`. Texels beyond the layer's edge are gathered first
/// and summed once each afterwards: a large footprint reaches some of them twice through a
/// seam. (A per-thread buffer, sorted and deduplicated: no allocation per lookup, no
/// quadratic search.)
#[inline]
fn visit_texels(
    rows: &EllipseRows,
    proj: &Projection,
    layer: usize,
    w: u32,
    h: u32,
    mut add: impl FnMut(usize, u32, u32),
) {
    OUTSIDE.with(|cell| {
        let mut outside = cell.borrow_mut();
        outside.clear();
        for ty in rows.y0..=rows.y1 {
            let (sx0, sx1) = rows.span(ty);
            for tx in sx0..=sx1 {
                if tx >= 0 && ty >= 0 && tx < w as i64 && ty < h as i64 {
                    add(layer, tx as u32, ty as u32);
                } else {
                    let t = proj.wrap_texel(layer, tx, ty, w, h);
                    outside.push(((t.0 as u64) << 48) | ((t.1 as u64) << 24) | t.2 as u64);
                }
            }
        }
        outside.sort_unstable();
        outside.dedup();
        for &key in outside.iter() {
            let (layer, px, py) = (
                (key >> 48) as usize,
                ((key >> 24) & 0xFF_FFFF) as u32,
                (key & 0xFF_FFFF) as u32,
            );
            add(layer, px, py);
        }
    });
}

/// `exp(−2)`: the EWA weight at the ellipse, subtracted so that weights fall to zero there.
const EXP_M2: f64 = 0.135_335_283_236_612_7;

thread_local! {
    /// Per-thread scratch of [`Sampler::ewa_level`]: the texels a footprint reaches beyond
    /// its layer's edge, as `layer << 48 | x << 24 | y`.
    static OUTSIDE: std::cell::RefCell<Vec<u64>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// A footprint in the tangent plane at its centre direction `d`: the conjugate
/// semi-diameters `p`, `q` (radians) in the frame `(t₁, t₂)`.
struct Tangent {
    d: DVec3,
    t1: DVec3,
    t2: DVec3,
    p: DVec2,
    q: DVec2,
    /// The major semi-axis, radians.
    radius: f64,
}

/// `r² = xᵀ S⁻¹ x` for a tangent-plane covariance-like matrix `S`.
struct Quadratic {
    inv: [f64; 3],
}

impl Quadratic {
    #[inline]
    fn r2(&self, x: DVec2) -> f64 {
        self.inv[0] * x.x * x.x + 2.0 * self.inv[1] * x.x * x.y + self.inv[2] * x.y * x.y
    }
}

impl Tangent {
    fn new(d: DVec3, fp: &Footprint) -> Tangent {
        let (t1, t2) = tangent_frame(d);
        let (p, q) = match *fp {
            Footprint::Point => (DVec2::ZERO, DVec2::ZERO),
            Footprint::Cone(beta) => (DVec2::new(beta, 0.0), DVec2::new(0.0, beta)),
            Footprint::Differentials { dx, dy } => (
                DVec2::new(t1.dot(dx), t2.dot(dx)),
                DVec2::new(t1.dot(dy), t2.dot(dy)),
            ),
        };
        let radius = semi_axes(p, q).0;
        Tangent {
            d,
            t1,
            t2,
            p,
            q,
            radius,
        }
    }

    /// Geodesic polar coordinates of unit `l` about `d` (the logarithmic map): the angle
    /// from `d`, in the direction `l` leaves `d`.
    #[inline]
    fn log(&self, l: DVec3) -> DVec2 {
        let (x, y, z) = (self.t1.dot(l), self.t2.dot(l), self.d.dot(l));
        let s = (x * x + y * y).sqrt();
        if s < 1e-300 {
            return DVec2::ZERO;
        }
        let theta = s.atan2(z);
        DVec2::new(x, y) * (theta / s)
    }

    /// The quadratic form of the footprint ellipse (`r = 1` on it), `S = P Pᵀ + extra`
    /// (`extra = [e₀₀, e₀₁, e₁₁]`, radians², symmetric).
    fn quadratic_form(&self, extra: [f64; 3]) -> Quadratic {
        let (p, q) = (self.p, self.q);
        let s00 = p.x * p.x + q.x * q.x + extra[0];
        let s01 = p.x * p.y + q.x * q.y + extra[1];
        let s11 = p.y * p.y + q.y * q.y + extra[2];
        // Keep S positive definite: at least a thousandth of the major axis.
        let floor = (1e-3 * self.radius).powi(2) + 1e-300;
        let det = (s00 * s11 - s01 * s01).max(floor * (s00 + s11));
        Quadratic {
            inv: [s11 / det, -s01 / det, s00 / det],
        }
    }
}

/// The unit direction of the major axis of the ellipse with conjugate radii `a`, `b`, and
/// the major semi-axis.
fn principal_directions(a: DVec2, b: DVec2) -> (DVec2, f64) {
    let (s00, s01, s11) = (
        a.x * a.x + b.x * b.x,
        a.x * a.y + b.x * b.y,
        a.y * a.y + b.y * b.y,
    );
    let theta = 0.5 * (2.0 * s01).atan2(s00 - s11);
    let v = DVec2::new(theta.cos(), theta.sin());
    (v, semi_axes(a, b).0)
}
