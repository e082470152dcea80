//! KTX 2.0 cube maps (Khronos KTX File Format Specification, version 2.0).
//!
//! The writer is written by hand from the specification: RGBA16F
//! (`VK_FORMAT_R16G16B16A16_SFLOAT`) or RGBA32F (`VK_FORMAT_R32G32B32A32_SFLOAT`), faceCount 6,
//! every mip level given, no supercompression, a basic Data Format Descriptor and the
//! `KTXorientation` = `rd` and `KTXwriter` metadata (and `mirrorball:projection` when the
//! projection is given, read back as [`Loaded::recorded`]). Faces go in the order +X −X +Y −Y +Z −Z
//! with row 0 (`t = 0`) first, which is how KTX2 and Vulkan define cube faces (orientation
//! `rd`: s increases to the right, t downwards), so mirrorball's face images are stored
//! unchanged.
//!
//! The reader uses the `ktx2` crate after checking the header against the [`Limits`] and the
//! file length, and takes level 0 of uncompressed float cube maps or 2D textures.
//!
//! This module also holds what the KTX2 and DDS code share: cube validation, texel formats
//! and size checks.

use crate::{atomic_write, Error, Format, Limits, Loaded, Precision, WriteOptions};
use half::f16;
use mirrorball_core::{Image, ProjectionKind};
use std::fs::File;
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::Path;

/// The KTX 2.0 file identifier, `«KTX 20»\r\n\x1A\n`.
const IDENTIFIER: [u8; 12] = [
    0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A,
];
/// Identifier plus header plus index: the level index starts here.
const HEADER_LEN: usize = 80;
/// One level index entry: byteOffset, byteLength, uncompressedByteLength (all UInt64).
const LEVEL_INDEX_LEN: usize = 24;
/// Largest DFD plus key/value data we are willing to read (they are tiny in practice).
const MAX_METADATA: u64 = 16 << 20;

const VK_FORMAT_R16G16B16_SFLOAT: u32 = 90;
const VK_FORMAT_R16G16B16A16_SFLOAT: u32 = 97;
const VK_FORMAT_R32G32B32_SFLOAT: u32 = 106;
const VK_FORMAT_R32G32B32A32_SFLOAT: u32 = 109;
const VK_FORMAT_B10G11R11_UFLOAT_PACK32: u32 = 122;
const VK_FORMAT_E5B9G9R9_UFLOAT_PACK32: u32 = 123;

/// How the texels of a KTX2 or DDS file are encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum TexelFormat {
    /// Four little-endian binary16 floats, R G B A.
    Rgba16F,
    /// Four little-endian binary32 floats, R G B A.
    Rgba32F,
    /// Three binary16 floats, R G B.
    Rgb16F,
    /// Three binary32 floats, R G B.
    Rgb32F,
    /// One 32-bit word: unsigned 11-bit R (bits 0–10), 11-bit G, 10-bit B floats.
    Rg11B10F,
    /// One 32-bit word: 9-bit R, G, B mantissas and a shared 5-bit exponent (bits 27–31).
    Rgb9E5,
}

impl TexelFormat {
    /// Bytes per texel.
    pub(crate) fn bytes(self) -> usize {
        match self {
            TexelFormat::Rgba16F => 8,
            TexelFormat::Rgba32F => 16,
            TexelFormat::Rgb16F => 6,
            TexelFormat::Rgb32F => 12,
            TexelFormat::Rg11B10F | TexelFormat::Rgb9E5 => 4,
        }
    }

    /// Channels of the decoded image: 4 for the RGBA formats, 3 otherwise.
    pub(crate) fn channels(self) -> usize {
        match self {
            TexelFormat::Rgba16F | TexelFormat::Rgba32F => 4,
            _ => 3,
        }
    }

