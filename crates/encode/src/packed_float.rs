//! `B10G11R11_UFLOAT_PACK32` (OpenGL's `GL_R11F_G11F_B10F`, Direct3D's `R11G11B10_FLOAT`):
//! R in bits 0–10 and G in 11–21 as unsigned 11-bit floats, B in 22–31 as an unsigned 10-bit
//! float. Each has no sign bit, a 5-bit exponent with bias 15 (binary16's) and a 6-bit (R, G)
//! or 5-bit (B) mantissa (Vulkan 1.3 §3.9.x "Unsigned 11-Bit / 10-Bit Floating-Point
//! Numbers", OpenGL 4.6 §2.3.4.3–4).
//!
//! Encoding rounds to the nearest representable value, ties to the even mantissa, with
//! subnormals (exponent 0) kept; negative values and NaN become 0, and values above the
//! largest finite one (`(2 − 2^−m)·2^15`: 65024 for 11 bits, 64512 for 10) are clamped to
//! it, infinity included, so a written texel is always finite. The relative error of a
//! normal value is at most `2^−(m+1)`: 1/128 for R and G, 1/64 for B.

/// Largest finite unsigned 11-bit float (R, G): `(2 − 2^−6)·2^15`.
pub const MAX_11: f32 = 65024.0;
/// Largest finite unsigned 10-bit float (B): `(2 − 2^−5)·2^15`.
pub const MAX_10: f32 = 64512.0;

/// Largest finite unsigned float with `mantissa_bits` of mantissa: `(2 − 2^−m)·2^15`
/// ([`MAX_11`], [`MAX_10`]).
pub fn max_finite(mantissa_bits: u32) -> f32 {
    (2.0 - 2f32.powi(-(mantissa_bits as i32))) * 32768.0
}

/// The unsigned small float nearest to `v` (ties to even), as its bits.
pub fn to_small_ufloat(v: f32, mantissa_bits: u32) -> u32 {
    let m = mantissa_bits as i32;
    if v.is_nan() || v <= 0.0 {
        return 0;
    }
    if v >= max_finite(mantissa_bits) {
        return (30 << m) | ((1 << m) - 1);
    }
    let v = f64::from(v);
    // The exponent e of v's leading bit, at least the subnormal one (−14).
    let e = ((v.to_bits() >> 52) as i32 - 1023).max(-14);
    // v / 2^(e − m) = v · 2^(m − e) is exact in f64; rounding it gives the mantissa with its leading bit
    // (or a subnormal one below 2^m). A carry out of the mantissa lands in the exponent
    // field, which is the next binade's correct encoding.
    let q = (v * crate::shared_exp::pow2(m - e)).round_ties_even() as u32;
    if e == -14 && q < 1 << m {
        return q; // subnormal: exponent field 0
    }
    (((e + 15) as u32) << m) + (q - (1 << m))
}

/// The value of the unsigned small float `bits`, as in the 11- and 10-bit channels.
pub fn small_ufloat(bits: u32, mantissa_bits: u32) -> f32 {
    let one = (1u32 << mantissa_bits) as f32;
    let m = bits & ((1 << mantissa_bits) - 1);
    match bits >> mantissa_bits {
        0 => m as f32 / one * 2f32.powi(-14),
        31 if m == 0 => f32::INFINITY,
        31 => f32::NAN,
        e => (1.0 + m as f32 / one) * 2f32.powi(e as i32 - 15),
    }
}

/// Packs one linear RGB texel.
pub fn encode(rgb: [f32; 3]) -> u32 {
    to_small_ufloat(rgb[0], 6) | to_small_ufloat(rgb[1], 6) << 11 | to_small_ufloat(rgb[2], 5) << 22
}

/// Unpacks one texel.
pub fn decode(v: u32) -> [f32; 3] {
    [
        small_ufloat(v & 0x7ff, 6),
        small_ufloat((v >> 11) & 0x7ff, 6),
        small_ufloat(v >> 22, 5),
    ]
}
