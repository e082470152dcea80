//! Cubes in every texel encoding (KTX2 with and without Zstandard, DDS, KTX1): each file is
//! checked against its specification by a parser written here (for KTX2, the checks
//! KTX-Software's `ktx validate` makes), decoded level by level within the encoding's
//! error, and read back by mirrorball's readers; bad requests are refused before any work.

use ddsfile::{Caps2, Dds, DxgiFormat, MiscFlag};
use mirrorball_core::{Choice, Image, ProjectionKind};
use mirrorball_io::{
    filament_sh_text, read, write_dds, write_ktx1, write_ktx2, CubeWrite, Encoding, Fault, Limits,
};
use std::path::Path;

/// A smooth cube with the full chain below `size`: values 0.05 … 30 (and, when `signed`,
/// negative blue on face 3), different per face and level.
fn cube(size: u32, signed: bool) -> Vec<Vec<Image>> {
    crate::cube::chain(size, 3, |face, level, x, y, s| {
        let (u, v) = ((x as f32 + 0.5) / s as f32, (y as f32 + 0.5) / s as f32);
        // One colour per face and level scaled by a brightness: BC6H fits a colour line
        // per block, so its error stays small.
        let lum = 0.05 + 30.0 * u * v * v;
        let b = lum * (0.3 + 0.02 * level as f32);
        [
            lum,
            lum * (0.6 + 0.05 * face as f32),
            if signed && face == 3 { -b } else { b },
        ]
    })
}

/// The largest error allowed in one decoded channel `got` of a texel `want` (RGB), per
/// encoding; BC6H is judged by log-PSNR instead (`None`).
fn tolerance(e: Encoding, want: &[f32], c: usize) -> Option<f32> {
    let max = want[0].max(want[1]).max(want[2]);
    let v = want[c].abs();
    Some(match e {
        Encoding::Rgba32F => 0.0,
        Encoding::Rgba16F => v * 2f32.powi(-11),
        // Half a step of the shared scale, at most 2^-10 of the largest channel (×2 slack
        // for the scale's rounding).
        Encoding::Rgb9E5 => max * 2f32.powi(-9),
        Encoding::B10G11R11 => v * 2f32.powi(-6),
        // 8 bits after a 2.2 gamma: 2.2·½/byte of the channel's value, bytes ≥ 40 here
        // (the weakest channel is 0.3 of the largest, whose byte is ≥ 160).
        Encoding::Rgbd => v * 2.2 * 0.5 / 40.0 + 1e-6,
        // Half a byte of M·range.
        Encoding::Rgbm => 6.0 * 0.5 / 255.0 + max.min(6.0) * 0.5 / 255.0,
        Encoding::Bc6hUnsigned | Encoding::Bc6hSigned => return None,
    })
}

/// What an encoding keeps of a value it cannot hold: RGBM stops at its range.
fn held(e: Encoding, v: f32) -> f32 {
    match e {
        Encoding::Rgbm => v.min(6.0),
        _ => v,
    }
}

/// Log-domain PSNR over RGB, sign kept, peak the largest log value.
fn log_psnr(a: &[f32], b: &[f32]) -> f64 {
    let l = |v: f32| f64::from(1.0 + v.abs()).log2() * f64::from(v.signum());
    let (mut se, mut peak) = (0.0, 0.0f64);
    for (x, y) in a.iter().zip(b) {
        peak = peak.max(l(*x).abs());
        se += (l(*x) - l(*y)).powi(2);
    }
    if se == 0.0 {
        return f64::INFINITY;
    }
    10.0 * (peak * peak / (se / a.len() as f64)).log10()
}

