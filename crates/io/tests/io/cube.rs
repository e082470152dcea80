//! Cube-container tests (KTX2, DDS): files written by mirrorball are read back with the
//! independent `ktx2` and `ddsfile` crates and with mirrorball's own readers; bad requests
//! and bad files give errors of the right fault, never panics.

use ddsfile::{
    AlphaMode, Caps, Caps2, D3D10ResourceDimension, D3DFormat, Dds, DxgiFormat, FourCC, MiscFlag,
    NewD3dParams, NewDxgiParams, PixelFormat, PixelFormatFlags,
};
use half::f16;
use ktx2::dfd::{Basic, Block, ChannelTypeQualifiers};
use mirrorball_core::{Image, ProjectionKind};
use mirrorball_io::{read, write_cube, Fault, Format, Limits, Precision, WriteOptions};
use std::path::Path;

/// A texel unique to (face, level, x, y): R = x + y/3 (not exact in half), G = −y/4,
/// B = 16·face + level, A = 1 + face/2.
fn texel(face: usize, level: usize, x: u32, y: u32) -> [f32; 4] {
    [
        x as f32 + y as f32 / 3.0,
        -(y as f32) * 0.25,
        (face * 16 + level) as f32,
        1.0 + face as f32 * 0.5,
    ]
}

/// A cube of `size`×`size` faces with the full mip chain down to 1×1.
fn make_cube(size: u32, channels: usize) -> Vec<Vec<Image>> {
    chain(size, channels, |face, level, x, y, _| {
        texel(face, level, x, y)
    })
}

/// A cube of `size`×`size` faces with the full mip chain down to 1×1, texel
/// `(x, y)` of `face` at `level` (of edge `s`) being `f(face, level, x, y, s)`.
pub(crate) fn chain<F, const N: usize>(size: u32, channels: usize, f: F) -> Vec<Vec<Image>>
where
    F: Fn(usize, usize, u32, u32, u32) -> [f32; N],
{
    let count = 32 - size.leading_zeros() as usize;
    (0..count)
        .map(|level| {
            let s = (size >> level).max(1);
            (0..6)
                .map(|face| {
                    let mut img = Image::new(s, s, channels);
                    for y in 0..s {
                        for x in 0..s {
                            img.set(x, y, &f(face, level, x, y, s));
                        }
                    }
                    img
                })
                .collect()
        })
        .collect()
}

/// What a face reads back as: RGBA, alpha 1 for RGB input, rounded to half if `half`.
fn expected(face: &Image, half: bool) -> Vec<f32> {
    let rgba = face.with_channels(4);
    rgba.data()
        .iter()
        .map(|&v| if half { f16::from_f32(v).to_f32() } else { v })
        .collect()
}

fn decode(bytes: &[u8], half: bool) -> Vec<f32> {
    if half {
        bytes
            .chunks_exact(2)
            .map(|b| f16::from_le_bytes([b[0], b[1]]).to_f32())
            .collect()
    } else {
        bytes
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect()
    }
}

fn opts(precision: Option<Precision>) -> WriteOptions {
    WriteOptions {
        precision,
        ..WriteOptions::default()
    }
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap())
}

