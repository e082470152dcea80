//! BC6H (Direct3D 11's `BC6H_UF16`/`BC6H_SF16`, Vulkan's `BC6H_UFLOAT_BLOCK`/
//! `BC6H_SFLOAT_BLOCK`): 4×4 texel blocks of 16 bytes, RGB half floats, no alpha.
//!
//! **Unsigned** blocks come from Intel's ISPC Texture Compressor (`intel_tex_2`, its BC6H
//! kernel with one of its five quality profiles, [`Effort`]): it searches all fourteen
//! modes and the 32 two-region partitions. The Rust port of the same kernel
//! (`block_compression`) gives the same log-PSNR but ran 4–9× slower here, so the ISPC build
//! is used; rows of blocks are compressed on all cores.
//!
//! **Signed** blocks: neither encoder writes them (the ISPC kernel is UF16 only), so they come
//! from [`encode_signed_block`] here, written from the format's specification (Direct3D 11.3
//! §19.5.9, "BC6H", and the Khronos Data Format Specification 1.3 §21, "BC6H"): mode 11
//! only, one region with two 10-bit endpoints stored as they are and 4-bit indices. It fits
//! the endpoints along the block's principal axis in the space the hardware interpolates in
//! (half-float bit patterns, nearly logarithmic), then refines them by least squares.
//!
//! Faces whose size is not a multiple of 4 (the 2×2 and 1×1 mips of every chain) are
//! padded to whole blocks by repeating their last column and row, as the format requires
//! (the padding texels are never sampled).
//!
//! Decoding, for the readers, is `bcdec_rs`'s; the tests check it, and both encoders,
//! against a second decoder (`texture2ddecoder`).

use crate::range::Storage;
use crate::Encoding;
use half::f16;
use mirrorball_core::Image;
use rayon::prelude::*;

/// Bytes of one 4×4 block.
pub const BLOCK_BYTES: usize = 16;

/// How hard the unsigned encoder searches: Intel's profiles of the same names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Effort {
    /// One-region modes only, no refinement.
    VeryFast,
    /// Two-region partitions tried, little refinement.
    Fast,
    /// Two refinement passes (the default: within 0.2 dB of `Slow` at a fifth of its time).
    #[default]
    Basic,
    /// Every mode and partition, fully refined.
    Slow,
}

impl mirrorball_core::Choice for Effort {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (Effort::VeryFast, &["very-fast"]),
        (Effort::Fast, &["fast"]),
        (Effort::Basic, &["basic", "default"]),
        (Effort::Slow, &["slow", "best"]),
    ];
}
mirrorball_core::choice_traits!(Effort);

/// Blocks across and down an image of `width`×`height` texels.
pub fn blocks(width: u32, height: u32) -> (usize, usize) {
    (width.div_ceil(4) as usize, height.div_ceil(4) as usize)
}

/// The texel of `image` that padded position `(x, y)` repeats: the nearest one inside.
fn clamped(image: &Image, x: usize, y: usize) -> &[f32] {
    let x = x.min(image.width() as usize - 1) as u32;
    let y = y.min(image.height() as usize - 1) as u32;
    image.get(x, y)
}

/// Rows `4·band..4·band + 4` of `image` as little-endian RGBA binary16, padded to `4·bw`
/// columns by edge replication, into `out` (`4·bw·4·8` bytes); values fitted to unsigned
/// BC6H's range ([`crate::Range::fit`]: a sun brighter than 65504 is 65504, never infinity).
fn band_rgba16(image: &Image, band: usize, bw: usize, out: &mut [u8]) {
    let range = Storage::Texels(Encoding::Bc6hUnsigned).range();
    for y in 0..4 {
        for x in 0..4 * bw {
            let px = clamped(image, x, 4 * band + y);
            let o = (y * 4 * bw + x) * 8;
            let rgb = [0, 1, 2].map(|c| range.fit(c, px[c]));
            let rgba = [rgb[0], rgb[1], rgb[2], 1.0].map(|v| f16::from_f32(v).to_le_bytes());
            out[o..o + 8].copy_from_slice(rgba.as_flattened());
        }
    }
}

/// Encodes `image` as unsigned BC6H blocks (row-major) into `out`, replacing its contents.
/// Negative values must have been refused before ([`crate::Encoding::check`]); the kernel
/// would clamp them to 0.
pub fn encode_unsigned(image: &Image, effort: Effort, out: &mut Vec<u8>) {
    let settings = match effort {
        Effort::VeryFast => intel_tex_2::bc6h::very_fast_settings(),
        Effort::Fast => intel_tex_2::bc6h::fast_settings(),
        Effort::Basic => intel_tex_2::bc6h::basic_settings(),
        Effort::Slow => intel_tex_2::bc6h::slow_settings(),
    };
    let (bw, bh) = blocks(image.width(), image.height());
    out.clear();
    out.resize(bw * bh * BLOCK_BYTES, 0);
    out.par_chunks_mut(bw * BLOCK_BYTES)
        .enumerate()
        .for_each_init(
            || vec![0u8; 16 * bw * 8],
            |texels, (band, row)| {
                band_rgba16(image, band, bw, texels);
                let surface = intel_tex_2::RgbaSurface {
                    data: texels,
                    width: 4 * bw as u32,
                    height: 4,
                    stride: 4 * bw as u32 * 8,
                };
                intel_tex_2::bc6h::compress_blocks_into(&settings, &surface, row);
                mirrorball_core::work::add(Encoding::Bc6hUnsigned.work(16 * bw as u64));
            },
        );
}