/// Checks a decoded face against its source.
fn check_face(e: Encoding, src: &Image, got: &Image, what: &str) {
    assert_eq!(
        (got.width(), got.height()),
        (src.width(), src.height()),
        "{what}"
    );
    let rgb: Vec<f32> = got
        .data()
        .chunks_exact(got.channels())
        .flat_map(|px| [px[0], px[1], px[2]])
        .collect();
    if e.is_block_compressed() {
        let p = log_psnr(src.data(), &rgb);
        // A loose floor: these small synthetic faces change fast; the bundled maps set the
        // real floors (quality.rs).
        assert!(p >= 30.0, "{what}: log-PSNR {p:.1} dB");
        return;
    }
    for (px, want) in rgb.chunks_exact(3).zip(src.data().chunks_exact(3)) {
        for c in 0..3 {
            let tol = tolerance(e, want, c).unwrap();
            let w = held(e, want[c]);
            assert!(
                (px[c] - w).abs() <= tol,
                "{what}: {} vs {w} (±{tol})",
                px[c]
            );
        }
    }
}

// ---------------------------------------------------------------------------------------
// KTX 2.0, checked as `ktx validate` checks it.

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}
fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap())
}

/// One expected DFD sample: bitOffset, bitLength, channelType, qualifiers (linear 0x1,
/// exponent 0x2, signed 0x4, float 0x8 of the top nibble), sampleLower, sampleUpper.
type Want = (u32, u32, u32, u32, u32, u32);

const F1: u32 = 0x3F80_0000; // 1.0f
const FM1: u32 = 0xBF80_0000; // -1.0f

/// What the Khronos Data Format Specification 1.3 (§5, §13 "Float formats", §19
/// "Compressed texture formats: BC6H") and the Vulkan format table say each vkFormat's
/// descriptor holds: vkFormat, typeSize, colour model, texel block dimensions (minus one),
/// bytes of a block, samples.
struct Expect {
    vk: u32,
    type_size: u32,
    model: u8,
    dims: [u8; 4],
    block: u8,
    samples: Vec<Want>,
}

fn expect(e: Encoding) -> Expect {
    let (sf, uf, ex) = (0xC, 0x8, 0x2);
    match e {
        Encoding::Rgba16F => Expect {
            vk: 97, // VK_FORMAT_R16G16B16A16_SFLOAT
            type_size: 2,
            model: 1,
            dims: [0; 4],
            block: 8,
            samples: vec![
                (0, 16, 0, sf, FM1, F1),
                (16, 16, 1, sf, FM1, F1),
                (32, 16, 2, sf, FM1, F1),
                (48, 16, 15, sf, FM1, F1),
            ],
        },
        Encoding::Rgba32F => Expect {
            vk: 109, // VK_FORMAT_R32G32B32A32_SFLOAT
            type_size: 4,
            model: 1,
            dims: [0; 4],
            block: 16,
            samples: vec![
                (0, 32, 0, sf, FM1, F1),
                (32, 32, 1, sf, FM1, F1),
                (64, 32, 2, sf, FM1, F1),
                (96, 32, 15, sf, FM1, F1),
            ],
        },
        Encoding::Rgb9E5 => Expect {
            vk: 123, // VK_FORMAT_E5B9G9R9_UFLOAT_PACK32
            type_size: 4,
            model: 1,
            dims: [0; 4],
            block: 4,
            samples: vec![
                (0, 9, 0, 0, 0, 8448),
                (27, 5, 0, ex, 15, 31),
                (9, 9, 1, 0, 0, 8448),
                (27, 5, 1, ex, 15, 31),
                (18, 9, 2, 0, 0, 8448),
                (27, 5, 2, ex, 15, 31),
            ],
        },
        Encoding::B10G11R11 => Expect {
            vk: 122, // VK_FORMAT_B10G11R11_UFLOAT_PACK32
            type_size: 4,
            model: 1,
            dims: [0; 4],
            block: 4,
            samples: vec![
                (0, 11, 0, uf, 0, F1),
                (11, 11, 1, uf, 0, F1),
                (22, 10, 2, uf, 0, F1),
            ],
        },
        Encoding::Rgbd | Encoding::Rgbm => Expect {
            vk: 37, // VK_FORMAT_R8G8B8A8_UNORM
            type_size: 1,
            model: 1,
            dims: [0; 4],
            block: 4,
            samples: vec![
                (0, 8, 0, 0, 0, 255),
                (8, 8, 1, 0, 0, 255),
                (16, 8, 2, 0, 0, 255),
                (24, 8, 15, 0, 0, 255),
            ],
        },
        Encoding::Bc6hUnsigned => Expect {
            vk: 143, // VK_FORMAT_BC6H_UFLOAT_BLOCK
            type_size: 1,
            model: 133, // KHR_DF_MODEL_BC6H
            dims: [3, 3, 0, 0],
            block: 16,
            samples: vec![(0, 128, 0, uf, 0, F1)],
        },
        Encoding::Bc6hSigned => Expect {
            vk: 144, // VK_FORMAT_BC6H_SFLOAT_BLOCK
            type_size: 1,
            model: 133,
            dims: [3, 3, 0, 0],
            block: 16,
            samples: vec![(0, 128, 0, sf, FM1, F1)],
        },
    }
}

