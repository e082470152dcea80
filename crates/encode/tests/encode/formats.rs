//! The per-texel encodings against their specifications, written again here independently.

use mirrorball_core::{Choice, Image};
use mirrorball_encode::{ldr8, packed_float, shared_exp, Encoding};
use proptest::prelude::*;

/// EXT_texture_shared_exponent's algorithm as the extension writes it, in `f64` with
/// `log2` (the crate reads the exponent bits instead).
fn rgb9e5_spec(rgb: [f32; 3]) -> u32 {
    let (n, b, emax) = (9.0f64, 15.0f64, 31.0f64);
    let sharedexp_max = (2f64.powf(n) - 1.0) / 2f64.powf(n) * 2f64.powf(emax - b);
    let c = rgb.map(|v| {
        let v = f64::from(v);
        if v.is_nan() {
            0.0
        } else {
            v.clamp(0.0, sharedexp_max)
        }
    });
    let max_c = c[0].max(c[1]).max(c[2]);
    let exp_p = (-b - 1.0).max(max_c.log2().floor()) + 1.0 + b;
    let max_s = (max_c / 2f64.powf(exp_p - b - n) + 0.5).floor();
    let exp = if max_s < 2f64.powf(n) {
        exp_p
    } else {
        exp_p + 1.0
    };
    let m = c.map(|v| (v / 2f64.powf(exp - b - n) + 0.5).floor() as u32);
    m[0] | m[1] << 9 | m[2] << 18 | (exp as u32) << 27
}

fn interesting() -> Vec<f32> {
    let mut v = vec![
        0.0,
        -1.0,
        f32::NAN,
        f32::INFINITY,
        1e-30,
        2f32.powi(-16),
        2f32.powi(-15),
        2f32.powi(-24),
        0.5,
        1.0,
        65408.0,
        65409.0,
        65535.0,
        1e9,
    ];
    // Values either side of every rounding boundary near 1: m + ½ steps of 2^-8.
    for m in 250..=512 {
        let x = (m as f32 + 0.5) / 256.0;
        v.extend([
            x,
            f32::from_bits(x.to_bits() - 1),
            f32::from_bits(x.to_bits() + 1),
        ]);
    }
    v
}

#[test]
fn rgb9e5_follows_the_extension_exactly() {
    let vals = interesting();
    for &r in &vals {
        for &g in [0.0, 0.3, 1.0, 511.5 / 256.0, 300.0].iter() {
            for &b in [0.0, 1e-6, 0.999_999].iter() {
                assert_eq!(
                    shared_exp::encode([r, g, b]),
                    rgb9e5_spec([r, g, b]),
                    "{r} {g} {b}"
                );
            }
        }
    }
}

proptest! {
    #[test]
    fn rgb9e5_matches_spec_and_round_trips(
        e in -20i32..17, m in 0.0f32..1.0, g in 0.0f32..1.0, b in 0.0f32..1.0
    ) {
        let r = (1.0 + m) * 2f32.powi(e);
        let rgb = [r, g * r * 1.5, b * r];
        let v = shared_exp::encode(rgb);
        prop_assert_eq!(v, rgb9e5_spec(rgb));
        // The error is at most half a step of the shared scale: 2^-10 of the largest
        // channel (the scale's step is at most 2^-9 of it, the rounding half of that).
        let back = shared_exp::decode(v);
        let max_c = rgb.iter().cloned().fold(0.0f32, f32::max).min(shared_exp::MAX);
        let step = 2f32.powi((v >> 27) as i32 - 24);
        for c in 0..3 {
            let want = rgb[c].min(shared_exp::MAX);
            prop_assert!((back[c] - want).abs() <= step / 2.0 + want * 1e-7,
                "{:?} -> {:?}", rgb, back);
            prop_assert!((back[c] - want).abs() <= max_c * 2f32.powi(-9) + 2f32.powi(-25));
        }
    }
}

/// Every value of an unsigned float with `m` mantissa bits, finite, in code order.
fn all_small_ufloats(m: u32) -> Vec<f64> {
    (0..(31u32 << m))
        .map(|b| f64::from(packed_float::small_ufloat(b, m)))
        .collect()
}

/// The code nearest to `v` by exhaustive search, ties to the even code; negatives and NaN
/// to 0, beyond the largest to the largest.
fn nearest_code(table: &[f64], v: f32) -> u32 {
    if v.is_nan() || v <= 0.0 {
        return 0;
    }
    let v = f64::from(v);
    if v >= table[table.len() - 1] {
        return table.len() as u32 - 1;
    }
    let mut best = (f64::INFINITY, 0u32);
    for (code, &x) in table.iter().enumerate() {
        let d = (x - v).abs();
        if d < best.0 || (d == best.0 && code % 2 == 0) {
            best = (d, code as u32);
        }
    }
    best.1
}

#[test]
fn small_floats_round_to_nearest_even_and_clamp() {
    for m in [6u32, 5] {
        let table = all_small_ufloats(m);
        // Every representable value and every midpoint (and its neighbours) between two.
        let mut probes = vec![0.0f32, -3.0, f32::NAN, f32::INFINITY, 1e10, 65535.0];
        for w in table.windows(2) {
            let mid = ((w[0] + w[1]) / 2.0) as f32;
            probes.extend([
                w[0] as f32,
                mid,
                f32::from_bits(mid.to_bits() - 1),
                f32::from_bits(mid.to_bits() + 1),
            ]);
        }
        for v in probes {
            assert_eq!(
                packed_float::to_small_ufloat(v, m),
                nearest_code(&table, v),
                "{v} with {m} mantissa bits"
            );
        }
        assert_eq!(
            packed_float::small_ufloat(packed_float::to_small_ufloat(f32::INFINITY, m), m),
            packed_float::max_finite(m)
        );
    }
}

