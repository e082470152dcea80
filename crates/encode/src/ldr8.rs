//! HDR in four 8-bit channels, for engines that take only 8-bit textures (PNG, JPEG, WebGL
//! 1): RGBD and RGBM. Both are stored as `R8G8B8A8_UNORM`, never `_SRGB`: the engine's
//! shader decodes them (alpha is a linear factor, and RGBD's colour curve is not sRGB's), so
//! the texture unit must hand the bytes over unchanged. A byte `b` is read as `b/255`; a
//! value is written as the nearest byte, `round(255·x)`, as a GPU stores a UNORM8.

/// RGBD's range: the largest value it holds (Babylon.js's `rgbdMaxRange`).
pub const RGBD_RANGE: f32 = 255.0;

/// RGBM's range: the largest value it holds, `M = 1`, `rgb = 1`. The decoder must use the
/// same number (three.js's `RGBMToLinear(value, maxRange)`, PlayCanvas's `decodeRGBM`
/// scale).
pub const RGBM_RANGE: f32 = 6.0;

/// Babylon.js's `maxEps` floor on the largest channel (`Epsilon` in its helper functions).
const EPSILON: f32 = 1e-7;

fn unorm8(x: f32) -> u8 {
    (x.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// RGBD as Babylon.js writes it (`toRGBD` in `helperFunctions.fx`, used by its `.env`
/// writer through the `rgbdEncode` shader):
///
/// ```text
/// maxRGB = max(ε, max(r, g, b));  D = max(255/maxRGB, 1);  D = saturate(⌊D⌋/255)
/// rgb = saturate(toGammaSpace(color·D));  return (rgb, D)
/// ```
///
/// with `toGammaSpace(x) = x^(1/2.2)` (`GammaEncodePowerApprox`). The divisor D is an exact
/// byte, ⌊D⌋ in 1..=255: bright texels get a small D, dark ones the largest.
pub fn rgbd_encode(rgb: [f32; 3]) -> [u8; 4] {
    let c = rgb.map(|c| if c > 0.0 { c } else { 0.0 });
    let max_rgb = c[0].max(c[1]).max(c[2]).max(EPSILON);
    let d = (RGBD_RANGE / max_rgb).max(1.0).floor().min(255.0);
    let scaled = c.map(|c| unorm8((c * (d / 255.0)).powf(1.0 / 2.2)));
    [scaled[0], scaled[1], scaled[2], d as u8]
}

/// Babylon.js's `fromRGBD`: `toLinearSpace(rgb) / D`, `toLinearSpace(x) = x^2.2`.
pub fn rgbd_decode(t: [u8; 4]) -> [f32; 3] {
    let d = f32::from(t[3]) / 255.0;
    let lin = |b: u8| (f32::from(b) / 255.0).powf(2.2) / d;
    if t[3] == 0 {
        return [0.0; 3];
    }
    [lin(t[0]), lin(t[1]), lin(t[2])]
}

/// RGBM as three.js's `LinearToRGBM(value, maxRange)` writes it, linear (no gamma):
///
/// ```text
/// M = ⌈saturate(max(r, g, b)/range)·255⌉/255;  return (rgb/(M·range), M)
/// ```
///
/// M rounds up, so `rgb/(M·range) ≤ 1`; a black texel (M = 0) is stored as four zeros
/// (the formula's 0/0).
pub fn rgbm_encode(rgb: [f32; 3]) -> [u8; 4] {
    let c = rgb.map(|c| if c > 0.0 { c } else { 0.0 });
    let max_rgb = c[0].max(c[1]).max(c[2]);
    let m = ((max_rgb / RGBM_RANGE).clamp(0.0, 1.0) * 255.0).ceil();
    if m == 0.0 {
        return [0; 4];
    }
    let scale = 255.0 / (m * RGBM_RANGE);
    let s = c.map(|c| unorm8(c * scale));
    [s[0], s[1], s[2], m as u8]
}

/// three.js's `RGBMToLinear`: `rgb · M · range`.
pub fn rgbm_decode(t: [u8; 4]) -> [f32; 3] {
    let m = f32::from(t[3]) / 255.0 * RGBM_RANGE;
    [0, 1, 2].map(|i| f32::from(t[i]) / 255.0 * m)
}