/// Bytes of one `s`×`s` face: whole blocks.
fn face_bytes(x: &Expect, s: u32) -> u64 {
    let bw = u64::from(x.dims[0]) + 1;
    u64::from(s).div_ceil(bw).pow(2) * u64::from(x.block)
}

/// The KTX 2.0 specification's rules, as `ktx validate` applies them, for a cube of
/// `encoding`: returns every level's uncompressed bytes (level 0 first).
fn validate_ktx2(bytes: &[u8], encoding: Encoding) -> Vec<Vec<u8>> {
    let x = expect(encoding);
    assert_eq!(
        &bytes[..12],
        &[0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A]
    );
    let h = |i: usize| u32_at(bytes, 12 + 4 * i);
    let (vk, type_size, w, hgt, depth, layers, faces, levels, scheme) =
        (h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8));
    assert_eq!(vk, x.vk, "vkFormat");
    assert_eq!(type_size, x.type_size, "typeSize (3005/3012)");
    assert!(w > 0 && w == hgt, "cube faces square (3008)");
    assert_eq!(
        (depth, layers, faces),
        (0, 0, 6),
        "a cube, not 3D or an array (3013/3015)"
    );
    assert!(
        levels >= 1 && levels <= 32 - w.leading_zeros(),
        "levelCount (3016/3017)"
    );
    assert!(scheme == 0 || scheme == 2, "NONE or ZSTD (3019)");
    let zstd = scheme == 2;
    let (dfd_off, dfd_len, kvd_off, kvd_len) = (h(9), h(10), h(11), h(12));
    let (sgd_off, sgd_len) = (u64_at(bytes, 64), u64_at(bytes, 72));
    assert_eq!(
        dfd_off as usize,
        80 + 24 * levels as usize,
        "DFD right after the index (3021)"
    );
    assert_eq!(kvd_off, dfd_off + dfd_len, "KVD right after the DFD (3022)");
    assert!(kvd_len > 0 && kvd_off % 4 == 0);
    assert_eq!(
        (sgd_off, sgd_len),
        (0, 0),
        "no supercompression global data (3025/3027)"
    );

    // Data Format Descriptor.
    let d = &bytes[dfd_off as usize..(dfd_off + dfd_len) as usize];
    assert_eq!(u32_at(d, 0), dfd_len, "dfdTotalSize = dfdByteLength (6001)");
    assert_eq!(u32_at(d, 4), 0, "Khronos vendor, basic descriptor type");
    let version = u32_at(d, 8);
    assert_eq!(version & 0xffff, 2, "descriptor version 1.3");
    assert_eq!(
        version >> 16,
        24 + 16 * x.samples.len() as u32,
        "descriptorBlockSize"
    );
    assert_eq!(dfd_len, 4 + 24 + 16 * x.samples.len() as u32);
    assert_eq!(d[12], x.model, "colorModel");
    assert_eq!(d[13], 1, "BT.709 primaries");
    assert_eq!(d[14], 1, "linear transfer");
    assert_eq!(d[15], 0, "straight alpha");
    assert_eq!(d[16..20], x.dims, "texelBlockDimension");
    // KTX 2.0.4 keeps the pre-deflation bytesPlanes when supercompressed (6030 warns on 0).
    let mut planes = [0u8; 8];
    planes[0] = x.block;
    assert_eq!(
        d[20..28],
        planes,
        "bytesPlane (6022; 6030 when supercompressed)"
    );
    for (i, want) in x.samples.iter().enumerate() {
        let s = &d[28 + 16 * i..44 + 16 * i];
        let word = u32_at(s, 0);
        let got = (
            word & 0xffff,
            ((word >> 16) & 0xff) + 1,
            (word >> 24) & 0xf,
            word >> 28,
            u32_at(s, 8),
            u32_at(s, 12),
        );
        assert_eq!(got, *want, "sample {i} of {encoding} (6xxx FormatMismatch)");
        assert_eq!(u32_at(s, 4), 0, "samplePosition");
    }

    // Key/value data: sorted, NUL-terminated keys, padded, KTXorientation and KTXwriter.
    let kvd = &bytes[kvd_off as usize..(kvd_off + kvd_len) as usize];
    let mut at = 0;
    let mut keys = Vec::new();
    while at < kvd.len() {
        let len = u32_at(kvd, at) as usize;
        let entry = &kvd[at + 4..at + 4 + len];
        let nul = entry
            .iter()
            .position(|&b| b == 0)
            .expect("key NUL-terminated");
        let key = std::str::from_utf8(&entry[..nul])
            .expect("UTF-8 key")
            .to_string();
        let value = &entry[nul + 1..];
        if key.starts_with("KTX") || key.starts_with("mirrorball") {
            assert_eq!(value.last(), Some(&0), "{key}'s value NUL-terminated");
        }
        if key == "KTXorientation" {
            assert_eq!(value, b"rd\0");
        }
        if key == "KTXwriter" {
            assert!(value.len() > 1);
        }
        keys.push(key);
        let next = (at + 4 + len).next_multiple_of(4);
        assert!(
            kvd[at + 4 + len..next].iter().all(|&b| b == 0),
            "valuePadding zero"
        );
        at = next;
    }
    assert_eq!(at, kvd.len(), "kvdByteLength covers the entries exactly");
    assert!(
        keys.windows(2).all(|k| k[0] < k[1]),
        "keys sorted: {keys:?}"
    );
    assert!(keys.iter().any(|k| k == "KTXorientation") && keys.iter().any(|k| k == "KTXwriter"));

    // Level index: largest first in the index, smallest first in the file, each at its
    // expected, aligned offset, with the expected lengths.
    let lcm = |a: u64, b: u64| a * b / gcd(a, b);
    let align = if zstd { 1 } else { lcm(u64::from(x.block), 4) };
    let index: Vec<(u64, u64, u64)> = (0..levels as usize)
        .map(|p| {
            let at = 80 + 24 * p;
            (
                u64_at(bytes, at),
                u64_at(bytes, at + 8),
                u64_at(bytes, at + 16),
            )
        })
        .collect();
    let mut cursor = u64::from(kvd_off + kvd_len);
    for p in (0..levels as usize).rev() {
        let (offset, len, raw) = index[p];
        let s = (w >> p).max(1);
        assert_eq!(
            raw,
            6 * face_bytes(&x, s),
            "level {p} uncompressedByteLength (4006)"
        );
        if !zstd {
            assert_eq!(len, raw, "level {p} byteLength (4005)");
        }
        assert!(len > 0);
        let want = cursor.div_ceil(align) * align;
        assert_eq!(offset, want, "level {p} byteOffset (4003/4004)");
        assert_eq!(offset % align, 0);
        assert!(
            bytes[cursor as usize..offset as usize]
                .iter()
                .all(|&b| b == 0),
            "mipPadding"
        );
        cursor = offset + len;
    }
    assert_eq!(cursor, bytes.len() as u64, "nothing after level 0");
    for p in 1..levels as usize {
        assert!(index[p - 1].2 >= index[p].2, "index order (4001)");
        assert!(index[p - 1].0 > index[p].0, "file order (4002)");
    }
    index
        .iter()
        .map(|&(offset, len, raw)| {
            let data = &bytes[offset as usize..(offset + len) as usize];
            if zstd {
                let out = zstd::bulk::decompress(data, raw as usize).expect("valid Zstandard");
                assert_eq!(
                    out.len() as u64,
                    raw,
                    "inflates to uncompressedByteLength (4008)"
                );
                out
            } else {
                data.to_vec()
            }
        })
        .collect()
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// Splits a level into its six faces and checks each against the source.
fn check_level(e: Encoding, data: &[u8], src: &[Image], what: &str) {
    let s = src[0].width();
    let n = e.image_bytes(s, s);
    assert_eq!(data.len(), 6 * n, "{what}");
    for (f, face) in data.chunks_exact(n).enumerate() {
        check_face(
            e,
            &src[f],
            &e.decode(face, s, s),
            &format!("{what} face {f}"),
        );
    }
}