    /// Short name for descriptions.
    pub(crate) fn name(self) -> &'static str {
        match self {
            TexelFormat::Rgba16F => "RGBA16F",
            TexelFormat::Rgba32F => "RGBA32F",
            TexelFormat::Rgb16F => "RGB16F",
            TexelFormat::Rgb32F => "RGB32F",
            TexelFormat::Rg11B10F => "R11G11B10F",
            TexelFormat::Rgb9E5 => "RGB9E5",
        }
    }

    /// Decodes tightly packed texels into interleaved `f32`s (`channels()` per texel).
    pub(crate) fn decode(self, bytes: &[u8]) -> Vec<f32> {
        let word = |b: &[u8]| u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        match self {
            TexelFormat::Rgba16F | TexelFormat::Rgb16F => bytes
                .chunks_exact(2)
                .map(|b| f16::from_le_bytes([b[0], b[1]]).to_f32())
                .collect(),
            TexelFormat::Rgba32F | TexelFormat::Rgb32F => bytes
                .chunks_exact(4)
                .map(|b| f32::from_bits(word(b)))
                .collect(),
            TexelFormat::Rg11B10F => bytes
                .chunks_exact(4)
                .flat_map(|b| {
                    let v = word(b);
                    [
                        small_ufloat(v & 0x7ff, 6),
                        small_ufloat((v >> 11) & 0x7ff, 6),
                        small_ufloat(v >> 22, 5),
                    ]
                })
                .collect(),
            TexelFormat::Rgb9E5 => bytes
                .chunks_exact(4)
                .flat_map(|b| {
                    let v = word(b);
                    // value = mantissa × 2^(exponent − bias − mantissa bits), bias 15.
                    let scale = 2f32.powi((v >> 27) as i32 - 15 - 9);
                    [
                        (v & 0x1ff) as f32 * scale,
                        ((v >> 9) & 0x1ff) as f32 * scale,
                        ((v >> 18) & 0x1ff) as f32 * scale,
                    ]
                })
                .collect(),
        }
    }

    /// Encodes `image` as tightly packed RGBA texels (alpha = 1 for RGB images) into `out`,
    /// replacing its contents. Only the formats mirrorball writes: RGBA16F and RGBA32F.
    pub(crate) fn encode_rgba(self, image: &Image, out: &mut Vec<u8>) {
        out.clear();
        out.reserve(image.width() as usize * image.height() as usize * self.bytes());
        let c = image.channels();
        for px in image.data().chunks_exact(c) {
            let rgba = [px[0], px[1], px[2], if c == 4 { px[3] } else { 1.0 }];
            for v in rgba {
                match self {
                    TexelFormat::Rgba16F => out.extend_from_slice(&f16::from_f32(v).to_le_bytes()),
                    TexelFormat::Rgba32F => out.extend_from_slice(&v.to_le_bytes()),
                    _ => unreachable!("mirrorball writes only RGBA16F and RGBA32F"),
                }
            }
        }
    }
}

/// An unsigned float with a 5-bit exponent (bias 15) above `mantissa_bits` of mantissa and no
/// sign, as in the 11- and 10-bit channels of `B10G11R11_UFLOAT_PACK32`.
fn small_ufloat(bits: u32, mantissa_bits: u32) -> f32 {
    let one = (1u32 << mantissa_bits) as f32;
    let m = bits & ((1 << mantissa_bits) - 1);
    match bits >> mantissa_bits {
        0 => m as f32 / one * 2f32.powi(-14),
        31 if m == 0 => f32::INFINITY,
        31 => f32::NAN,
        e => (1.0 + m as f32 / one) * 2f32.powi(e as i32 - 15),
    }
}

/// The texel format a cube container is written in: half unless `opts` asks for float.
pub(crate) fn written_format(
    path: &Path,
    opts: &WriteOptions,
    container: &str,
) -> Result<TexelFormat, Error> {
    match opts.precision {
        None | Some(Precision::Half) => Ok(TexelFormat::Rgba16F),
        Some(Precision::Float) => Ok(TexelFormat::Rgba32F),
        Some(p) => Err(Error::request(
            path,
            format!("{container} cube maps are written as half or float, not {p:?}"),
        )),
    }
}

