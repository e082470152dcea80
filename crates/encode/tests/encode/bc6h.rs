//! BC6H: both encoders decoded by a second, independent decoder (`texture2ddecoder`), the
//! padding of small mips, and refusals.

use half as _;
use mirrorball_core::Image;
use mirrorball_encode::{bc6h, Encoding};

/// A smooth HDR test image with a bright spot: values 0.01 … 60.
fn hdr_image(w: u32, h: u32, signed: bool) -> Image {
    let mut data = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let (u, v) = (x as f32 / w as f32, y as f32 / h as f32);
            let spot = 60.0 * (-((u - 0.3).powi(2) + (v - 0.6).powi(2)) * 40.0).exp();
            let mut px = [
                0.02 + u * 2.0 + spot,
                0.01 + v + spot * 0.8,
                0.5 * u * v + 0.05,
            ];
            if signed && (x + y) % 3 == 0 {
                px[2] = -px[2];
            }
            data.extend(px);
        }
    }
    Image::from_vec(w, h, 3, data).unwrap()
}

/// The same picture in [0, 0.9], where 8-bit output still tells decoders apart.
fn ldr_image(w: u32, h: u32) -> Image {
    let hdr = hdr_image(w, h, false);
    let data = hdr.data().iter().map(|v| (v / 70.0).sqrt() * 0.9).collect();
    Image::from_vec(w, h, 3, data).unwrap()
}

/// texture2ddecoder (an independent port, from AssetStudio's C++) decodes blocks to 8-bit
/// BGRA by `(f·255).clamp(0, 255) as u8`; bcdec_rs's floats, truncated the same way, must
/// give the same bytes, for every mode and partition Intel's encoder picks.
#[test]
fn unsigned_blocks_decode_the_same_in_a_second_decoder() {
    let (w, h) = (64, 64);
    let image = ldr_image(w, h);
    let mut out = Vec::new();
    Encoding::Bc6hUnsigned.encode(&image, &mut out);
    let ours = Encoding::Bc6hUnsigned.decode(&out, w, h);
    let (bw, _) = bc6h::blocks(w, h);
    let mut modes = std::collections::BTreeSet::new();
    for (i, block) in out.chunks_exact(16).enumerate() {
        modes.insert(if block[0] & 2 == 0 {
            block[0] & 3
        } else {
            block[0] & 31
        });
        let mut texels = [0u32; 16];
        texture2ddecoder::decode_bc6_block(block, &mut texels, false);
        for (t, &bgra) in texels.iter().enumerate() {
            let (x, y) = ((i % bw) * 4 + t % 4, (i / bw) * 4 + t / 4);
            let [b, g, r, _] = bgra.to_le_bytes();
            let px = ours.get(x as u32, y as u32);
            let byte = |v: f32| (v * 255.0).clamp(0.0, 255.0) as u8;
            assert_eq!(
                [r, g, b],
                [byte(px[0]), byte(px[1]), byte(px[2])],
                "block {i}"
            );
        }
    }
    assert!(
        modes.len() >= 2,
        "the test image should exercise several modes: {modes:?}"
    );
}

/// Mode 11 decoded from the specification (D3D11.3 §19.5.9): two 10-bit endpoints per
/// channel after the 5 mode bits, sign-extended, unquantized, interpolated with 4-bit
/// weights, finished by ×31/32 of the magnitude.
fn decode_mode11_signed(block: &[u8]) -> [[f32; 3]; 16] {
    let bits = u128::from_le_bytes(block.try_into().unwrap());
    assert_eq!(bits & 31, 3, "mode 11");
    let field = |at: u32, n: u32| ((bits >> at) & ((1 << n) - 1)) as i32;
    let sext = |v: i32| (v << 22) >> 22;
    let unq = |q: i32| {
        let (s, m) = (q < 0, q.abs());
        let u = if m == 0 {
            0
        } else if m >= 511 {
            0x7fff
        } else {
            ((m << 15) + 0x4000) >> 9
        };
        if s {
            -u
        } else {
            u
        }
    };
    let e: Vec<i32> = (0..6).map(|k| unq(sext(field(5 + 10 * k, 10)))).collect();
    let w = [0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64];
    let mut out = [[0f32; 3]; 16];
    let mut at = 65;
    for (t, px) in out.iter_mut().enumerate() {
        let n = if t == 0 { 3 } else { 4 };
        let k = field(at, n) as usize;
        at += n;
        for c in 0..3 {
            let v = (e[c] * (64 - w[k]) + e[3 + c] * w[k] + 32) >> 6;
            let m = (v.abs() * 31) >> 5;
            let h = half::f16::from_bits(m as u16 | if v < 0 { 0x8000 } else { 0 });
            px[c] = h.to_f32();
        }
    }
    out
}