/// Encodes `image` as signed BC6H blocks (row-major) into `out`, replacing its contents;
/// values fitted to signed BC6H's range ([`crate::Range::fit`]).
pub fn encode_signed(image: &Image, out: &mut Vec<u8>) {
    let range = Storage::Texels(Encoding::Bc6hSigned).range();
    let (bw, bh) = blocks(image.width(), image.height());
    out.clear();
    out.resize(bw * bh * BLOCK_BYTES, 0);
    out.par_chunks_mut(BLOCK_BYTES)
        .enumerate()
        .for_each(|(i, block)| {
            let (bx, by) = (i % bw, i / bw);
            let mut texels = [[0f32; 3]; 16];
            for (t, texel) in texels.iter_mut().enumerate() {
                let px = clamped(image, 4 * bx + t % 4, 4 * by + t / 4);
                *texel = [0, 1, 2].map(|c| range.fit(c, px[c]));
            }
            block.copy_from_slice(&encode_signed_block(&texels));
        });
    mirrorball_core::work::add(Encoding::Bc6hSigned.work(16 * (bw * bh) as u64));
}

/// Interpolation weights of 4-bit indices (×1/64).
const WEIGHTS4: [i32; 16] = [0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64];

/// Where a signed half's magnitude `m` lies before the format's final `×31/32`: the centre
/// of the interval of interpolated values that finish as `m`.
fn signed_target(v: f32) -> f32 {
    let bits = f16::from_f32(v).to_bits();
    let m = f32::from((bits & 0x7fff).min(0x7bff));
    let t = (m + 0.5) * 32.0 / 31.0;
    if bits & 0x8000 != 0 {
        -t
    } else {
        t
    }
}

/// A signed 10-bit endpoint's value after unquantization (the specification's
/// `unquantize` for signed formats: 0 stays 0, ±511 and beyond saturate to ±0x7FFF, others
/// `(q·2^15 + 2^14) >> 9`).
fn unquantize10(q: i32) -> i32 {
    let m = q.abs();
    let u = match m {
        0 => 0,
        511.. => 0x7fff,
        _ => ((m << 15) + 0x4000) >> 9,
    };
    if q < 0 {
        -u
    } else {
        u
    }
}

/// The 10-bit signed endpoint whose unquantized value is nearest to `t`.
fn quantize10(t: f32) -> i32 {
    let guess = ((t.abs() - 32.0) / 64.0).floor() as i32;
    let best = [0, guess.clamp(0, 511), (guess + 1).clamp(0, 511)]
        .into_iter()
        .min_by(|&a, &b| {
            let da = (unquantize10(a) as f32 - t.abs()).abs();
            let db = (unquantize10(b) as f32 - t.abs()).abs();
            da.total_cmp(&db)
        })
        .unwrap_or(0);
    if t < 0.0 {
        -best
    } else {
        best
    }
}

/// The nearest endpoint at or below `t` (`up` false) or at or above it (`up` true), so
/// that two endpoints bracket the values between them and the 4-bit weights reach them
/// more finely than the endpoints' own 64-unit steps.
fn quantize10_toward(t: f32, up: bool) -> i32 {
    let q = quantize10(t);
    let u = unquantize10(q) as f32;
    let step = if up && u < t {
        1
    } else if !up && u > t {
        -1
    } else {
        0
    };
    (q + step).clamp(-511, 511)
}

/// The specification's interpolation of two unquantized endpoints.
fn interpolate(a: i32, b: i32, w: i32) -> i32 {
    (a * (64 - w) + b * w + 32) >> 6
}

/// Best index for each texel and the total squared error, for quantized endpoints `q`.
fn assign(q: &[[i32; 3]; 2], targets: &[[f32; 3]; 16]) -> ([u8; 16], f32) {
    let a = q[0].map(unquantize10);
    let b = q[1].map(unquantize10);
    let palette: [[f32; 3]; 16] =
        WEIGHTS4.map(|w| [0, 1, 2].map(|c| interpolate(a[c], b[c], w) as f32));
    let mut idx = [0u8; 16];
    let mut total = 0.0;
    for (i, t) in targets.iter().enumerate() {
        let mut best = (f32::INFINITY, 0u8);
        for (k, p) in palette.iter().enumerate() {
            let e = (p[0] - t[0]).powi(2) + (p[1] - t[1]).powi(2) + (p[2] - t[2]).powi(2);
            if e < best.0 {
                best = (e, k as u8);
            }
        }
        idx[i] = best.1;
        total += best.0;
    }
    (idx, total)
}