#[test]
fn b10g11r11_packs_red_lowest() {
    let v = packed_float::encode([1.0, 2.0, 4.0]);
    // 1.0 = exponent 15, mantissa 0 in each.
    assert_eq!(v & 0x7ff, 15 << 6);
    assert_eq!((v >> 11) & 0x7ff, 16 << 6);
    assert_eq!(v >> 22, 17 << 5);
    assert_eq!(packed_float::decode(v), [1.0, 2.0, 4.0]);
}

#[test]
fn rgbd_follows_babylon() {
    // A bright texel: maxRGB = 10, D = ⌊25.5⌋ = 25.
    let t = ldr8::rgbd_encode([10.0, 5.0, 0.0]);
    assert_eq!(t[3], 25);
    assert_eq!(
        t[0],
        ((10.0f32 * 25.0 / 255.0).powf(1.0 / 2.2) * 255.0).round() as u8
    );
    // A dark one uses the largest D; one beyond the range clamps.
    assert_eq!(ldr8::rgbd_encode([0.1, 0.1, 0.1])[3], 255);
    assert_eq!(ldr8::rgbd_encode([1000.0, 0.0, 0.0]), [255, 0, 0, 1]);
    // Round trips within 8-bit precision after the gamma curve: the relative error of a
    // texel's largest channel is at most 2.2 · ½ / its byte (d(x^2.2)/x^2.2 = 2.2 dx/x).
    for v in [0.01f32, 0.2, 1.0, 3.7, 42.0, 200.0] {
        let t = ldr8::rgbd_encode([v, v * 0.5, v * 0.1]);
        let back = ldr8::rgbd_decode(t);
        let tol = 2.2 * 0.5 / f32::from(t[0]) * 1.01;
        assert!((back[0] / v - 1.0).abs() <= tol, "{v}: {back:?}");
    }
}

#[test]
fn rgbm_follows_three() {
    let t = ldr8::rgbm_encode([3.0, 1.5, 0.0]);
    // M = ⌈3/6·255⌉ = 128, rgb = value/(M/255·6).
    assert_eq!(t[3], 128);
    assert_eq!(t[0], (3.0f32 / (128.0 / 255.0 * 6.0) * 255.0).round() as u8);
    assert_eq!(ldr8::rgbm_encode([0.0; 3]), [0; 4]);
    assert_eq!(
        ldr8::rgbm_decode(ldr8::rgbm_encode([100.0, 0.0, 0.0])),
        [6.0, 0.0, 0.0]
    );
    for v in [0.05f32, 0.5, 1.0, 5.9] {
        let back = ldr8::rgbm_decode(ldr8::rgbm_encode([v, 0.0, 0.0]));
        // The largest channel's byte is ≥ 254·(M−1)/M; its error half a byte of M·range.
        let m = (v / 6.0 * 255.0).ceil() / 255.0 * 6.0;
        assert!(
            (back[0] - v).abs() <= m * 0.5 / 255.0 + 1e-6,
            "{v}: {back:?}"
        );
    }
}

#[test]
fn every_encoding_sizes_and_round_trips_an_image() {
    let w = 5;
    let h = 3;
    let data: Vec<f32> = (0..w * h * 3)
        .map(|i| 0.25 + (i % 7) as f32 * 0.5)
        .collect();
    let image = Image::from_vec(w, h, 3, data.clone()).unwrap();
    for e in Encoding::all() {
        let mut out = Vec::new();
        e.encode(&image, &mut out);
        assert_eq!(out.len(), e.image_bytes(w, h), "{e}");
        let back = e.decode(&out, w, h);
        assert_eq!(back.channels(), e.channels());
        for (px, want) in back
            .data()
            .chunks_exact(e.channels())
            .zip(data.chunks_exact(3))
        {
            for c in 0..3 {
                let tol = match e {
                    Encoding::Rgba32F => 0.0,
                    Encoding::Rgba16F => want[c] * 2f32.powi(-11),
                    Encoding::Rgb9E5 => 3.25 * 2f32.powi(-9),
                    Encoding::B10G11R11 => want[c] * 2f32.powi(-6),
                    Encoding::Rgbd | Encoding::Rgbm => 0.04 * want[c].max(1.0),
                    // BC6H: lossy with one colour line per region, so noise like this
                    // picture's is beyond it; its quality is measured in the bc6h module.
                    _ => f32::INFINITY,
                };
                assert!(
                    (px[c] - want[c]).abs() <= tol,
                    "{e}: {} vs {}",
                    px[c],
                    want[c]
                );
            }
        }
    }
}

#[test]
fn names_parse_back() {
    for e in Encoding::all() {
        assert_eq!(e.name().parse::<Encoding>().unwrap(), e);
    }
    assert_eq!(
        "R11G11B10".parse::<Encoding>().unwrap(),
        Encoding::B10G11R11
    );
}
