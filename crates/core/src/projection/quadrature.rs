//! Exact-integration helpers shared by the projections: Gauss–Legendre quadrature and the
//! solid angle of spherical polygons.

use glam::DVec3;

/// 16-point Gauss–Legendre nodes on `[-1, 1]` (positive half; the rule is symmetric) and
/// their weights (Abramowitz & Stegun, table 25.4). Exact for polynomials of degree 31.
#[allow(clippy::excessive_precision)]
const GL16_X: [f64; 8] = [
    0.095_012_509_837_637_44,
    0.281_603_550_779_258_9,
    0.458_016_777_657_227_4,
    0.617_876_244_402_643_8,
    0.755_404_408_355_003_0,
    0.865_631_202_387_831_8,
    0.944_575_023_073_232_6,
    0.989_400_934_991_649_9,
];
#[allow(clippy::excessive_precision)]
const GL16_W: [f64; 8] = [
    0.189_450_610_455_068_5,
    0.182_603_415_044_923_6,
    0.169_156_519_395_002_5,
    0.149_595_988_816_576_7,
    0.124_628_971_255_533_9,
    0.095_158_511_682_492_78,
    0.062_253_523_938_647_89,
    0.027_152_459_411_754_09,
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
    fn octant_is_an_eighth_of_the_sphere() {
        let o = triangle_solid_angle(DVec3::X, DVec3::Y, DVec3::Z);
        assert!((o - std::f64::consts::PI / 2.0).abs() < 1e-14);
        assert!((triangle_solid_angle(DVec3::X, DVec3::Z, DVec3::Y) + o).abs() < 1e-14);
    }
}