#[test]
fn signed_blocks_decode_the_same_by_the_specification() {
    let (w, h) = (32, 32);
    let image = hdr_image(w, h, true);
    let mut out = Vec::new();
    Encoding::Bc6hSigned.encode(&image, &mut out);
    let ours = Encoding::Bc6hSigned.decode(&out, w, h);
    let (bw, _) = bc6h::blocks(w, h);
    for (i, block) in out.chunks_exact(16).enumerate() {
        for (t, px) in decode_mode11_signed(block).iter().enumerate() {
            let (x, y) = ((i % bw) * 4 + t % 4, (i / bw) * 4 + t / 4);
            assert_eq!(ours.get(x as u32, y as u32), px, "block {i} texel {t}");
        }
    }
}

/// Log-domain PSNR over RGB, peak the largest log value (the metric the quality floors use).
fn log_psnr(a: &[f32], b: &[f32]) -> f64 {
    let l = |v: f32| f64::from(1.0 + v.abs()).log2() * f64::from(v.signum());
    let mut se = 0.0;
    let mut peak: f64 = 0.0;
    for (x, y) in a.iter().zip(b) {
        peak = peak.max(l(*x).abs());
        se += (l(*x) - l(*y)).powi(2);
    }
    10.0 * (peak * peak / (se / a.len() as f64)).log10()
}

#[test]
fn every_size_down_to_1x1_is_padded_and_decodes() {
    for signed in [false, true] {
        let e = if signed {
            Encoding::Bc6hSigned
        } else {
            Encoding::Bc6hUnsigned
        };
        for size in [1u32, 2, 3, 4, 5, 8, 13] {
            let image = hdr_image(size, size, false);
            let mut out = Vec::new();
            e.encode(&image, &mut out);
            assert_eq!(out.len(), bc6h::blocks(size, size).0.pow(2) * 16);
            // The blocks are those of the picture padded by repeating its last column and row.
            let padded_size = size.next_multiple_of(4);
            let mut padded = Image::new(padded_size, padded_size, 3);
            for y in 0..padded_size {
                for x in 0..padded_size {
                    let px = image.get(x.min(size - 1), y.min(size - 1)).to_vec();
                    padded.set(x, y, &px);
                }
            }
            let mut want = Vec::new();
            e.encode(&padded, &mut want);
            assert_eq!(out, want, "{e} {size}");
            let back = e.decode(&out, size, size);
            assert_eq!((back.width(), back.height()), (size, size));
            // Loosely: these small pictures span 0.01 to 60 in one block, off any one
            // colour line, which neither encoder can follow closely.
            let log = |v: f32| (1.0 + v.abs()).log2();
            for (p, q) in back.data().iter().zip(image.data()) {
                assert!((log(*p) - log(*q)).abs() <= 1.5, "{e} {size}: {p} vs {q}");
            }
        }
    }
}

#[test]
fn quality_of_both_encoders() {
    let image = hdr_image(64, 64, false);
    let signed_image = hdr_image(64, 64, true);
    for (e, img, floor) in [
        (Encoding::Bc6hUnsigned, &image, 45.0),
        (Encoding::Bc6hSigned, &image, 38.0),
        (Encoding::Bc6hSigned, &signed_image, 30.0),
    ] {
        let mut out = Vec::new();
        e.encode(img, &mut out);
        let back = e.decode(&out, 64, 64);
        let p = log_psnr(img.data(), back.data());
        assert!(p >= floor, "{e}: {p:.2} dB < {floor}");
    }
}

#[test]
fn negative_values_are_refused_as_unsigned() {
    let image = hdr_image(8, 8, true);
    let err = Encoding::Bc6hUnsigned.check(&image).unwrap_err();
    assert!(err.0.contains("negative"), "{err}");
    assert!(Encoding::Bc6hSigned.check(&image).is_ok());
    assert!(Encoding::Bc6hUnsigned
        .check(&hdr_image(8, 8, false))
        .is_ok());
}