fn put_u32(bytes: &mut [u8], at: usize, v: u32) {
    bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

/// Checks a KTX2 file written from `levels` with the `ktx2` crate and by its raw layout.
fn check_ktx2(path: &Path, levels: &[Vec<Image>], half: bool) {
    let bytes = std::fs::read(path).unwrap();
    let reader = ktx2::Reader::new(bytes.as_slice()).expect("the ktx2 crate parses the file");
    let header = reader.header();
    let size = levels[0][0].width();
    let n = levels.len();
    let (format, type_size, texel_size) = if half {
        (ktx2::Format::R16G16B16A16_SFLOAT, 2, 8)
    } else {
        (ktx2::Format::R32G32B32A32_SFLOAT, 4, 16)
    };
    assert_eq!(header.format, Some(format));
    assert_eq!(header.format.unwrap().value(), if half { 97 } else { 109 });
    assert_eq!(header.type_size, type_size);
    assert_eq!((header.pixel_width, header.pixel_height), (size, size));
    assert_eq!(header.pixel_depth, 0);
    assert_eq!(header.layer_count, 0);
    assert_eq!(header.face_count, 6);
    assert_eq!(header.level_count as usize, n);
    assert_eq!(header.supercompression_scheme, None);

    // The Data Format Descriptor: one basic block, exactly what the ktx2 crate generates
    // for the format, and byte for byte its serialisation.
    let (want_dfd, want_type_size) = Basic::from_format(format).unwrap();
    assert_eq!(want_type_size, type_size);
    assert_eq!(reader.dfd_blocks().len(), 1);
    let basic = reader.basic_dfd().expect("a basic DFD block");
    assert_eq!(basic, &want_dfd);
    assert_eq!(basic.color_model, Some(ktx2::ColorModel::RGBSDA));
    assert_eq!(basic.color_primaries, Some(ktx2::ColorPrimaries::BT709));
    assert_eq!(
        basic.transfer_function,
        Some(ktx2::TransferFunction::Linear)
    );
    assert_eq!(basic.bytes_planes[0], texel_size as u8);
    let bits = if half { 16 } else { 32 };
    let channels: Vec<u8> = basic
        .sample_information
        .iter()
        .map(|s| s.channel_type)
        .collect();
    assert_eq!(channels, [0, 1, 2, 15]);
    for (i, s) in basic.sample_information.iter().enumerate() {
        assert_eq!(s.bit_offset as usize, i * bits);
        assert_eq!(s.bit_length.get() as usize, bits);
        assert_eq!(
            s.channel_type_qualifiers,
            ChannelTypeQualifiers::SIGNED | ChannelTypeQualifiers::FLOAT
        );
        assert_eq!((s.lower, s.upper), ((-1.0f32).to_bits(), 1.0f32.to_bits()));
    }
    let index = header.index;
    let block = Block::Basic(want_dfd).to_vec();
    let dfd = &bytes[index.dfd_byte_offset as usize..][..index.dfd_byte_length as usize];
    assert_eq!(u32_at(dfd, 0) as usize, 4 + block.len(), "dfdTotalSize");
    assert_eq!(&dfd[4..], &block[..]);

    // Key/value data, sorted by key, right after the DFD.
    let kv: Vec<(&str, &[u8])> = reader.key_value_data().collect();
    assert_eq!(kv.len(), 2);
    assert_eq!(kv[0], ("KTXorientation", &b"rd\0"[..]));
    assert_eq!(kv[1].0, "KTXwriter");
    assert!(reader.writer().unwrap().starts_with("mirrorball "));
    assert!(kv[1].1.ends_with(b"\0"));
    assert_eq!(index.dfd_byte_offset as usize, 80 + 24 * n);
    assert_eq!(
        index.kvd_byte_offset,
        index.dfd_byte_offset + index.dfd_byte_length
    );
    assert_eq!(index.kvd_byte_length % 4, 0);
    assert_eq!((index.sgd_byte_offset, index.sgd_byte_length), (0, 0));

    // Level index: level 0 first; data smallest level first, each on a multiple of
    // lcm(texel size, 4) = texel size, with the least padding, ending at the end of the file.
    let align = |v: u64| v.div_ceil(texel_size) * texel_size;
    let entries: Vec<ktx2::LevelIndex> = (0..n)
        .map(|p| ktx2::LevelIndex::from_bytes(bytes[80 + 24 * p..][..24].try_into().unwrap()))
        .collect();
    let kvd_end = u64::from(index.kvd_byte_offset + index.kvd_byte_length);
    assert_eq!(entries[n - 1].byte_offset, align(kvd_end));
    for (p, e) in entries.iter().enumerate() {
        let s = u64::from((size >> p).max(1));
        assert_eq!(e.byte_length, 6 * s * s * texel_size, "level {p}");
        assert_eq!(e.uncompressed_byte_length, e.byte_length);
        assert_eq!(e.byte_offset % texel_size, 0);
        if p + 1 < n {
            let next = &entries[p + 1];
            assert_eq!(e.byte_offset, align(next.byte_offset + next.byte_length));
        }
    }
    assert_eq!(
        entries[0].byte_offset + entries[0].byte_length,
        bytes.len() as u64
    );

    // The texels: six faces per level in order +X −X +Y −Y +Z −Z, rows as stored.
    assert_eq!(reader.levels().len(), n);
    for (p, level) in reader.levels().enumerate() {
        let face_len = level.data.len() / 6;
        for (f, face) in level.data.chunks_exact(face_len).enumerate() {
            assert_eq!(
                decode(face, half),
                expected(&levels[p][f], half),
                "level {p} face {f}"
            );
        }
    }
}

/// Checks a DDS file written from `levels` with the `ddsfile` crate.
fn check_dds(path: &Path, levels: &[Vec<Image>], half: bool) {
    let dds = Dds::read(std::fs::File::open(path).unwrap()).expect("ddsfile parses the file");
    let size = levels[0][0].width();
    let n = levels.len();
    let (format, texel_size) = if half {
        (DxgiFormat::R16G16B16A16_Float, 8)
    } else {
        (DxgiFormat::R32G32B32A32_Float, 16)
    };
    assert_eq!(dds.header.spf.fourcc, Some(FourCC(FourCC::DX10)));
    assert_eq!(dds.header.spf.flags, PixelFormatFlags::FOURCC);
    assert_eq!(dds.get_dxgi_format(), Some(format));
    let h10 = dds.header10.as_ref().expect("a DX10 header");
    assert_eq!(h10.resource_dimension, D3D10ResourceDimension::Texture2D);
    assert!(h10.misc_flag.contains(MiscFlag::TEXTURECUBE));
    assert_eq!(h10.array_size, 1, "DX10 arraySize counts cubes");
    assert_eq!(dds.get_num_array_layers(), 6);
    assert_eq!((dds.get_width(), dds.get_height()), (size, size));
    assert_eq!(dds.get_num_mipmap_levels() as usize, n);
    assert!(dds
        .header
        .caps2
        .contains(Caps2::CUBEMAP | Caps2::CUBEMAP_ALLFACES));
    assert!(dds.header.caps.contains(Caps::TEXTURE | Caps::COMPLEX));
    assert_eq!(dds.header.caps.contains(Caps::MIPMAP), n > 1);
    assert_eq!(dds.get_pitch(), Some(size * texel_size as u32));

    // Face-major: each face with its whole mip chain.
    let chain: usize = (0..n)
        .map(|p| ((size >> p).max(1) as usize).pow(2) * texel_size)
        .sum();
    assert_eq!(dds.data.len(), 6 * chain);
    for f in 0..6 {
        let data = dds.get_data(f as u32).unwrap();
        assert_eq!(data.len(), chain);
        let mut at = 0;
        for (p, level) in levels.iter().enumerate() {
            let len = ((size >> p).max(1) as usize).pow(2) * texel_size;
            assert_eq!(
                decode(&data[at..at + len], half),
                expected(&level[f], half),
                "face {f} level {p}"
            );
            at += len;
        }
    }
}

/// Reads `path` with mirrorball and compares with level 0 of `levels`.
fn check_own_read(path: &Path, levels: &[Vec<Image>], half: bool, format: Format, name: &str) {
    let loaded = read(path, &Limits::default()).unwrap();
    assert_eq!(loaded.format, format);
    assert_eq!(loaded.declared, Some(ProjectionKind::Cube));
    assert_eq!(loaded.layers.len(), 6);
    for (f, face) in loaded.layers.iter().enumerate() {
        assert_eq!(face.channels(), 4);
        assert_eq!(
            (face.width(), face.height()),
            (levels[0][f].width(), levels[0][f].height())
        );
        assert_eq!(face.data(), &expected(&levels[0][f], half)[..], "face {f}");
    }
    let mips = match levels.len() {
        1 => "1 mip level".to_string(),
        n => format!("{n} mip levels"),
    };
    assert!(loaded.description.contains(name), "{}", loaded.description);
    assert!(loaded.description.contains(&mips), "{}", loaded.description);
    assert!(
        loaded.description.contains("cube map"),
        "{}",
        loaded.description
    );
}

#[test]
fn ktx2_rgba16f_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cube.ktx2");
    let levels = make_cube(16, 4);
    assert_eq!(levels.len(), 5);
    write_cube(&path, &levels, &opts(None)).unwrap();
    check_ktx2(&path, &levels, true);
    check_own_read(&path, &levels, true, Format::Ktx2, "RGBA16F");
    let loaded = read(&path, &Limits::default()).unwrap();
    assert_eq!(loaded.description, "KTX2 cube map, RGBA16F, 5 mip levels");

    // Half is also what Precision::Half asks for.
    let explicit = dir.path().join("half.ktx2");
    write_cube(&explicit, &levels, &opts(Some(Precision::Half))).unwrap();
    assert_eq!(
        std::fs::read(&path).unwrap(),
        std::fs::read(&explicit).unwrap()
    );
}