#[test]
fn ktx2_every_encoding_passes_the_validator_rules_and_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    for e in Encoding::all() {
        let signed = e == Encoding::Bc6hSigned;
        for size in [16u32, 6] {
            let levels = cube(size, signed);
            for zstd in [None, Some(3), Some(19)] {
                let what = format!("{e} {size}² zstd {zstd:?}");
                let path = dir.path().join(format!("{e}-{size}-{zstd:?}.ktx2"));
                let how = CubeWrite {
                    encoding: e,
                    zstd,
                    ..CubeWrite::default()
                };
                write_ktx2(&path, &levels, &how).unwrap();
                let bytes = std::fs::read(&path).unwrap();
                let decoded = validate_ktx2(&bytes, e);
                assert_eq!(decoded.len(), levels.len());
                for (p, data) in decoded.iter().enumerate() {
                    check_level(e, data, &levels[p], &format!("{what} level {p}"));
                }
                // mirrorball's reader: level 0, decoded the same way.
                let loaded = read(&path, &Limits::default()).unwrap();
                assert_eq!(loaded.declared, Some(ProjectionKind::Cube));
                let n = e.image_bytes(size, size);
                for (f, layer) in loaded.layers.iter().enumerate() {
                    let want = e.decode(&decoded[0][f * n..(f + 1) * n], size, size);
                    assert_eq!(layer.data(), want.data(), "{what} face {f} as read");
                }
                // The independent `ktx2` crate parses it too.
                let reader = ktx2::Reader::new(&bytes[..]).expect(&what);
                assert_eq!(reader.header().level_count as usize, levels.len());
            }
        }
    }
}