/// Checks that `levels` is a cube map with a mip chain: six square faces per level, all the
/// same size, each level half the one before (rounded down, at least 1), no more levels than
/// the chain down to 1×1 has. Returns the level-0 face size.
pub(crate) fn validate_cube(path: &Path, levels: &[Vec<Image>]) -> Result<u32, Error> {
    let bad = |problem: String| Err(Error::request(path, problem));
    let Some(first) = levels.first() else {
        return bad("a cube map needs at least one mip level".into());
    };
    let Some(face0) = first.first() else {
        return bad("mip level 0 has no faces; a cube map has 6".into());
    };
    let size = face0.width();
    if size == 0 {
        return bad("cube faces must not be empty".into());
    }
    if levels.len() > max_levels(size, size) as usize {
        return bad(format!(
            "{} mip levels given, but a {size}×{size} face has at most {}",
            levels.len(),
            max_levels(size, size)
        ));
    }
    for (i, level) in levels.iter().enumerate() {
        if level.len() != 6 {
            return bad(format!(
                "mip level {i} has {} faces; a cube map has 6",
                level.len()
            ));
        }
        let want = (size >> i).max(1);
        for (f, face) in level.iter().enumerate() {
            if face.width() != face.height() {
                return bad(format!(
                    "face {f} of mip level {i} is {}×{}; cube faces must be square",
                    face.width(),
                    face.height()
                ));
            }
            if face.width() != want {
                return bad(format!(
                    "face {f} of mip level {i} is {0}×{0}; expected {want}×{want} \
                     (level 0 is {size}×{size}, each level half the one before)",
                    face.width()
                ));
            }
        }
    }
    Ok(size)
}

/// Mip levels in a full chain for a `width`×`height` image: ⌊log₂ max(w, h)⌋ + 1.
pub(crate) fn max_levels(width: u32, height: u32) -> u32 {
    32 - width.max(height).max(1).leading_zeros()
}

/// Refuses images larger than `limits` allow, before anything is allocated.
pub(crate) fn check_limits(
    path: &Path,
    width: u32,
    height: u32,
    limits: &Limits,
) -> Result<(), Error> {
    if width > limits.max_dimension || height > limits.max_dimension {
        return Err(Error::input(
            path,
            format!(
                "declared size {width}×{height} exceeds the largest allowed dimension {}",
                limits.max_dimension
            ),
        ));
    }
    let texels = u64::from(width) * u64::from(height);
    if texels > limits.max_texels {
        return Err(Error::input(
            path,
            format!(
                "declared size {width}×{height} ({texels} texels) exceeds the limit of {} texels",
                limits.max_texels
            ),
        ));
    }
    Ok(())
}