#[test]
fn ktx2_rgba32f_round_trip_from_rgb() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cube.ktx2");
    let levels = make_cube(16, 3);
    write_cube(&path, &levels, &opts(Some(Precision::Float))).unwrap();
    check_ktx2(&path, &levels, false);
    check_own_read(&path, &levels, false, Format::Ktx2, "RGBA32F");
}

#[test]
fn ktx2_odd_sizes_and_partial_chains() {
    let dir = tempfile::tempdir().unwrap();
    // 12 → 6 → 3 → 1 (rounded down), and a chain cut after two levels; a single level.
    for (size, keep) in [(12, 4), (12, 2), (5, 1)] {
        let mut levels = make_cube(size, 4);
        levels.truncate(keep);
        for precision in [Precision::Half, Precision::Float] {
            let path = dir
                .path()
                .join(format!("c{size}_{keep}_{precision:?}.ktx2"));
            write_cube(&path, &levels, &opts(Some(precision))).unwrap();
            let half = precision == Precision::Half;
            check_ktx2(&path, &levels, half);
            check_own_read(&path, &levels, half, Format::Ktx2, "KTX2");
            let path = path.with_extension("dds");
            write_cube(&path, &levels, &opts(Some(precision))).unwrap();
            check_dds(&path, &levels, half);
            check_own_read(&path, &levels, half, Format::Dds, "DDS");
        }
    }
}

