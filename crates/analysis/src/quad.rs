//! 16-point Gauss–Legendre quadrature (Abramowitz & Stegun, table 25.4): exact for
//! polynomials of degree 31. Used for the exact used-area integral `½∮ r(ψ)² dψ`.

/// Positive nodes on `[-1, 1]` (the rule is symmetric).
#[allow(clippy::excessive_precision)]
const X: [f64; 8] = [
    0.095_012_509_837_637_44,
    0.281_603_550_779_258_9,
    0.458_016_777_657_227_4,
    0.617_876_244_402_643_8,
    0.755_404_408_355_003_0,
    0.865_631_202_387_831_8,
    0.944_575_023_073_232_6,
    0.989_400_934_991_649_9,
];
/// Their weights.
#[allow(clippy::excessive_precision)]
const W: [f64; 8] = [
    0.189_450_610_455_068_5,
    0.182_603_415_044_923_6,
    0.169_156_519_395_002_5,
    0.149_595_988_816_576_7,
    0.124_628_971_255_533_9,
    0.095_158_511_682_492_78,
    0.062_253_523_938_647_89,
    0.027_152_459_411_754_09,
];

/// `∫ₐᵇ f(t) dt` by 16-point Gauss–Legendre.
pub fn gauss_legendre<F: FnMut(f64) -> f64>(a: f64, b: f64, mut f: F) -> f64 {
    let m = 0.5 * (a + b);
    let r = 0.5 * (b - a);
    let mut s = 0.0;
    for i in 0..8 {
        let dx = r * X[i];
        s += W[i] * (f(m - dx) + f(m + dx));
    }
    s * r
}