/// One signed BC6H block (mode 11) for 16 linear RGB texels in raster order.
pub fn encode_signed_block(texels: &[[f32; 3]; 16]) -> [u8; 16] {
    let targets = texels.map(|t| t.map(signed_target));
    // Principal axis of the targets by power iteration on their covariance.
    let mean = [0, 1, 2].map(|c| targets.iter().map(|t| t[c]).sum::<f32>() / 16.0);
    let mut cov = [[0f32; 3]; 3];
    for t in &targets {
        let d = [0, 1, 2].map(|c| t[c] - mean[c]);
        for (i, row) in cov.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v += d[i] * d[j];
            }
        }
    }
    let mut axis = [1f32, 1.0, 1.0];
    for _ in 0..8 {
        let next = [0, 1, 2].map(|i| (0..3).map(|j| cov[i][j] * axis[j]).sum::<f32>());
        let len = next.iter().map(|v| v * v).sum::<f32>().sqrt();
        if len == 0.0 {
            break;
        }
        axis = next.map(|v| v / len);
    }
    let proj = |t: &[f32; 3]| (0..3).map(|c| (t[c] - mean[c]) * axis[c]).sum::<f32>();
    let (lo, hi) = targets
        .iter()
        .map(proj)
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p), hi.max(p))
        });
    let lo_end = [0, 1, 2].map(|c| mean[c] + lo * axis[c]);
    let hi_end = [0, 1, 2].map(|c| mean[c] + hi * axis[c]);
    // Two candidates: each endpoint rounded to the nearest, or rounded outwards so the pair
    // brackets the block's colours in every channel.
    let nearest = [lo_end.map(quantize10), hi_end.map(quantize10)];
    let outward = [
        [0, 1, 2].map(|c| quantize10_toward(lo_end[c], lo_end[c] > hi_end[c])),
        [0, 1, 2].map(|c| quantize10_toward(hi_end[c], hi_end[c] >= lo_end[c])),
    ];
    let (mut q, (mut idx, mut err)) = [nearest, outward]
        .into_iter()
        .map(|q| (q, assign(&q, &targets)))
        .min_by(|a, b| a.1 .1.total_cmp(&b.1 .1))
        .expect("two candidates");

    // Least-squares endpoints for the chosen weights, requantized, kept while better.
    for _ in 0..3 {
        let (mut aa, mut ab, mut bb) = (0f32, 0f32, 0f32);
        let mut ax = [0f32; 3];
        let mut bx = [0f32; 3];
        for (i, t) in targets.iter().enumerate() {
            let w = WEIGHTS4[idx[i] as usize] as f32 / 64.0;
            let (wa, wb) = (1.0 - w, w);
            aa += wa * wa;
            ab += wa * wb;
            bb += wb * wb;
            for c in 0..3 {
                ax[c] += wa * t[c];
                bx[c] += wb * t[c];
            }
        }
        let det = aa * bb - ab * ab;
        if det.abs() < 1e-6 {
            break;
        }
        let trial = [
            [0, 1, 2].map(|c| quantize10((bb * ax[c] - ab * bx[c]) / det)),
            [0, 1, 2].map(|c| quantize10((aa * bx[c] - ab * ax[c]) / det)),
        ];
        let (i2, e2) = assign(&trial, &targets);
        if e2 >= err {
            break;
        }
        (q, idx, err) = (trial, i2, e2);
    }

    // The anchor (texel 0) index is stored with its top bit implied 0.
    if idx[0] >= 8 {
        q.swap(0, 1);
        idx = idx.map(|i| 15 - i);
    }
    let mut bits: u128 = 0b00011; // mode 11
    let mut at = 5;
    let mut put = |v: u128, n: u32| {
        bits |= (v & ((1 << n) - 1)) << at;
        at += n;
    };
    for end in &q {
        for &c in end {
            put(c as u32 as u128 & 0x3ff, 10);
        }
    }
    for (i, &k) in idx.iter().enumerate() {
        put(u128::from(k), if i == 0 { 3 } else { 4 });
    }
    bits.to_le_bytes()
}

/// Decodes BC6H blocks (row-major) of a `width`×`height` image into interleaved RGB `f32`s,
/// the padding dropped.
pub fn decode(bytes: &[u8], width: u32, height: u32, signed: bool) -> Vec<f32> {
    let (w, h) = (width as usize, height as usize);
    let (bw, _) = blocks(width, height);
    let mut out = vec![0f32; w * h * 3];
    let mut texels = [0f32; 48];
    for (i, block) in bytes.chunks_exact(BLOCK_BYTES).enumerate() {
        let (bx, by) = (i % bw, i / bw);
        bcdec_rs::bc6h_float(block, &mut texels, 12, signed);
        for y in 0..4.min(h.saturating_sub(4 * by)) {
            for x in 0..4.min(w - 4 * bx) {
                let o = ((4 * by + y) * w + 4 * bx + x) * 3;
                out[o..o + 3].copy_from_slice(&texels[(y * 4 + x) * 3..(y * 4 + x) * 3 + 3]);
            }
        }
    }
    out
}