#[test]
fn ktx2_default_write_is_the_rgba16f_encoding() {
    let dir = tempfile::tempdir().unwrap();
    let levels = cube(8, false);
    let a = dir.path().join("a.ktx2");
    let b = dir.path().join("b.ktx2");
    mirrorball_io::write_cube(&a, &levels, &Default::default()).unwrap();
    write_ktx2(&b, &levels, &CubeWrite::default()).unwrap();
    assert_eq!(std::fs::read(a).unwrap(), std::fs::read(b).unwrap());
}

// ---------------------------------------------------------------------------------------
// DDS.

#[test]
fn dds_every_dxgi_encoding_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    for (e, dxgi) in [
        (Encoding::Rgba16F, DxgiFormat::R16G16B16A16_Float),
        (Encoding::Rgba32F, DxgiFormat::R32G32B32A32_Float),
        (Encoding::Rgb9E5, DxgiFormat::R9G9B9E5_SharedExp),
        (Encoding::B10G11R11, DxgiFormat::R11G11B10_Float),
        (Encoding::Bc6hUnsigned, DxgiFormat::BC6H_UF16),
        (Encoding::Bc6hSigned, DxgiFormat::BC6H_SF16),
    ] {
        let size = 16;
        let levels = cube(size, e == Encoding::Bc6hSigned);
        let path = dir.path().join(format!("{e}.dds"));
        let how = CubeWrite {
            encoding: e,
            ..CubeWrite::default()
        };
        write_dds(&path, &levels, &how).unwrap();
        // ddsfile parses the headers: DX10, the format, a cube of one element, all faces.
        let dds = Dds::read(std::fs::File::open(&path).unwrap()).unwrap();
        let h10 = dds.header10.as_ref().expect("DX10 header");
        assert_eq!(h10.dxgi_format, dxgi, "{e}");
        assert!(h10.misc_flag.contains(MiscFlag::TEXTURECUBE));
        assert_eq!(h10.array_size, 1);
        assert!(dds
            .header
            .caps2
            .contains(Caps2::CUBEMAP | Caps2::CUBEMAP_ALLFACES));
        assert_eq!(dds.header.mip_map_count, Some(levels.len() as u32));
        if e.is_block_compressed() {
            // DDSD_LINEARSIZE: level 0's bytes, whole blocks.
            assert_eq!(
                dds.header.linear_size,
                Some(e.image_bytes(size, size) as u32)
            );
        }
        // Face-major data: each face with its whole chain.
        let chain: usize = (0..levels.len())
            .map(|p| e.image_bytes((size >> p).max(1), (size >> p).max(1)))
            .sum();
        assert_eq!(dds.data.len(), 6 * chain, "{e}");
        for f in 0..6 {
            let mut at = f * chain;
            for (p, level) in levels.iter().enumerate() {
                let s = (size >> p).max(1);
                let n = e.image_bytes(s, s);
                let got = e.decode(&dds.data[at..at + n], s, s);
                check_face(e, &level[f], &got, &format!("{e} face {f} level {p}"));
                at += n;
            }
        }
        let loaded = read(&path, &Limits::default()).unwrap();
        assert_eq!(loaded.layers.len(), 6);
        let n0 = e.image_bytes(size, size);
        for (f, layer) in loaded.layers.iter().enumerate() {
            let want = e.decode(&dds.data[f * chain..f * chain + n0], size, size);
            assert_eq!(layer.data(), want.data(), "{e} face {f} as read");
        }
    }
}