#[test]
fn dds_rgba16f_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cube.dds");
    let levels = make_cube(16, 4);
    write_cube(&path, &levels, &opts(None)).unwrap();
    check_dds(&path, &levels, true);
    check_own_read(&path, &levels, true, Format::Dds, "RGBA16F");
    let loaded = read(&path, &Limits::default()).unwrap();
    assert_eq!(
        loaded.description,
        "DDS cube map (DX10), RGBA16F, 5 mip levels"
    );
}

#[test]
fn dds_rgba32f_round_trip_from_rgb() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cube.dds");
    let levels = make_cube(16, 3);
    write_cube(&path, &levels, &opts(Some(Precision::Float))).unwrap();
    check_dds(&path, &levels, false);
    check_own_read(&path, &levels, false, Format::Dds, "RGBA32F");
}

#[test]
fn bad_requests_are_refused_and_leave_no_file() {
    let good = make_cube(8, 4);
    let mut five_faces = good.clone();
    five_faces[0].pop();
    let mut seven_faces = good.clone();
    let extra = seven_faces[2][0].clone();
    seven_faces[2].push(extra);
    let non_square: Vec<Vec<Image>> = vec![(0..6).map(|_| Image::new(8, 4, 4)).collect()];
    let mut mixed_sizes = good.clone();
    mixed_sizes[0][3] = Image::new(4, 4, 4);
    let mut bad_mip = good.clone();
    bad_mip[1] = (0..6).map(|_| Image::new(3, 3, 4)).collect();
    let mut too_many = good.clone();
    too_many.push(too_many.last().unwrap().clone());
    let empty: Vec<Vec<Image>> = Vec::new();

    let cases: Vec<(&str, &[Vec<Image>], WriteOptions)> = vec![
        ("five faces", &five_faces[..], opts(None)),
        ("seven faces", &seven_faces[..], opts(None)),
        ("non-square", &non_square[..], opts(None)),
        ("mixed face sizes", &mixed_sizes[..], opts(None)),
        ("inconsistent mip", &bad_mip[..], opts(None)),
        ("too many mips", &too_many[..], opts(None)),
        ("no levels", &empty[..], opts(None)),
        ("precision U8", &good[..], opts(Some(Precision::U8))),
        ("precision U16", &good[..], opts(Some(Precision::U16))),
    ];
    let dir = tempfile::tempdir().unwrap();
    for ext in ["ktx2", "dds"] {
        for (what, levels, o) in &cases {
            let path = dir.path().join(format!("out.{ext}"));
            let err = write_cube(&path, levels, o).expect_err(what);
            assert_eq!(err.fault(), Fault::Request, "{ext} {what}: {err}");
            assert_eq!(err.path(), path);
            assert_eq!(
                std::fs::read_dir(dir.path()).unwrap().count(),
                0,
                "{ext} {what}"
            );
        }
    }
}

