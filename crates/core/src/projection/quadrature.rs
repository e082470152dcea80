//! Exact-integration helpers shared by the projections: Gauss–Legendre quadrature and the
//! solid angle of spherical polygons.

use glam::{DVec2, DVec3};

/// 16-point Gauss–Legendre nodes on `[-1, 1]` (positive half; the rule is symmetric) and
/// their weights, each the `f64` nearest the true value: the roots `xᵢ` of the Legendre
/// polynomial `P₁₆` by Newton's iteration and `wᵢ = 2/((1 − xᵢ²) P₁₆′(xᵢ)²)` (Abramowitz &
/// Stegun 25.4.29), both in 60-digit arithmetic (mpmath), then rounded once. They agree
/// with Abramowitz & Stegun table 25.4 to its 15 printed digits. Exact for polynomials of
/// degree 31 (tested, with an `f64` Newton computation of the same roots).
const GL16_X: [f64; 8] = [
    0.095_012_509_837_637_44,
    0.281_603_550_779_258_9,
    0.458_016_777_657_227_37,
    0.617_876_244_402_643_8,
    0.755_404_408_355_003,
    0.865_631_202_387_831_8,
    0.944_575_023_073_232_6,
    0.989_400_934_991_649_9,
];
const GL16_W: [f64; 8] = [
    0.189_450_610_455_068_5,
    0.182_603_415_044_923_58,
    0.169_156_519_395_002_54,
    0.149_595_988_816_576_74,
    0.124_628_971_255_533_88,
    0.095_158_511_682_492_79,
    0.062_253_523_938_647_894,
    0.027_152_459_411_754_096,
];

/// ∫ₐᵇ f(t) dt by 16-point Gauss–Legendre.
pub fn gauss_legendre<F: FnMut(f64) -> f64>(a: f64, b: f64, mut f: F) -> f64 {
    let m = 0.5 * (a + b);
    let r = 0.5 * (b - a);
    let mut s = 0.0;
    for i in 0..8 {
        let dx = r * GL16_X[i];
        s += GL16_W[i] * (f(m - dx) + f(m + dx));
    }
    s * r
}

/// Signed solid angle of the spherical triangle with vertices in the directions `a`, `b`,
/// `c` (need not be unit length), by Van Oosterom & Strackee (1983):
/// `tan(Ω/2) = a·(b×c) / (|a||b||c| + (a·b)|c| + (a·c)|b| + (b·c)|a|)`.
pub fn triangle_solid_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let num = a.dot(b.cross(c));
    let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    2.0 * num.atan2(den)
}

/// Unsigned solid angle of a convex spherical polygon given by its vertex directions in
/// order (a triangle fan; the edges are great-circle arcs).
pub fn polygon_solid_angle(v: &[DVec3]) -> f64 {
    if v.len() < 3 {
        return 0.0;
    }
    let mut s = 0.0;
    for i in 1..v.len() - 1 {
        s += triangle_solid_angle(v[0], v[i], v[i + 1]);
    }
    s.abs()
}

/// Clips a convex polygon to the half-plane `n·p ≤ c` (Sutherland–Hodgman).
pub(crate) fn clip(poly: &[DVec2], n: DVec2, c: f64) -> Vec<DVec2> {
    let mut out = Vec::with_capacity(poly.len() + 2);
    for i in 0..poly.len() {
        let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
        let (dp, dq) = (n.dot(p) - c, n.dot(q) - c);
        if dp <= 0.0 {
            out.push(p);
        }
        if (dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0) {
            out.push(p + (q - p) * (dp / (dp - dq)));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_degree_31_exactly() {
        let v = gauss_legendre(-1.0, 2.0, |t| t.powi(31) - 3.0 * t.powi(10));
        let exact = (2f64.powi(32) - 1.0) / 32.0 - 3.0 * (2f64.powi(11) + 1.0) / 11.0;
        assert!((v - exact).abs() < 1e-9 * exact.abs(), "{v} vs {exact}");
    }

    #[test]
    fn gauss_legendre_integrates_every_monomial_to_degree_31() {
        for k in 0..=31 {
            let v = gauss_legendre(0.0, 1.0, |t| t.powi(k));
            let exact = 1.0 / (k + 1) as f64;
            assert!(
                (v - exact).abs() <= 16.0 * f64::EPSILON * exact,
                "t^{k}: {v} vs {exact}"
            );
        }
        // Degree 32 is the first the rule cannot integrate.
        let v = gauss_legendre(-1.0, 1.0, |t| t.powi(32));
        assert!((v - 2.0 / 33.0).abs() > 1e-12);
    }

    /// `(P₁₆(x), P₁₆′(x))` by the three-term recurrence.
    fn legendre16(x: f64) -> (f64, f64) {
        let (mut p0, mut p1) = (1.0, x);
        for k in 2..=16 {
            let k = k as f64;
            (p0, p1) = (p1, ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k);
        }
        (p1, 16.0 * (x * p1 - p0) / (x * x - 1.0))
    }

    #[test]
    fn table_matches_a_newton_computation_of_the_roots() {
        for i in 0..8 {
            // Root 8 − i of P₁₆ counted from +1: cos(π(k − ¼)/(n + ½)) starts Newton close.
            let k = (8 - i) as f64;
            let mut x = (std::f64::consts::PI * (k - 0.25) / 16.5).cos();
            for _ in 0..8 {
                let (p, dp) = legendre16(x);
                x -= p / dp;
            }
            let (_, dp) = legendre16(x);
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            let ulps = |a: f64, b: f64| (a.to_bits() as i64 - b.to_bits() as i64).abs();
            assert!(ulps(x, GL16_X[i]) <= 2, "x{i}: {x:e} vs {:e}", GL16_X[i]);
            // The weight formula loses a few digits in `f64` (P₁₆′ near ±1).
            assert!(
                (w / GL16_W[i] - 1.0).abs() < 1e-14,
                "w{i}: {w:e} vs {:e}",
                GL16_W[i]
            );
        }
        assert!((2.0 * GL16_W.iter().sum::<f64>() - 2.0).abs() < 4.0 * f64::EPSILON);
    }

    #[test]
    fn octant_is_an_eighth_of_the_sphere() {
        let o = triangle_solid_angle(DVec3::X, DVec3::Y, DVec3::Z);
        assert!((o - std::f64::consts::PI / 2.0).abs() < 1e-14);
        assert!((triangle_solid_angle(DVec3::X, DVec3::Z, DVec3::Y) + o).abs() < 1e-14);
    }
}