/// "1 mip level", "11 mip levels".
pub(crate) fn mip_phrase(n: u32) -> String {
    if n == 1 {
        "1 mip level".into()
    } else {
        format!("{n} mip levels")
    }
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// Writes a cube map with its mip chain as KTX 2.0. See the module documentation.
pub fn write(path: &Path, levels: &[Vec<Image>], opts: &WriteOptions) -> Result<(), Error> {
    let format = written_format(path, opts, "KTX2")?;
    let size = validate_cube(path, levels)?;
    let level_count = levels.len();
    let texel = format.bytes();
    let (vk_format, type_size) = match format {
        TexelFormat::Rgba16F => (VK_FORMAT_R16G16B16A16_SFLOAT, 2u32),
        _ => (VK_FORMAT_R32G32B32A32_SFLOAT, 4u32),
    };

    let dfd = data_format_descriptor(format);
    let writer = format!("mirrorball {}", env!("CARGO_PKG_VERSION"));
    let mut pairs = vec![("KTXorientation", "rd".to_string()), ("KTXwriter", writer)];
    if let Some(info) = &opts.declared {
        // Sorted by key, as the specification requires: "KTX…" < "mirrorball:…".
        pairs.push((crate::PROJECTION_KEY, info.texts().0));
    }
    let pairs: Vec<(&str, &str)> = pairs.iter().map(|(k, v)| (*k, v.as_str())).collect();
    let kvd = key_value_data(&pairs);
    let dfd_offset = HEADER_LEN + LEVEL_INDEX_LEN * level_count;
    let kvd_offset = dfd_offset + dfd.len();
    let data_start = (kvd_offset + kvd.len()) as u64;

    // The Mip Level Array holds the smallest level first; each level starts on a multiple of
    // lcm(texel block size, 4) (mipPadding). The Level Index lists level 0 first.
    let align = (texel * 4 / gcd(texel, 4)) as u64;
    let mut index = vec![(0u64, 0u64); level_count];
    let mut cursor = data_start;
    for p in (0..level_count).rev() {
        let s = u64::from((size >> p).max(1));
        let len = 6 * s * s * texel as u64;
        let offset = cursor.div_ceil(align) * align;
        index[p] = (offset, len);
        cursor = offset + len;
    }

    let mut head = Vec::with_capacity(data_start as usize);
    head.extend_from_slice(&IDENTIFIER);
    for v in [
        vk_format,
        type_size,
        size,               // pixelWidth
        size,               // pixelHeight
        0,                  // pixelDepth: not 3D
        0,                  // layerCount: not an array
        6,                  // faceCount: cube map
        level_count as u32, // levelCount
        0,                  // supercompressionScheme: none
        dfd_offset as u32,  // dfdByteOffset
        dfd.len() as u32,   // dfdByteLength
        kvd_offset as u32,  // kvdByteOffset
        kvd.len() as u32,   // kvdByteLength
    ] {
        head.extend_from_slice(&v.to_le_bytes());
    }
    head.extend_from_slice(&0u64.to_le_bytes()); // sgdByteOffset
    head.extend_from_slice(&0u64.to_le_bytes()); // sgdByteLength
    for &(offset, len) in &index {
        head.extend_from_slice(&offset.to_le_bytes());
        head.extend_from_slice(&len.to_le_bytes()); // byteLength
        head.extend_from_slice(&len.to_le_bytes()); // uncompressedByteLength
    }
    debug_assert_eq!(head.len(), dfd_offset);
    head.extend_from_slice(&dfd);
    head.extend_from_slice(&kvd);
    debug_assert_eq!(head.len() as u64, data_start);

    atomic_write(path, |w| {
        let io = |e| Error::io(path, e);
        w.write_all(&head).map_err(io)?;
        let mut written = data_start;
        let mut buf = Vec::new();
        for p in (0..level_count).rev() {
            let (offset, _) = index[p];
            let padding = (offset - written) as usize;
            w.write_all(&[0u8; 16][..padding]).map_err(io)?;
            written = offset;
            for face in &levels[p] {
                format.encode_rgba(face, &mut buf);
                w.write_all(&buf).map_err(io)?;
                written += buf.len() as u64;
            }
        }
        Ok(())
    })
}

/// The Data Format Descriptor for the RGBA float formats mirrorball writes (Khronos Data
/// Format Specification 1.3/1.4, basic descriptor block): `dfdTotalSize`, then one block
/// with vendor 0 (Khronos), type 0 (basic), version 2 (1.3), colour model RGBSDA, BT.709
/// primaries, linear transfer, straight alpha, a 1×1×1×1 texel block of `bytes()` bytes in
/// plane 0, and one sample per channel (R=0, G=1, B=2, A=15) with the signed and float
/// qualifiers, its bit offset and length, and sampleLower/Upper = −1.0/1.0 as `f32` bits,
/// as the specification's examples do for float formats.
fn data_format_descriptor(format: TexelFormat) -> Vec<u8> {
    const SAMPLE_SIGNED: u32 = 0x40;
    const SAMPLE_FLOAT: u32 = 0x80;
    let bits: u32 = match format {
        TexelFormat::Rgba16F => 16,
        _ => 32,
    };
    let channels = [0u32, 1, 2, 15];
    let block_size = 24 + 16 * channels.len() as u32;
    let mut out = Vec::with_capacity(4 + block_size as usize);
    out.extend_from_slice(&(4 + block_size).to_le_bytes()); // dfdTotalSize
    out.extend_from_slice(&0u32.to_le_bytes()); // vendorId 0 | descriptorType 0 << 17
    out.extend_from_slice(&(2 | block_size << 16).to_le_bytes()); // version | block size
    out.extend_from_slice(&[1, 1, 1, 0]); // RGBSDA, BT709, LINEAR, straight alpha
    out.extend_from_slice(&[0, 0, 0, 0]); // texelBlockDimension0..3 (stored minus 1)
    let mut planes = [0u8; 8];
    planes[0] = format.bytes() as u8;
    out.extend_from_slice(&planes); // bytesPlane0..7
    for (i, &channel) in channels.iter().enumerate() {
        let word = (i as u32 * bits) // bitOffset
            | (bits - 1) << 16 // bitLength − 1
            | (channel | SAMPLE_SIGNED | SAMPLE_FLOAT) << 24; // channelType | qualifiers
        out.extend_from_slice(&word.to_le_bytes());
        out.extend_from_slice(&[0, 0, 0, 0]); // samplePosition0..3
        out.extend_from_slice(&(-1.0f32).to_bits().to_le_bytes()); // sampleLower
        out.extend_from_slice(&1.0f32.to_bits().to_le_bytes()); // sampleUpper
    }
    out
}

/// Key/value data: each pair as keyAndValueByteLength, key, NUL, value, NUL, padded to 4
/// bytes. `pairs` must be sorted by key (the specification requires code-point order).
fn key_value_data(pairs: &[(&str, &str)]) -> Vec<u8> {
    debug_assert!(pairs.windows(2).all(|w| w[0].0 < w[1].0));
    let mut out = Vec::new();
    for (key, value) in pairs {
        let len = key.len() + 1 + value.len() + 1;
        out.extend_from_slice(&(len as u32).to_le_bytes());
        out.extend_from_slice(key.as_bytes());
        out.push(0);
        out.extend_from_slice(value.as_bytes());
        out.push(0);
        out.resize(out.len().next_multiple_of(4), 0);
    }
    out
}

fn read_u32(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"))
}

/// What `ktx2` 0.5 would panic on in the Data Format Descriptor at `offset` (`len` bytes)
/// of `bytes`, if anything: a basic block's texel block dimension byte of 255 (it adds one
/// to the byte as a `u8` and unwraps a `NonZeroU8`; found by fuzzing). Walks the blocks as
/// the crate does: after `dfdTotalSize`, each block's 8-byte header (vendor and type in
/// the first word, its size in the upper half of the second), the basic block's
/// dimensions four bytes after the header. Malformed bounds are left to the crate.
fn dfd_problem(bytes: &[u8], offset: usize, len: usize) -> Option<String> {
    let end = offset.checked_add(len)?.min(bytes.len());
    let mut at = offset.checked_add(4)?;
    while at + 8 <= end {
        let kind = read_u32(bytes, at);
        let size = u16::from_le_bytes([bytes[at + 6], bytes[at + 7]]) as usize;
        // Vendor 0 (Khronos), type 0: the basic block.
        if kind == 0 && at + 16 <= end && bytes[at + 12..at + 16].contains(&255) {
            return Some(
                "its data format descriptor gives a texel block dimension of 256".to_string(),
            );
        }
        if size < 8 {
            break;
        }
        at += size;
    }
    None
}

fn read_u64(bytes: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"))
}

/// Reads level 0 of a KTX2 cube map (faceCount 6: the six faces, declared cube) or 2D
/// texture (faceCount 1: one flat image, turned to top-row-first by its `KTXorientation`).
/// Uncompressed RGBA16F, RGBA32F, RGB16F, RGB32F, B10G11R11 and E5B9G9R9 float data.
pub fn read(path: &Path, limits: &Limits) -> Result<Loaded, Error> {
    let io = |e| Error::io(path, e);
    let invalid = |problem: String| Error::input(path, problem);
    let mut file = File::open(path).map_err(io)?;
    let file_len = file.metadata().map_err(io)?.len();

    let mut head = [0u8; HEADER_LEN];
    file.read_exact(&mut head).map_err(io)?;
    if head[..12] != IDENTIFIER {
        return Err(invalid("not a KTX 2.0 file (bad identifier)".into()));
    }
    let header = ktx2::Header::from_bytes(&head)
        .map_err(|e| invalid(format!("invalid KTX2 header: {e}")))?;
    let vk_format = read_u32(&head, 12);
    let scheme = read_u32(&head, 44);

    let format = match vk_format {
        VK_FORMAT_R16G16B16A16_SFLOAT => TexelFormat::Rgba16F,
        VK_FORMAT_R32G32B32A32_SFLOAT => TexelFormat::Rgba32F,
        VK_FORMAT_R16G16B16_SFLOAT => TexelFormat::Rgb16F,
        VK_FORMAT_R32G32B32_SFLOAT => TexelFormat::Rgb32F,
        VK_FORMAT_B10G11R11_UFLOAT_PACK32 => TexelFormat::Rg11B10F,
        VK_FORMAT_E5B9G9R9_UFLOAT_PACK32 => TexelFormat::Rgb9E5,
        _ => {
            let name = header
                .format
                .map_or("VK_FORMAT_UNDEFINED".to_string(), |f| format!("{f:?}"));
            return Err(invalid(format!(
                "unsupported KTX2 format {name} ({vk_format}); mirrorball reads uncompressed \
                 float formats: RGBA16F, RGBA32F, RGB16F, RGB32F, B10G11R11 and E5B9G9R9"
            )));
        }
    };
    match scheme {
        0 => {}
        2 => {
            return Err(invalid(
                "Zstandard-supercompressed KTX2 is not supported; save the file without \
                 supercompression"
                    .into(),
            ))
        }
        s => {
            let name = header
                .supercompression_scheme
                .map_or(String::new(), |s| format!("{s:?} "));
            return Err(invalid(format!(
                "KTX2 supercompression scheme {name}({s}) is not supported; save the file \
                 without supercompression"
            )));
        }
    }
    let (width, height) = (header.pixel_width, header.pixel_height);
    if height == 0 {
        return Err(invalid("1D KTX2 textures are not supported".into()));
    }
    if header.pixel_depth != 0 {
        return Err(invalid("3D KTX2 textures are not supported".into()));
    }
    if header.layer_count != 0 {
        return Err(invalid(format!(
            "KTX2 array textures ({} layers) are not supported",
            header.layer_count
        )));
    }
    let faces = header.face_count;
    match faces {
        1 => {}
        6 if width == height => {}
        6 => {
            return Err(invalid(format!(
                "KTX2 cube map with non-square faces ({width}×{height})"
            )))
        }
        n => {
            return Err(invalid(format!(
                "invalid KTX2 face count {n} (must be 1 or 6)"
            )))
        }
    }
    check_limits(path, width, height, limits)?;
    let level_count = header.level_count.max(1);
    if level_count > max_levels(width, height) {
        return Err(invalid(format!(
            "{level_count} mip levels declared for a {width}×{height} texture, which has at most {}",
            max_levels(width, height)
        )));
    }

    // The level index and the sections it points to must lie inside the file, and each level
    // must hold exactly the texels its size calls for, before anything big is read.
    let mut index = vec![0u8; LEVEL_INDEX_LEN * level_count as usize];
    file.read_exact(&mut index).map_err(io)?;
    let texel = format.bytes() as u64;
    let mut end = (HEADER_LEN + index.len()) as u64;
    for p in 0..level_count as usize {
        let offset = read_u64(&index, p * LEVEL_INDEX_LEN);
        let len = read_u64(&index, p * LEVEL_INDEX_LEN + 8);
        let (w, h) = (
            u64::from((width >> p).max(1)),
            u64::from((height >> p).max(1)),
        );
        let want = u64::from(faces) * w * h * texel;
        if len != want {
            return Err(invalid(format!(
                "mip level {p} holds {len} bytes; {faces} face(s) of {w}×{h} {} need {want}",
                format.name()
            )));
        }
        let level_end = offset
            .checked_add(len)
            .ok_or_else(|| invalid(format!("mip level {p} has an impossible offset")))?;
        end = end.max(level_end);
    }
    let index_fields = &header.index;
    let metadata =
        u64::from(index_fields.dfd_byte_length) + u64::from(index_fields.kvd_byte_length);
    if metadata > MAX_METADATA {
        return Err(invalid(format!(
            "implausibly large KTX2 metadata ({metadata} bytes of descriptor and key/value data)"
        )));
    }
    end = end
        .max(u64::from(index_fields.dfd_byte_offset) + u64::from(index_fields.dfd_byte_length))
        .max(u64::from(index_fields.kvd_byte_offset) + u64::from(index_fields.kvd_byte_length));
    if index_fields.sgd_byte_length != 0 {
        return Err(invalid("unexpected supercompression global data".into()));
    }
    if end > file_len {
        return Err(invalid(format!(
            "file is truncated: its index refers to byte {end}, but the file has {file_len} bytes"
        )));
    }

    let mut bytes = Vec::with_capacity(end as usize);
    file.seek(SeekFrom::Start(0)).map_err(io)?;
    file.take(end).read_to_end(&mut bytes).map_err(io)?;
    if (bytes.len() as u64) < end {
        return Err(invalid(
            "file is truncated (it shrank while being read)".into(),
        ));
    }
    if let Some(problem) = dfd_problem(
        &bytes,
        index_fields.dfd_byte_offset as usize,
        index_fields.dfd_byte_length as usize,
    ) {
        return Err(invalid(format!("invalid KTX2 file: {problem}")));
    }
    let reader = ktx2::Reader::new(bytes.as_slice())
        .map_err(|e| invalid(format!("invalid KTX2 file: {e}")))?;
    let level0 = reader
        .levels()
        .next()
        .ok_or_else(|| invalid("KTX2 file has no mip levels".into()))?;

    let face_len = width as usize * height as usize * format.bytes();
    let mut layers = Vec::with_capacity(faces as usize);
    for face in level0.data.chunks_exact(face_len).take(faces as usize) {
        let texels = format.decode(face);
        let image = Image::from_vec(width, height, format.channels(), texels)
            .expect("decoded length matches the face size");
        layers.push(image);
    }
    if layers.len() != faces as usize {
        return Err(invalid("mip level 0 is shorter than its faces".into()));
    }

    let levels = mip_phrase(level_count);
    let get = |key: &str| {
        reader
            .key_value_data()
            .find(|(k, _)| *k == key)
            .map(|(_, v)| {
                String::from_utf8_lossy(v)
                    .trim_end_matches('\0')
                    .to_string()
            })
    };
    let recorded = crate::recorded(get, width, height);
    let (declared, description) = if faces == 6 {
        // Cube faces are always `rd` (the specification requires it), so they are kept as is.
        (
            Some(ProjectionKind::Cube),
            format!("KTX2 cube map, {}, {levels}", format.name()),
        )
    } else {
        let orientation = reader
            .key_value_data()
            .find(|(key, _)| *key == "KTXorientation")
            .map(|(_, value)| value.to_vec())
            .unwrap_or_default();
        let image = &mut layers[0];
        if orientation.first() == Some(&b'l') {
            *image = image.flipped(true);
        }
        if orientation.get(1) == Some(&b'u') {
            *image = image.flipped(false);
        }
        (
            None,
            format!("KTX2 2D texture, {}, {levels}", format.name()),
        )
    };
    Ok(Loaded {
        layers,
        declared,
        recorded,
        format: Format::Ktx2,
        description,
        invalid: None,
    })
}