// ---------------------------------------------------------------------------------------
// KTX 1.1 for Filament, parsed here from the specification.

#[test]
fn ktx1_follows_the_specification_and_filament() {
    let dir = tempfile::tempdir().unwrap();
    let sh: Vec<[f32; 3]> = (0..9).map(|i| [i as f32 * 0.1, -0.25, 1.5e-3]).collect();
    for (e, gl) in [
        // glType, glTypeSize, glFormat, glInternalFormat, glBaseInternalFormat
        (Encoding::B10G11R11, [0x8C3A, 4, 0x1907, 0x8C3A, 0x1907]),
        (Encoding::Rgba16F, [0x140B, 2, 0x1908, 0x881A, 0x1908]),
        (Encoding::Rgba32F, [0x1406, 4, 0x1908, 0x8814, 0x1908]),
    ] {
        let size = 8;
        let levels = cube(size, false);
        let path = dir.path().join(format!("{e}.ktx"));
        let how = CubeWrite {
            encoding: e,
            metadata: vec![("sh".into(), filament_sh_text(&sh))],
            ..CubeWrite::default()
        };
        write_ktx1(&path, &levels, &how).unwrap();
        let b = std::fs::read(&path).unwrap();
        assert_eq!(
            &b[..12],
            &[0xAB, 0x4B, 0x54, 0x58, 0x20, 0x31, 0x31, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A]
        );
        let h = |i: usize| u32_at(&b, 12 + 4 * i);
        assert_eq!(h(0), 0x0403_0201, "endianness");
        assert_eq!([h(1), h(2), h(3), h(4), h(5)], gl, "{e}");
        assert_eq!((h(6), h(7), h(8), h(9), h(10)), (size, size, 0, 0, 6));
        assert_eq!(h(11) as usize, levels.len());
        let kvd_len = h(12) as usize;
        // Key/value data: one entry, `sh` = nine lines of three numbers.
        let kvd = &b[64..64 + kvd_len];
        let len = u32_at(kvd, 0) as usize;
        let entry = &kvd[4..4 + len];
        assert!(entry.starts_with(b"sh\0"));
        let text = std::str::from_utf8(&entry[3..len - 1]).unwrap();
        assert_eq!(entry[len - 1], 0);
        let parsed: Vec<Vec<f32>> = text
            .lines()
            .map(|l| l.split(' ').map(|v| v.parse().unwrap()).collect())
            .collect();
        assert_eq!(parsed.len(), 9);
        for (p, s) in parsed.iter().zip(&sh) {
            assert_eq!(p.as_slice(), s.as_slice());
        }
        assert_eq!((4 + len).next_multiple_of(4), kvd_len);
        // Levels, largest first: imageSize (one face), six faces, each padded to 4.
        let mut at = 64 + kvd_len;
        for (p, level) in levels.iter().enumerate() {
            let s = (size >> p).max(1);
            let n = e.image_bytes(s, s);
            assert_eq!(u32_at(&b, at) as usize, n, "imageSize of level {p}");
            at += 4;
            for (f, face) in level.iter().enumerate() {
                let got = e.decode(&b[at..at + n], s, s);
                check_face(e, face, &got, &format!("KTX1 {e} level {p} face {f}"));
                at = (at + n).next_multiple_of(4); // cubePadding
            }
            at = at.next_multiple_of(4); // mipPadding
        }
        assert_eq!(at, b.len());
    }
}