/// Prefixes of a valid file (every length through the headers, then a stride through the
/// texels, and the last bytes) are refused as the input's fault, without panicking.
fn check_truncations(path: &Path) {
    let bytes = std::fs::read(path).unwrap();
    let cut = path.with_file_name(format!(
        "cut.{}",
        path.extension().unwrap().to_str().unwrap()
    ));
    let n = bytes.len();
    let lengths = (0..n.min(512))
        .chain((512..n).step_by(7))
        .chain(n.saturating_sub(8)..n);
    for len in lengths {
        std::fs::write(&cut, &bytes[..len]).unwrap();
        let err = read(&cut, &Limits::default()).expect_err("a truncated file is refused");
        assert_eq!(err.fault(), Fault::Input, "cut at {len}: {err}");
    }
}

#[test]
fn truncated_files_are_input_errors() {
    let dir = tempfile::tempdir().unwrap();
    let levels = make_cube(8, 4);
    for ext in ["ktx2", "dds"] {
        for precision in [Precision::Half, Precision::Float] {
            let path = dir.path().join(format!("cube.{ext}"));
            write_cube(&path, &levels, &opts(Some(precision))).unwrap();
            check_truncations(&path);
        }
    }
}

/// Reads `bytes` saved as `name`, expecting an input error; returns its message.
fn input_error(dir: &Path, name: &str, bytes: &[u8], limits: &Limits) -> String {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    let err = read(&path, limits).expect_err(name);
    assert_eq!(err.fault(), Fault::Input, "{name}: {err}");
    err.problem().to_string()
}

