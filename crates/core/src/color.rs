//! Transfer functions: the sRGB encoding and the tone curves that squeeze radiance into
//! `[0, 1]` for screens. Pure arithmetic; the crates that write files build their tables
//! from these.
//!
//! **sRGB** (IEC 61966-2-1:1999, §4.7 and its amendment's exact constants): encoded `V`
//! and linear `L` in `[0, 1]`,
//!
//! ```text
//! L = V/12.92                       V ≤ 0.04045
//! L = ((V + 0.055)/1.055)^2.4       otherwise
//! V = 12.92 L                       L ≤ 0.0031308
//! V = 1.055 L^(1/2.4) − 0.055       otherwise
//! ```
//!
//! (The two thresholds are the standard's; they meet the curves within `10⁻⁷`, not
//! exactly.)
//!
//! ```
//! use mirrorball_core::color::{linear_to_srgb, srgb_to_linear};
//! assert!((srgb_to_linear(linear_to_srgb(0.18)) - 0.18).abs() < 1e-12);
//! assert!((linear_to_srgb(1.0) - 1.0).abs() < 1e-15);
//! ```

/// Encoded values at or below this are on the linear segment (IEC 61966-2-1).
pub const SRGB_ENCODED_KNEE: f64 = 0.040_45;
/// Linear values at or below this are on the linear segment (IEC 61966-2-1).
pub const SRGB_LINEAR_KNEE: f64 = 0.003_130_8;
/// The slope of the linear segment.
pub const SRGB_SLOPE: f64 = 12.92;
/// The power segment's scale `1 + a` (`a = 0.055`).
pub const SRGB_SCALE: f64 = 1.055;
/// The power segment's offset `a`.
pub const SRGB_OFFSET: f64 = 0.055;
/// The power segment's exponent.
pub const SRGB_GAMMA: f64 = 2.4;

/// The sRGB decoding (the EOTF): encoded value in `[0, 1]` to linear light, in `f64`.
#[inline]
pub fn srgb_to_linear(v: f64) -> f64 {
    if v <= SRGB_ENCODED_KNEE {
        v / SRGB_SLOPE
    } else {
        ((v + SRGB_OFFSET) / SRGB_SCALE).powf(SRGB_GAMMA)
    }
}

/// The one body of the sRGB encoding, for `f64` and `f32` (every constant converts to `f32`
/// exactly as its decimal literal reads, so the `f32` curve is the standard's too).
macro_rules! encode_srgb {
    ($l:expr, $t:ty) => {{
        let l: $t = $l;
        if l <= SRGB_LINEAR_KNEE as $t {
            SRGB_SLOPE as $t * l
        } else {
            SRGB_SCALE as $t * l.powf(1.0 / SRGB_GAMMA as $t) - SRGB_OFFSET as $t
        }
    }};
}

/// The sRGB encoding (the inverse EOTF): linear light in `[0, 1]` to an encoded value, in
/// `f64` (so that 16-bit codes round to nearest exactly).
#[inline]
pub fn linear_to_srgb(l: f64) -> f64 {
    encode_srgb!(l, f64)
}

/// [`linear_to_srgb`] evaluated in `f32`. Rounded to 8 bits it gives the code nearest the
/// exact curve for all but a few hundred of the 10⁹ `f32` values in `[0, 1]` (those within
/// an `f32` rounding of a code's boundary).
#[inline]
pub fn linear_to_srgb_f32(l: f32) -> f32 {
    encode_srgb!(l, f32)
}

/// Linear `x` clamped to `[0, 1]`, sRGB-encoded in `f32` and rounded to 8 bits.
#[inline]
pub fn srgb8_f32(x: f32) -> u8 {
    (linear_to_srgb_f32(x.clamp(0.0, 1.0)) * 255.0 + 0.5) as u8
}

/// Reinhard's global operator `x/(1 + x)` (Reinhard et al. 2002, eq. 3), for `x ≥ 0`.
#[inline]
pub fn reinhard(x: f32) -> f32 {
    x / (1.0 + x)
}

/// Narkowicz's fit of the ACES filmic curve (2016),
/// `x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14)`, clipped to `[0, 1]`, for `x ≥ 0`.
#[inline]
pub fn aces_narkowicz(x: f32) -> f32 {
    (x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_segments_meet_and_invert() {
        // The standard's knees join the segments to within 1e-7 (not exactly).
        let a = SRGB_SLOPE * SRGB_LINEAR_KNEE;
        let b = SRGB_SCALE * SRGB_LINEAR_KNEE.powf(1.0 / SRGB_GAMMA) - SRGB_OFFSET;
        assert!((a - b).abs() < 1e-7);
        assert!((srgb_to_linear(SRGB_ENCODED_KNEE) - SRGB_ENCODED_KNEE / SRGB_SLOPE).abs() < 1e-15);
        for k in 0..=1000 {
            let l = k as f64 / 1000.0;
            assert!((srgb_to_linear(linear_to_srgb(l)) - l).abs() < 1e-12);
        }
    }

    #[test]
    fn the_f32_encoding_is_the_f64_one_in_f32() {
        for k in 0..=100_000 {
            let l = k as f32 / 100_000.0;
            let e = linear_to_srgb(l as f64);
            assert!((linear_to_srgb_f32(l) as f64 - e).abs() < 4e-7, "{l}");
        }
        assert_eq!(srgb8_f32(1.0), 255);
        assert_eq!(srgb8_f32(-1.0), 0);
        assert_eq!(srgb8_f32(0.5), 188);
    }

    #[test]
    fn tone_curves_map_into_the_unit_interval() {
        for k in 0..1000 {
            let x = k as f32 * 0.05;
            for y in [reinhard(x), aces_narkowicz(x)] {
                assert!((0.0..=1.0).contains(&y));
            }
        }
        assert_eq!(reinhard(1.0), 0.5);
        assert_eq!(aces_narkowicz(0.0), 0.0);
    }
}