// ---------------------------------------------------------------------------------------
// Refusals, before any work and leaving no file.

fn refused(path: &Path, result: Result<(), mirrorball_io::Error>, needle: &str) {
    let err = result.expect_err(needle);
    assert_eq!(err.fault(), Fault::Request, "{err}");
    assert!(err.to_string().contains(needle), "{err}");
    assert!(!path.exists());
}

#[test]
fn impossible_requests_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let signed = cube(8, true);
    let plain = cube(8, false);
    let with = |encoding, zstd| CubeWrite {
        encoding,
        zstd,
        ..CubeWrite::default()
    };
    let p = dir.path().join("neg.ktx2");
    refused(
        &p,
        write_ktx2(&p, &signed, &with(Encoding::Bc6hUnsigned, None)),
        "negative",
    );
    let p = dir.path().join("neg.dds");
    refused(
        &p,
        write_dds(&p, &signed, &with(Encoding::Bc6hUnsigned, None)),
        "negative",
    );
    let p = dir.path().join("rgbd.dds");
    refused(
        &p,
        write_dds(&p, &plain, &with(Encoding::Rgbd, None)),
        "KTX2",
    );
    let p = dir.path().join("z.dds");
    refused(
        &p,
        write_dds(&p, &plain, &with(Encoding::Rgba16F, Some(3))),
        "Zstandard",
    );
    let p = dir.path().join("z.ktx2");
    refused(
        &p,
        write_ktx2(&p, &plain, &with(Encoding::Rgba16F, Some(0))),
        "Zstandard",
    );
    let p = dir.path().join("bc.ktx");
    refused(
        &p,
        write_ktx1(&p, &plain, &with(Encoding::Bc6hUnsigned, None)),
        "Filament",
    );
}
