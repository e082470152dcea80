//! Grimm & Niebruegge's continuous cube map: the cube folded onto the sphere.

use super::cube::CubeFace;
use super::quadrature::gauss_legendre;
use super::{texel_range, WorldProjection};
use glam::{DVec2, DVec3};
use std::f64::consts::SQRT_2;

/// `c = asin(1/√3) = atan(1/√2)`: the latitude of a cube corner above the face's mid-line.
const C: f64 = 0.615_479_708_670_387_3;

/// The continuous cube map (Grimm & Niebruegge, *Continuous Cube Mapping*).
///
/// The sphere is cut into the six cube-face regions (the great circles `x = ±y`, `y = ±z`,
/// `x = ±z`: the paper's figure 9 selects exactly the faces OpenGL's major axis does), and
/// each region is parameterised by *angles* instead of by the tangent-plane intersection.
///
/// **Formulas used.** In a face with OpenGL face coordinates `A = s_c/|m_a|`,
/// `B = t_c/|m_a|` (the gnomonic ones, in `[-1, 1]`), write `λ = atan A` for the longitude
/// around the face's `t` axis and `ψ = atan(B/√(1 + A²))` for the latitude. Then
///
/// * `p = atan(A/√2) / c` — the paper's eq. (5) (`u = ½ − atan(R_x/(R_y√2)) / (2 asin(1/√3))`),
///   rescaled to `[-1, 1]`; lines of constant `p` are great circles (meridians);
/// * `q = ψ / E(λ)`, `E(λ) = atan(cos λ)` — the latitude as a fraction of the face edge's
///   latitude on that meridian. This is what the paper's Appendix A shader computes,
///   `T = (1 + asin(z)/asin(1/√(2 + (x/y)²)))/2` (`asin(1/√(2+A²)) = atan(cos λ)`).
///
/// and `(u, v) = ((p + 1)/2, (q + 1)/2)`.
///
/// **Where we differ from the paper.** Its eq. (6) divides by the constant `asin(1/√3)` and
/// puts `√(2 + R_x²/R_y²)` inside the arcsine: that does not map the face edges to `v = 0, 1`
/// (at `R_x = 0` the edge lands at `v ≈ 0.93`), so it is a misprint; the shader is the
/// consistent version. The shader itself does not compile as printed (stray braces, samplers
/// named `decalsY` but declared `decalY`, `bool` from `ceil`). Its Appendix C inverse uses
/// `dU`, `dV`, `dCT` without defining them; we derive the inverse instead:
/// `A = √2 tan(c p)`, `ψ = q·atan(1/√(1 + A²))`, `B = tan ψ · √(1 + A²)`, then OpenGL's face
/// table. We keep OpenGL's face order and per-face `(s, t)` axes (the paper rotates each face
/// to its +Y face with its own texture index order), so every cube layout applies unchanged.
///
/// **Continuity.** On an edge the parameter along it is `atan(t/√2)/c` from both sides: on
/// an `|A| = 1` edge, `q = atan(B/√2)/c`; on a `|B| = 1` edge, `p = atan(A/√2)/c`; and since
/// `asin(t/√(2 + t²)) = atan(t/√2)`, the two faces agree point for point at all 12 edges
/// (tested).
///
/// **Solid angle.** `dω = cos ψ dψ dλ`, so a texel between meridians `λ₀, λ₁` and fractions
/// `q₀, q₁` holds `∫ [sin(q₁E(λ)) − sin(q₀E(λ))] dλ`, integrated by Gauss–Legendre.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContinuousCube;

impl ContinuousCube {
    /// Continuous face coordinates `(p, q)` ∈ `[-1, 1]²` from gnomonic ones `(A, B)`.
    #[inline]
    pub fn warp(a: f64, b: f64) -> (f64, f64) {
        let r = (1.0 + a * a).sqrt();
        let p = (a / SQRT_2).atan() / C;
        let q = (b / r).atan() / (1.0 / r).atan();
        (p, q)
    }

    /// Gnomonic face coordinates `(A, B)` from continuous ones `(p, q)`.
    #[inline]
    pub fn unwarp(p: f64, q: f64) -> (f64, f64) {
        let a = SQRT_2 * (C * p).tan();
        let r = (1.0 + a * a).sqrt();
        let psi = q * (1.0 / r).atan();
        (a, psi.tan() * r)
    }
}

impl WorldProjection for ContinuousCube {
    fn layer_count(&self) -> usize {
        6
    }
    fn layer_extent(&self, size: u32) -> (u32, u32) {
        (size, size)
    }
    #[inline]
    fn dir_to_uv(&self, d: DVec3) -> Option<(usize, DVec2)> {
        let (face, sc, tc, ma) = CubeFace::select(d);
        if ma <= 0.0 || !ma.is_finite() {
            return None;
        }
        let (p, q) = ContinuousCube::warp(sc / ma, tc / ma);
        Some((face as usize, DVec2::new(0.5 * (p + 1.0), 0.5 * (q + 1.0))))
    }
    #[inline]
    fn uv_to_dir(&self, layer: usize, uv: DVec2) -> Option<DVec3> {
        let face = CubeFace::from_index(layer)?;
        let (a, b) = ContinuousCube::unwarp(2.0 * uv.x - 1.0, 2.0 * uv.y - 1.0);
        Some(face.point(a, b).normalize())
    }
    fn density(&self, _layer: usize, uv: DVec2) -> f64 {
        let (p, q) = (2.0 * uv.x - 1.0, 2.0 * uv.y - 1.0);
        let cp = (C * p).cos();
        let a = SQRT_2 * (C * p).tan();
        let r = (1.0 + a * a).sqrt();
        let e = (1.0 / r).atan();
        let psi = q * e;
        let b = psi.tan() * r;
        let da_dp = SQRT_2 * C / (cp * cp);
        let cpsi = psi.cos();
        let db_dq = e * r / (cpsi * cpsi);
        let g = 1.0 + a * a + b * b;
        4.0 * da_dp * db_dq / (g * g.sqrt())
    }
    fn texel_solid_angle(&self, _layer: usize, x: u32, y: u32, w: u32, h: u32) -> f64 {
        let (u0, u1) = texel_range(x, w);
        let (v0, v1) = texel_range(y, h);
        let (q0, q1) = (2.0 * v0 - 1.0, 2.0 * v1 - 1.0);
        let lam = |u: f64| (SQRT_2 * (C * (2.0 * u - 1.0)).tan()).atan();
        gauss_legendre(lam(u0), lam(u1), |l| {
            let e = l.cos().atan();
            (q1 * e).sin() - (q0 * e).sin()
        })
    }
}
