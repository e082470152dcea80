//! `E5B9G9R9_UFLOAT_PACK32` (OpenGL's `GL_RGB9_E5`, Direct3D's `R9G9B9E5_SHAREDEXP`): three
//! 9-bit mantissas sharing one 5-bit exponent, R in bits 0–8, G in 9–17, B in 18–26, the
//! exponent in 27–31.
//!
//! Encoding follows the rule of EXT_texture_shared_exponent (OpenGL 4.6 §8.25, "Shared
//! Exponent Texture Color Conversion"), with N = 9 mantissa bits, E_max = 31 and bias
//! B = 15:
//!
//! 1. each component is clamped to `[0, sharedexp_max]`, `sharedexp_max =
//!    (2^N − 1)/2^N · 2^(E_max − B)` = 65408 (NaN becomes 0);
//! 2. `exp_shared' = max(−B − 1, ⌊log₂ max_c⌋) + 1 + B`;
//! 3. `max_s = ⌊max_c / 2^(exp_shared' − B − N) + ½⌋`; if `max_s = 2^N` the exponent is one
//!    more (`exp_shared = exp_shared' + 1`), else `exp_shared = exp_shared'`;
//! 4. each mantissa is `⌊c / 2^(exp_shared − B − N) + ½⌋`.
//!
//! Decoding is `mantissa · 2^(exponent − B − N)`. The error of a component is at most half a
//! step of the shared scale, `2^(exp_shared − B − N − 1)`, so at most `2^−9` of the largest
//! component (relative to it, not to the component itself: small components of a bright
//! texel lose their precision).

/// Mantissa bits.
const N: i32 = 9;
/// Exponent bias.
const B: i32 = 15;
/// Largest encodable value, `(2^N − 1)/2^N · 2^(E_max − B)`.
pub const MAX: f32 = 511.0 / 512.0 * 65536.0;

/// `⌊log₂ v⌋` of a positive normal `f32`, read from its exponent bits (exact).
fn floor_log2(v: f32) -> i32 {
    ((v.to_bits() >> 23) & 0xff) as i32 - 127
}

/// `2^e` for a normal `f64` exponent, from its bits.
pub(crate) fn pow2(e: i32) -> f64 {
    f64::from_bits(((e + 1023) as u64) << 52)
}

/// Packs one linear RGB texel.
pub fn encode(rgb: [f32; 3]) -> u32 {
    // `max(0, min(MAX, c))` with NaN going to 0: `c > 0` is false for NaN.
    let c = rgb.map(|c| if c > 0.0 { c.min(MAX) } else { 0.0 });
    let max_c = c[0].max(c[1]).max(c[2]);
    // Below 2^−16 the max(−B − 1, …) clause decides, so subnormals never reach floor_log2.
    let log = if max_c < 2f32.powi(-B - 1) {
        -B - 1
    } else {
        floor_log2(max_c)
    };
    let mut exp = log + 1 + B;
    // c / 2^(e − B − N) as c · 2^(B + N − e): exact in f64 (c is an f32, the factor a power
    // of two, the product below 2^10), and so is the + ½.
    let inv_step = |e: i32| pow2(B + N - e);
    let max_s = (f64::from(max_c) * inv_step(exp) + 0.5).floor();
    if max_s >= f64::from(1 << N) {
        exp += 1;
    }
    let s = inv_step(exp);
    let m = c.map(|c| (f64::from(c) * s + 0.5).floor() as u32);
    m[0] | m[1] << 9 | m[2] << 18 | (exp as u32) << 27
}

/// Unpacks one texel.
pub fn decode(v: u32) -> [f32; 3] {
    // value = mantissa × 2^(exponent − bias − mantissa bits).
    let scale = 2f32.powi((v >> 27) as i32 - B - N);
    [
        (v & 0x1ff) as f32 * scale,
        ((v >> 9) & 0x1ff) as f32 * scale,
        ((v >> 18) & 0x1ff) as f32 * scale,
    ]
}