#[test]
fn absurd_headers_are_refused_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let levels = make_cube(16, 4);
    let ktx = dir.path().join("cube.ktx2");
    let dds = dir.path().join("cube.dds");
    write_cube(&ktx, &levels, &opts(None)).unwrap();
    write_cube(&dds, &levels, &opts(None)).unwrap();
    let ktx = std::fs::read(ktx).unwrap();
    let dds = std::fs::read(dds).unwrap();
    let limits = Limits::default();

    // Sizes beyond the limits: 1e12 texels, 9e8 texels, a huge width.
    for (w, h) in [(1 << 20, 1 << 20), (30_000, 30_000), (u32::MAX, u32::MAX)] {
        let mut k = ktx.clone();
        put_u32(&mut k, 20, w);
        put_u32(&mut k, 24, h);
        let msg = input_error(dir.path(), "big.ktx2", &k, &limits);
        assert!(msg.contains("exceeds"), "{msg}");
        let mut d = dds.clone();
        put_u32(&mut d, 12, h);
        put_u32(&mut d, 16, w);
        let msg = input_error(dir.path(), "big.dds", &d, &limits);
        assert!(msg.contains("exceeds"), "{msg}");
    }
    // Within the limits but far more than the file holds: 2^28 texels per face.
    let mut k = ktx.clone();
    put_u32(&mut k, 20, 16384);
    put_u32(&mut k, 24, 16384);
    input_error(dir.path(), "large.ktx2", &k, &limits);
    let mut d = dds.clone();
    put_u32(&mut d, 12, 16384);
    put_u32(&mut d, 16, 16384);
    let msg = input_error(dir.path(), "large.dds", &d, &limits);
    assert!(msg.contains("truncated"), "{msg}");

    // Tighter limits refuse the honest 16×16 files.
    let tight = Limits {
        max_texels: 255,
        max_dimension: 65536,
    };
    input_error(dir.path(), "tight.ktx2", &ktx, &tight);
    input_error(dir.path(), "tight.dds", &dds, &tight);
    let narrow = Limits {
        max_texels: 1 << 28,
        max_dimension: 15,
    };
    input_error(dir.path(), "narrow.ktx2", &ktx, &narrow);
    input_error(dir.path(), "narrow.dds", &dds, &narrow);

    // Absurd mip counts, level lengths and offsets.
    let mut k = ktx.clone();
    put_u32(&mut k, 40, 1000);
    input_error(dir.path(), "mips.ktx2", &k, &limits);
    let mut d = dds.clone();
    put_u32(&mut d, 28, 1000);
    input_error(dir.path(), "mips.dds", &d, &limits);
    let mut k = ktx.clone();
    k[88..96].copy_from_slice(&u64::MAX.to_le_bytes()); // levels[0].byteLength
    input_error(dir.path(), "length.ktx2", &k, &limits);
    let mut k = ktx.clone();
    k[80..88].copy_from_slice(&(u64::MAX - 8).to_le_bytes()); // levels[0].byteOffset
    input_error(dir.path(), "offset.ktx2", &k, &limits);
    let mut k = ktx.clone();
    put_u32(&mut k, 60, u32::MAX); // kvdByteLength
    input_error(dir.path(), "kvd.ktx2", &k, &limits);

    // Zstandard supercompression is named in the refusal.
    let mut k = ktx.clone();
    put_u32(&mut k, 44, 2);
    let msg = input_error(dir.path(), "zstd.ktx2", &k, &limits);
    assert!(msg.contains("Zstandard"), "{msg}");

    // Unsupported formats and other shapes.
    let mut k = ktx.clone();
    put_u32(&mut k, 12, 37); // VK_FORMAT_R8G8B8A8_UNORM
    input_error(dir.path(), "unorm.ktx2", &k, &limits);
    let mut k = ktx.clone();
    put_u32(&mut k, 36, 3); // faceCount 3
    input_error(dir.path(), "faces.ktx2", &k, &limits);
    let mut k = ktx.clone();
    put_u32(&mut k, 32, 2); // layerCount 2
    input_error(dir.path(), "array.ktx2", &k, &limits);
    let mut d = dds.clone();
    put_u32(&mut d, 128, 28); // DXGI_FORMAT_R8G8B8A8_UNORM
    input_error(dir.path(), "unorm.dds", &d, &limits);
    let mut d = dds.clone();
    put_u32(&mut d, 128 + 12, 2); // two cubes
    input_error(dir.path(), "array.dds", &d, &limits);
    let mut d = dds.clone();
    d[0] = b'X';
    input_error(dir.path(), "magic.dds", &d, &limits);
    let mut k = ktx.clone();
    k[5] = b'1';
    input_error(dir.path(), "magic.ktx2", &k, &limits);
}

/// A KTX2 2D texture (faceCount 1) built here from the specification, with the DFD from the
/// `ktx2` crate and orientation `ru` (bottom row first).
#[test]
fn ktx2_2d_texture_reads_as_flat_image() {
    let (w, h) = (5u32, 3u32);
    let format = ktx2::Format::R32G32B32A32_SFLOAT;
    let (basic, type_size) = Basic::from_format(format).unwrap();
    let block = Block::Basic(basic).to_vec();
    let mut dfd = ((4 + block.len()) as u32).to_le_bytes().to_vec();
    dfd.extend_from_slice(&block);
    let mut kvd = Vec::new();
    let kv = b"KTXorientation\0ru\0";
    kvd.extend_from_slice(&(kv.len() as u32).to_le_bytes());
    kvd.extend_from_slice(kv);
    kvd.resize(kvd.len().next_multiple_of(4), 0);

    let dfd_offset = 80 + 24;
    let kvd_offset = dfd_offset + dfd.len();
    let data_offset = (kvd_offset + kvd.len()).next_multiple_of(16);
    // Stored bottom row first: file row r is picture row h − 1 − r.
    let mut data = Vec::new();
    for r in 0..h {
        for x in 0..w {
            for v in texel(0, 0, x, h - 1 - r) {
                data.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    let mut file = vec![
        0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A,
    ];
    for v in [format.value(), type_size, w, h, 0, 0, 1, 1, 0] {
        file.extend_from_slice(&v.to_le_bytes());
    }
    for v in [dfd_offset, dfd.len(), kvd_offset, kvd.len()] {
        file.extend_from_slice(&(v as u32).to_le_bytes());
    }
    file.extend_from_slice(&[0; 16]);
    for v in [data_offset, data.len(), data.len()] {
        file.extend_from_slice(&(v as u64).to_le_bytes());
    }
    file.extend_from_slice(&dfd);
    file.extend_from_slice(&kvd);
    file.resize(data_offset, 0);
    file.extend_from_slice(&data);
    ktx2::Reader::new(file.as_slice()).expect("the test file is valid KTX2");

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("flat.ktx2");
    std::fs::write(&path, &file).unwrap();
    let loaded = read(&path, &Limits::default()).unwrap();
    assert_eq!(loaded.declared, None);
    assert_eq!(loaded.format, Format::Ktx2);
    assert_eq!(loaded.description, "KTX2 2D texture, RGBA32F, 1 mip level");
    assert_eq!(loaded.layers.len(), 1);
    let img = &loaded.layers[0];
    assert_eq!((img.width(), img.height(), img.channels()), (w, h, 4));
    for y in 0..h {
        for x in 0..w {
            assert_eq!(img.get(x, y), &texel(0, 0, x, y)[..], "({x}, {y})");
        }
    }
}

fn dx10_2d(width: u32, height: u32, format: DxgiFormat) -> Dds {
    Dds::new_dxgi(NewDxgiParams {
        height,
        width,
        depth: None,
        format,
        mipmap_levels: Some(1),
        array_layers: None,
        caps2: None,
        is_cubemap: false,
        resource_dimension: D3D10ResourceDimension::Texture2D,
        alpha_mode: AlphaMode::Unknown,
    })
    .unwrap()
}

fn save_dds(dir: &Path, name: &str, dds: &Dds) -> std::path::PathBuf {
    let path = dir.join(name);
    let mut file = std::fs::File::create(&path).unwrap();
    dds.write(&mut file).unwrap();
    path
}

#[test]
fn dds_2d_textures_read_as_flat_images() {
    let dir = tempfile::tempdir().unwrap();

    // RGBA32F, written by ddsfile.
    let (w, h) = (6u32, 4u32);
    let mut dds = dx10_2d(w, h, DxgiFormat::R32G32B32A32_Float);
    dds.data.clear();
    for y in 0..h {
        for x in 0..w {
            for v in texel(1, 0, x, y) {
                dds.data.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    let path = save_dds(dir.path(), "flat.dds", &dds);
    let loaded = read(&path, &Limits::default()).unwrap();
    assert_eq!(loaded.declared, None);
    assert_eq!(loaded.format, Format::Dds);
    assert_eq!(
        loaded.description,
        "DDS 2D texture (DX10), RGBA32F, 1 mip level"
    );
    let img = &loaded.layers[0];
    assert_eq!((img.width(), img.height(), img.channels()), (w, h, 4));
    for y in 0..h {
        for x in 0..w {
            assert_eq!(img.get(x, y), &texel(1, 0, x, y)[..]);
        }
    }

    // Packed R11G11B10 floats: 1.0, 2.0, 0.5 and 0, 0.25, inf.
    let mut dds = dx10_2d(2, 1, DxgiFormat::R11G11B10_Float);
    let word = |r: u32, g: u32, b: u32| (r | g << 11 | b << 22).to_le_bytes();
    dds.data = [word(15 << 6, 16 << 6, 14 << 5), word(0, 13 << 6, 31 << 5)].concat();
    let path = save_dds(dir.path(), "r11g11b10.dds", &dds);
    let loaded = read(&path, &Limits::default()).unwrap();
    assert_eq!(loaded.layers[0].channels(), 3);
    assert_eq!(
        loaded.layers[0].data(),
        &[1.0, 2.0, 0.5, 0.0, 0.25, f32::INFINITY]
    );

    // Shared-exponent RGB9E5: mantissas 256, 128, 1 with exponent 16 → 1, 0.5, 1/256.
    let mut dds = dx10_2d(1, 1, DxgiFormat::R9G9B9E5_SharedExp);
    dds.data = (256u32 | 128 << 9 | 1 << 18 | 16 << 27)
        .to_le_bytes()
        .to_vec();
    let path = save_dds(dir.path(), "rgb9e5.dds", &dds);
    let loaded = read(&path, &Limits::default()).unwrap();
    assert_eq!(loaded.layers[0].data(), &[1.0, 0.5, 1.0 / 256.0]);
}

#[test]
fn legacy_dds_a16b16g16r16f_cube() {
    let levels = make_cube(4, 4);
    let mut dds = Dds::new_d3d(NewD3dParams {
        height: 4,
        width: 4,
        depth: None,
        format: D3DFormat::A16B16G16R16F,
        mipmap_levels: Some(levels.len() as u32),
        caps2: Some(Caps2::CUBEMAP | Caps2::CUBEMAP_ALLFACES),
    })
    .unwrap();
    // Legacy float formats are named by the D3DFMT number as FourCC (113).
    dds.header.spf = PixelFormat {
        flags: PixelFormatFlags::FOURCC,
        fourcc: Some(FourCC(FourCC::A16B16G16R16F)),
        ..PixelFormat::default()
    };
    dds.data.clear();
    for f in 0..6 {
        for level in &levels {
            for v in level[f].data() {
                dds.data.extend_from_slice(&f16::from_f32(*v).to_le_bytes());
            }
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let path = save_dds(dir.path(), "legacy.dds", &dds);
    let loaded = read(&path, &Limits::default()).unwrap();
    assert_eq!(loaded.declared, Some(ProjectionKind::Cube));
    assert_eq!(
        loaded.description,
        "DDS cube map (legacy header), RGBA16F, 3 mip levels"
    );
    for (f, face) in loaded.layers.iter().enumerate() {
        assert_eq!(face.data(), &expected(&levels[0][f], true)[..], "face {f}");
    }

    // Without all six face bits it is refused.
    dds.header.caps2 = Caps2::CUBEMAP | Caps2::CUBEMAP_POSITIVEX;
    let path = save_dds(dir.path(), "partial.dds", &dds);
    let err = read(&path, &Limits::default()).unwrap_err();
    assert_eq!(err.fault(), Fault::Input);
}
