//! KTX 2.0 cube maps (Khronos KTX File Format Specification, version 2.0).
//!
//! The writer is written by hand from the specification: faceCount 6, every mip level given,
//! texels in any [`Encoding`] (vkFormats in [`vk_format`]), no supercompression or Zstandard
//! (supercompressionScheme 2, each level compressed on its own), a basic Data Format
//! Descriptor as KTX-Software's `vk2dfd` makes it for the vkFormat ([`data_format_descriptor`])
//! and the `KTXorientation` = `rd` and `KTXwriter` metadata (and `mirrorball:projection` when
//! the projection is given, read back as [`Loaded::recorded`]; `mirrorball:encoding` for
//! RGBD and RGBM, which share `R8G8B8A8_UNORM`). Faces go in the order +X −X +Y −Y +Z −Z
//! with row 0 (`t = 0`) first, which is how KTX2 and Vulkan define cube faces (orientation
//! `rd`: s increases to the right, t downwards), so mirrorball's face images are stored
//! unchanged.
//!
//! The reader uses the `ktx2` crate after checking the header against the [`Limits`] and the
//! file length, and takes level 0 of float cube maps or 2D textures (Zstandard-compressed
//! too), BC6H, and RGBD/RGBM recorded as such.
//!
//! This module also holds what the KTX2 and DDS code share: cube validation, texel formats
//! and size checks.

use crate::atomic::{Dest, Written};
use crate::input::{Input, Reader};
use crate::{Error, Format, Limits, Loaded, MapInfo, Precision, WriteOptions};
use half::f16;
use mirrorball_core::{Choice, Image, ProjectionKind};
use mirrorball_encode::{Effort, Encoding};
use rayon::prelude::*;
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

const VK_FORMAT_R8G8B8A8_UNORM: u32 = 37;
const VK_FORMAT_R16G16B16_SFLOAT: u32 = 90;
const VK_FORMAT_R16G16B16A16_SFLOAT: u32 = 97;
const VK_FORMAT_R32G32B32_SFLOAT: u32 = 106;
const VK_FORMAT_R32G32B32A32_SFLOAT: u32 = 109;
const VK_FORMAT_B10G11R11_UFLOAT_PACK32: u32 = 122;
const VK_FORMAT_E5B9G9R9_UFLOAT_PACK32: u32 = 123;
const VK_FORMAT_BC6H_UFLOAT_BLOCK: u32 = 143;
const VK_FORMAT_BC6H_SFLOAT_BLOCK: u32 = 144;
/// supercompressionScheme 2.
const SUPERCOMPRESSION_ZSTD: u32 = 2;
/// The key/value key that tells RGBD from RGBM (both `R8G8B8A8_UNORM`).
pub(crate) const ENCODING_KEY: &str = "mirrorball:encoding";

/// The vkFormat of each encoding and its typeSize (KTX 2.0 §3.2, §3.3: the size of the
/// component, or of the packed word, that endianness conversion swaps; 1 for block formats
/// and bytes).
pub(crate) fn vk_format(encoding: Encoding) -> (u32, u32) {
    match encoding {
        Encoding::Rgba16F => (VK_FORMAT_R16G16B16A16_SFLOAT, 2),
        Encoding::Rgba32F => (VK_FORMAT_R32G32B32A32_SFLOAT, 4),
        Encoding::Rgb9E5 => (VK_FORMAT_E5B9G9R9_UFLOAT_PACK32, 4),
        Encoding::B10G11R11 => (VK_FORMAT_B10G11R11_UFLOAT_PACK32, 4),
        Encoding::Rgbd | Encoding::Rgbm => (VK_FORMAT_R8G8B8A8_UNORM, 1),
        Encoding::Bc6hUnsigned => (VK_FORMAT_BC6H_UFLOAT_BLOCK, 1),
        Encoding::Bc6hSigned => (VK_FORMAT_BC6H_SFLOAT_BLOCK, 1),
    }
}

/// How the texels of a KTX2 or DDS file are stored: an [`Encoding`] mirrorball writes, or
/// one of the RGB float layouts it only reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum TexelFormat {
    /// One of the encodings mirrorball writes.
    Encoded(Encoding),
    /// Three binary16 floats, R G B.
    Rgb16F,
    /// Three binary32 floats, R G B.
    Rgb32F,
}

impl TexelFormat {
    /// Bytes of one `width`×`height` image (whole blocks for BC6H).
    pub(crate) fn image_bytes(self, width: u32, height: u32) -> u64 {
        let texels = u64::from(width) * u64::from(height);
        match self {
            TexelFormat::Encoded(e) => e.image_bytes(width, height) as u64,
            TexelFormat::Rgb16F => texels * 6,
            TexelFormat::Rgb32F => texels * 12,
        }
    }

    /// Short name for descriptions.
    pub(crate) fn name(self) -> &'static str {
        match self {
            TexelFormat::Encoded(Encoding::B10G11R11) => "R11G11B10F",
            TexelFormat::Encoded(e) => e.label(),
            TexelFormat::Rgb16F => "RGB16F",
            TexelFormat::Rgb32F => "RGB32F",
        }
    }

    /// Decodes one `width`×`height` image of [`TexelFormat::image_bytes`] bytes.
    pub(crate) fn decode(self, bytes: &[u8], width: u32, height: u32) -> Image {
        let data = match self {
            TexelFormat::Encoded(e) => return e.decode(bytes, width, height),
            TexelFormat::Rgb16F => bytes
                .chunks_exact(2)
                .map(|b| f16::from_le_bytes([b[0], b[1]]).to_f32())
                .collect(),
            TexelFormat::Rgb32F => bytes
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect(),
        };
        Image::from_vec(width, height, 3, data).expect("decoded length matches the image size")
    }
}

/// The texel format a cube container is written in: half unless `opts` asks for float.
pub(crate) fn written_format(
    path: &Path,
    opts: &WriteOptions,
    container: &str,
) -> Result<Encoding, Error> {
    match opts.precision {
        None | Some(Precision::Half) => Ok(Encoding::Rgba16F),
        Some(Precision::Float) => Ok(Encoding::Rgba32F),
        Some(p) => Err(Error::request(
            path,
            format!("{container} cube maps are written as half or float, not {p:?}"),
        )),
    }
}

/// How [`write_ktx2`], [`crate::write_dds`] and [`crate::write_ktx1`] write a cube: its
/// texel encoding, the unsigned BC6H encoder's effort, Zstandard supercompression (KTX2
/// only) and what the file records.
#[derive(Clone, Debug, Default)]
pub struct CubeWrite {
    /// The texel encoding of every face and level.
    pub encoding: Encoding,
    /// How hard the unsigned BC6H encoder searches.
    pub effort: Effort,
    /// Zstandard level (1–22; 3 is Zstandard's and KTX-Software's default) to
    /// supercompress each KTX2 level with, or `None` for none.
    pub zstd: Option<i32>,
    /// The projection (and packing) to record under [`crate::PROJECTION_KEY`] (KTX2).
    pub declared: Option<MapInfo>,
    /// More key/value pairs (KTX2, KTX1): UTF-8 text, written NUL-terminated.
    pub metadata: Vec<(String, String)>,
}

/// The work of supercompressing `bytes` bytes with Zstandard at the levels bakes use (3 by
/// default), in [`mirrorball_core::work`]'s units: what [`write_ktx2`] counts for it.
pub fn zstd_work(bytes: u64) -> u64 {
    bytes * 10
}

/// Refuses what `write` cannot encode, before any work: everything [`Encoding::check`]
/// refuses (negative values as unsigned BC6H), in any face of any level.
pub(crate) fn check_encodable(
    path: &Path,
    levels: &[Vec<Image>],
    encoding: Encoding,
) -> Result<(), Error> {
    for (i, level) in levels.iter().enumerate() {
        for (f, face) in level.iter().enumerate() {
            encoding
                .check(face)
                .map_err(|e| Error::request(path, format!("face {f} of mip level {i}: {e}")))?;
        }
    }
    Ok(())
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

/// Writes a cube map with its mip chain as KTX 2.0, RGBA16F or RGBA32F as `opts` asks.
/// See the module documentation.
pub fn write(dest: Dest, levels: &[Vec<Image>], opts: &WriteOptions) -> Result<Written, Error> {
    let encoding = written_format(dest.path(), opts, "KTX2")?;
    let how = CubeWrite {
        encoding,
        declared: opts.declared,
        ..CubeWrite::default()
    };
    encode(dest, levels, &how)
}

/// Writes a cube map with its mip chain as KTX 2.0 in `how.encoding`, Zstandard-compressed
/// when `how.zstd` is given. `levels` is as [`crate::write_cube`] takes it. The files are
/// made to pass the checks KTX-Software's `ktx validate` makes of such a file (header,
/// index, DFD against the vkFormat, key/value data, level order, alignment and lengths);
/// `tests/io/encoded.rs` implements them from the specification and runs them on every
/// encoding, with and without Zstandard.
///
/// ```
/// use mirrorball_core::Image;
/// use mirrorball_io::{read, write_ktx2, CubeWrite, Encoding, Limits};
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("sky.ktx2");
/// let levels: Vec<Vec<Image>> = [8u32, 4, 2, 1]
///     .iter()
///     .map(|&n| (0..6).map(|_| Image::new(n, n, 3)).collect())
///     .collect();
/// let how = CubeWrite {
///     encoding: Encoding::Bc6hUnsigned,
///     zstd: Some(3),
///     ..CubeWrite::default()
/// };
/// write_ktx2(&path, &levels, &how).unwrap();
/// let loaded = read(&path, &Limits::default()).unwrap();
/// assert_eq!(loaded.layers.len(), 6);
/// assert!(loaded.description.contains("BC6H"));
/// ```
pub fn write_ktx2(path: &Path, levels: &[Vec<Image>], how: &CubeWrite) -> Result<(), Error> {
    encode(Dest::File(path), levels, how)?.land().map(|_| ())
}

/// [`write_ktx2`] into `dest`.
fn encode(dest: Dest, levels: &[Vec<Image>], how: &CubeWrite) -> Result<Written, Error> {
    let path = dest.path();
    let encoding = how.encoding;
    let size = validate_cube(path, levels)?;
    if let Some(level) = how.zstd {
        if !(1..=22).contains(&level) {
            return Err(Error::request(
                path,
                format!("Zstandard level {level} is outside 1–22"),
            ));
        }
    }
    check_encodable(path, levels, encoding)?;
    let level_count = levels.len();
    let supercompressed = how.zstd.is_some();

    let dfd = data_format_descriptor(encoding);
    let kvd = written_key_value_data(how);
    let dfd_offset = HEADER_LEN + LEVEL_INDEX_LEN * level_count;
    let kvd_offset = dfd_offset + dfd.len();
    let data_start = (kvd_offset + kvd.len()) as u64;

    // Supercompressed levels are made before the index, which holds their lengths.
    let compressed = compress_levels(path, levels, how)?;
    let index = level_index(
        encoding,
        size,
        level_count,
        supercompressed,
        &compressed,
        data_start,
    );
    let head = ktx2_head(encoding, size, supercompressed, &index, &dfd, &kvd);
    debug_assert_eq!(head.len() as u64, data_start);

    dest.emit(|w| write_level_data(path, w, levels, how, &head, &index, &compressed))
}

/// The key/value data [`write_ktx2`] writes: `KTXorientation` = `rd`, `KTXwriter`, the
/// declared projection under [`crate::PROJECTION_KEY`], the encoding under
/// [`ENCODING_KEY`] for RGBD and RGBM, and `how.metadata`, sorted by key.
fn written_key_value_data(how: &CubeWrite) -> Vec<u8> {
    let encoding = how.encoding;
    let writer = format!("mirrorball {}", env!("CARGO_PKG_VERSION"));
    // Sorted by key, as the specification requires (code-point order: "KTX…" before
    // "mirrorball:…").
    let mut pairs = std::collections::BTreeMap::new();
    pairs.insert("KTXorientation".to_string(), "rd".to_string());
    pairs.insert("KTXwriter".to_string(), writer);
    if let Some(info) = &how.declared {
        pairs.insert(crate::PROJECTION_KEY.to_string(), info.texts().0);
    }
    if matches!(encoding, Encoding::Rgbd | Encoding::Rgbm) {
        pairs.insert(ENCODING_KEY.to_string(), encoding.name().to_string());
    }
    for (k, v) in &how.metadata {
        pairs.insert(k.clone(), v.clone());
    }
    let pairs: Vec<(&str, &str)> = pairs
        .iter()
        .map(|(k, v)| (k.as_str(), v.as_str()))
        .collect();
    key_value_data(&pairs)
}

/// Each level's six faces encoded and Zstandard-compressed at `how.zstd` (levels in
/// parallel, the work counted in [`mirrorball_core::work`]), level 0 first; empty when
/// `how.zstd` is `None`.
fn compress_levels(
    path: &Path,
    levels: &[Vec<Image>],
    how: &CubeWrite,
) -> Result<Vec<Vec<u8>>, Error> {
    let encoding = how.encoding;
    let encode_level = |p: usize| -> Vec<u8> {
        let mut level = Vec::new();
        let mut buf = Vec::new();
        for face in &levels[p] {
            encoding.encode_with(face, how.effort, &mut buf);
            level.extend_from_slice(&buf);
        }
        level
    };
    Ok(match how.zstd {
        None => Vec::new(),
        Some(z) => (0..levels.len())
            .into_par_iter()
            .map(|p| {
                let level = encode_level(p);
                let packed = zstd::bulk::compress(&level, z);
                mirrorball_core::work::add(zstd_work(level.len() as u64));
                packed
            })
            .collect::<Result<_, _>>()
            .map_err(|e| Error::io(path, e))?,
    })
}

/// The Level Index: each level's (byteOffset, byteLength, uncompressedByteLength), level 0
/// first. The Mip Level Array starting at `data_start` holds the smallest level first; each
/// level starts on a multiple of lcm(texel block size, 4) (mipPadding), or of 1 when
/// supercompressed (when `compressed` holds the levels' bytes).
fn level_index(
    encoding: Encoding,
    size: u32,
    level_count: usize,
    supercompressed: bool,
    compressed: &[Vec<u8>],
    data_start: u64,
) -> Vec<(u64, u64, u64)> {
    let block = encoding.block_bytes();
    let align = if supercompressed {
        1
    } else {
        (block * 4 / gcd(block, 4)) as u64
    };
    let mut index = vec![(0u64, 0u64, 0u64); level_count];
    let mut cursor = data_start;
    for p in (0..level_count).rev() {
        let s = (size >> p).max(1);
        let raw = 6 * encoding.image_bytes(s, s) as u64;
        let len = compressed.get(p).map_or(raw, |c| c.len() as u64);
        let offset = cursor.div_ceil(align) * align;
        index[p] = (offset, len, raw);
        cursor = offset + len;
    }
    index
}

/// Everything before the Mip Level Array: identifier, header, Level Index, Data Format
/// Descriptor (`dfd`) and key/value data (`kvd`).
fn ktx2_head(
    encoding: Encoding,
    size: u32,
    supercompressed: bool,
    index: &[(u64, u64, u64)],
    dfd: &[u8],
    kvd: &[u8],
) -> Vec<u8> {
    let level_count = index.len();
    let (vk_format, type_size) = vk_format(encoding);
    let dfd_offset = HEADER_LEN + LEVEL_INDEX_LEN * level_count;
    let kvd_offset = dfd_offset + dfd.len();
    let data_start = (kvd_offset + kvd.len()) as u64;
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
        if supercompressed {
            SUPERCOMPRESSION_ZSTD
        } else {
            0
        },
        dfd_offset as u32, // dfdByteOffset
        dfd.len() as u32,  // dfdByteLength
        kvd_offset as u32, // kvdByteOffset
        kvd.len() as u32,  // kvdByteLength
    ] {
        head.extend_from_slice(&v.to_le_bytes());
    }
    head.extend_from_slice(&0u64.to_le_bytes()); // sgdByteOffset: Zstandard has none
    head.extend_from_slice(&0u64.to_le_bytes()); // sgdByteLength
    for &(offset, len, raw) in index {
        head.extend_from_slice(&offset.to_le_bytes());
        head.extend_from_slice(&len.to_le_bytes()); // byteLength
        head.extend_from_slice(&raw.to_le_bytes()); // uncompressedByteLength
    }
    debug_assert_eq!(head.len(), dfd_offset);
    head.extend_from_slice(dfd);
    head.extend_from_slice(kvd);
    head
}

/// Writes `head`, then the levels smallest first, each after the zero padding that brings
/// it to its offset in `index`: the compressed bytes when `compressed` holds them, else the
/// faces encoded one at a time.
fn write_level_data(
    path: &Path,
    w: &mut (impl Write + ?Sized),
    levels: &[Vec<Image>],
    how: &CubeWrite,
    head: &[u8],
    index: &[(u64, u64, u64)],
    compressed: &[Vec<u8>],
) -> Result<(), Error> {
    let io = |e| Error::io(path, e);
    w.write_all(head).map_err(io)?;
    // `head` ends where the Mip Level Array starts.
    let mut written = head.len() as u64;
    let mut buf = Vec::new();
    for p in (0..levels.len()).rev() {
        let (offset, len, _) = index[p];
        let padding = (offset - written) as usize;
        w.write_all(&[0u8; 16][..padding]).map_err(io)?;
        written = offset;
        if let Some(level) = compressed.get(p) {
            w.write_all(level).map_err(io)?;
            written += len;
            continue;
        }
        for face in &levels[p] {
            how.encoding.encode_with(face, how.effort, &mut buf);
            w.write_all(&buf).map_err(io)?;
            written += buf.len() as u64;
        }
    }
    Ok(())
}

/// One sample of a Data Format Descriptor: bit offset, bit length, channel type with its
/// qualifiers, sampleLower, sampleUpper.
type Sample = (u32, u32, u32, u32, u32);

/// The Data Format Descriptor of `encoding`'s vkFormat as KTX-Software's `vk2dfd` makes it
/// (`createDFDUnpacked`, `createDFDPacked` and its E5B9G9R9 case, `createDFDCompressed` in
/// dfdutils' `createdfd.c`), which `ktx validate` compares a file's with: `dfdTotalSize`,
/// then one basic block (Khronos Data Format Specification 1.3 §5): vendor 0, type 0,
/// version 2, the colour model (RGBSDA, or BC6H = 133), BT.709 primaries, linear transfer
/// (every encoding here is linear or decoded by the shader), straight alpha, the texel block
/// dimensions minus one (3, 3, 0, 0 for BC6H's 4×4 blocks), bytesPlane0 = the block's bytes
/// (supercompressed or not: KTX 2.0.4, "DFD for Supercompressed Data", has the descriptor
/// keep the pre-deflation images' bytesPlane[0-7], where earlier revisions asked for 0;
/// `ktx validate` warns 6030 on a 0), and the samples:
///
/// - float channels: the FLOAT qualifier (and SIGNED when signed), sampleLower/Upper the
///   bits of −1.0 (or 0.0 when unsigned) and 1.0;
/// - E5B9G9R9: per channel a 9-bit mantissa (lower 0, upper 8448) and the shared 5-bit
///   exponent at bit 27 with the EXPONENT qualifier (lower 15, upper 31);
/// - R8G8B8A8_UNORM: 8 bits a channel, lower 0, upper 255;
/// - BC6H: one 128-bit sample of channel 0 (BC6H colour).
pub(crate) fn data_format_descriptor(encoding: Encoding) -> Vec<u8> {
    const MODEL_RGBSDA: u8 = 1;
    const MODEL_BC6H: u8 = 133;
    const EXPONENT: u32 = 0x20;
    const SIGNED: u32 = 0x40;
    const FLOAT: u32 = 0x80;
    const ALPHA: u32 = 15;
    let one = 1.0f32.to_bits();
    let minus_one = (-1.0f32).to_bits();
    let float4 = |bits: u32| -> Vec<Sample> {
        [0, 1, 2, ALPHA]
            .iter()
            .enumerate()
            .map(|(i, &c)| (i as u32 * bits, bits, c | SIGNED | FLOAT, minus_one, one))
            .collect()
    };
    let (model, dims, samples): (u8, [u8; 4], Vec<Sample>) = match encoding {
        Encoding::Rgba16F => (MODEL_RGBSDA, [0; 4], float4(16)),
        Encoding::Rgba32F => (MODEL_RGBSDA, [0; 4], float4(32)),
        Encoding::Rgb9E5 => (
            MODEL_RGBSDA,
            [0; 4],
            (0..3)
                .flat_map(|c| [(9 * c, 9, c, 0, 8448), (27, 5, c | EXPONENT, 15, 31)])
                .collect(),
        ),
        Encoding::B10G11R11 => (
            MODEL_RGBSDA,
            [0; 4],
            vec![
                (0, 11, FLOAT, 0, one),
                (11, 11, 1 | FLOAT, 0, one),
                (22, 10, 2 | FLOAT, 0, one),
            ],
        ),
        Encoding::Rgbd | Encoding::Rgbm => (
            MODEL_RGBSDA,
            [0; 4],
            [0, 1, 2, ALPHA]
                .iter()
                .enumerate()
                .map(|(i, &c)| (8 * i as u32, 8, c, 0, 255))
                .collect(),
        ),
        Encoding::Bc6hUnsigned => (MODEL_BC6H, [3, 3, 0, 0], vec![(0, 128, FLOAT, 0, one)]),
        Encoding::Bc6hSigned => (
            MODEL_BC6H,
            [3, 3, 0, 0],
            vec![(0, 128, SIGNED | FLOAT, minus_one, one)],
        ),
    };
    let block_size = 24 + 16 * samples.len() as u32;
    let mut out = Vec::with_capacity(4 + block_size as usize);
    out.extend_from_slice(&(4 + block_size).to_le_bytes()); // dfdTotalSize
    out.extend_from_slice(&0u32.to_le_bytes()); // vendorId 0 | descriptorType 0 << 17
    out.extend_from_slice(&(2 | block_size << 16).to_le_bytes()); // version | block size
    out.extend_from_slice(&[model, 1, 1, 0]); // model, BT709, LINEAR, straight alpha
    out.extend_from_slice(&dims); // texelBlockDimension0..3 (stored minus 1)
    let mut planes = [0u8; 8];
    planes[0] = encoding.block_bytes() as u8;
    out.extend_from_slice(&planes); // bytesPlane0..7
    for (offset, bits, channel, lower, upper) in samples {
        let word = offset | (bits - 1) << 16 | channel << 24;
        out.extend_from_slice(&word.to_le_bytes());
        out.extend_from_slice(&[0, 0, 0, 0]); // samplePosition0..3
        out.extend_from_slice(&lower.to_le_bytes());
        out.extend_from_slice(&upper.to_le_bytes());
    }
    out
}

/// Key/value data: each pair as keyAndValueByteLength, key, NUL, value, NUL, padded to 4
/// bytes. `pairs` must be sorted by key (the specification requires code-point order).
pub(crate) fn key_value_data(pairs: &[(&str, &str)]) -> Vec<u8> {
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
pub fn read(input: &Input, limits: &Limits) -> Result<Loaded, Error> {
    let path = input.path();
    let io = |e| Error::io(path, e);
    let invalid = |problem: String| Error::input(path, problem);
    let mut file = input.reader().map_err(io)?;
    let file_len = input.len();

    let mut head = [0u8; HEADER_LEN];
    file.read_exact(&mut head).map_err(io)?;
    if head[..12] != IDENTIFIER {
        return Err(invalid("not a KTX 2.0 file (bad identifier)".into()));
    }
    let header = ktx2::Header::from_bytes(&head)
        .map_err(|e| invalid(format!("invalid KTX2 header: {e}")))?;
    let vk_format = read_u32(&head, 12);
    let scheme = read_u32(&head, 44);

    let format = read_texel_format(path, &header, vk_format)?;
    let zstd = read_supercompression(path, &header, scheme)?;
    let (width, height) = (header.pixel_width, header.pixel_height);
    check_read_shape(path, &header)?;
    let faces = header.face_count;
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
    let (end, level0_raw) = check_level_index(path, &header, &index, format, zstd)?;
    let end = check_sections(path, &header, end, file_len)?;
    let bytes = read_checked_prefix(path, &header, file, end)?;
    let reader = ktx2::Reader::new(bytes.as_slice())
        .map_err(|e| invalid(format!("invalid KTX2 file: {e}")))?;
    let level0 = reader
        .levels()
        .next()
        .ok_or_else(|| invalid("KTX2 file has no mip levels".into()))?;

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
    let format = resolve_8bit_encoding(path, format, &get)?;
    let inflated;
    let level0 = if zstd {
        inflated = inflate_level0(path, level0.data, level0_raw)?;
        &inflated[..]
    } else {
        level0.data
    };

    let mut layers = decode_faces(path, format, level0, width, height, faces)?;

    let levels = mip_phrase(level_count);
    let recorded = crate::recorded(path, get, width, height);
    let (declared, description) = orient_and_describe(&reader, format, &levels, &mut layers);
    Ok(Loaded {
        layers,
        declared,
        recorded,
        format: Format::Ktx2,
        description,
        invalid: None,
    })
}

/// The texel format of a KTX2 file's `vk_format`, or the error that names the formats
/// mirrorball reads. `R8G8B8A8_UNORM` comes back as RGBD; [`resolve_8bit_encoding`] tells
/// RGBD from RGBM once the key/value data is read.
fn read_texel_format(
    path: &Path,
    header: &ktx2::Header,
    vk_format: u32,
) -> Result<TexelFormat, Error> {
    Ok(match vk_format {
        VK_FORMAT_R16G16B16A16_SFLOAT => TexelFormat::Encoded(Encoding::Rgba16F),
        VK_FORMAT_R32G32B32A32_SFLOAT => TexelFormat::Encoded(Encoding::Rgba32F),
        VK_FORMAT_R16G16B16_SFLOAT => TexelFormat::Rgb16F,
        VK_FORMAT_R32G32B32_SFLOAT => TexelFormat::Rgb32F,
        VK_FORMAT_B10G11R11_UFLOAT_PACK32 => TexelFormat::Encoded(Encoding::B10G11R11),
        VK_FORMAT_E5B9G9R9_UFLOAT_PACK32 => TexelFormat::Encoded(Encoding::Rgb9E5),
        VK_FORMAT_BC6H_UFLOAT_BLOCK => TexelFormat::Encoded(Encoding::Bc6hUnsigned),
        VK_FORMAT_BC6H_SFLOAT_BLOCK => TexelFormat::Encoded(Encoding::Bc6hSigned),
        // RGBD or RGBM, told apart by the key/value data once it is read.
        VK_FORMAT_R8G8B8A8_UNORM => TexelFormat::Encoded(Encoding::Rgbd),
        _ => {
            let name = header
                .format
                .map_or("VK_FORMAT_UNDEFINED".to_string(), |f| format!("{f:?}"));
            return Err(Error::input(
                path,
                format!(
                    "unsupported KTX2 format {name} ({vk_format}); mirrorball reads float formats: \
                     RGBA16F, RGBA32F, RGB16F, RGB32F, B10G11R11, E5B9G9R9 and BC6H (and RGBD or \
                     RGBM 8-bit when the file records which)"
                ),
            ));
        }
    })
}

/// Whether the file's levels are Zstandard-compressed (supercompressionScheme 2) rather
/// than plain (0); any other scheme is an error.
fn read_supercompression(path: &Path, header: &ktx2::Header, scheme: u32) -> Result<bool, Error> {
    match scheme {
        0 => Ok(false),
        SUPERCOMPRESSION_ZSTD => Ok(true),
        s => {
            let name = header
                .supercompression_scheme
                .map_or(String::new(), |s| format!("{s:?} "));
            Err(Error::input(
                path,
                format!(
                    "KTX2 supercompression scheme {name}({s}) is not supported; save the file \
                     without supercompression or with Zstandard"
                ),
            ))
        }
    }
}

/// Rejects the texture shapes the reader does not take, in this order: 1D (height 0), 3D
/// (a depth), arrays (a layer count), cube maps with non-square faces and face counts other
/// than 1 or 6.
fn check_read_shape(path: &Path, header: &ktx2::Header) -> Result<(), Error> {
    let invalid = |problem: String| Error::input(path, problem);
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
    match header.face_count {
        1 => Ok(()),
        6 if width == height => Ok(()),
        6 => Err(invalid(format!(
            "KTX2 cube map with non-square faces ({width}×{height})"
        ))),
        n => Err(invalid(format!(
            "invalid KTX2 face count {n} (must be 1 or 6)"
        ))),
    }
}

/// Checks each entry of the level index (`index`, `LEVEL_INDEX_LEN` bytes a level): a
/// level must hold exactly the bytes its faces of `format` call for (uncompressed bytes
/// when `zstd`), and its end must not overflow. Returns the furthest byte the header, the
/// index and the levels reach, and level 0's uncompressed length.
fn check_level_index(
    path: &Path,
    header: &ktx2::Header,
    index: &[u8],
    format: TexelFormat,
    zstd: bool,
) -> Result<(u64, u64), Error> {
    let invalid = |problem: String| Error::input(path, problem);
    let (width, height) = (header.pixel_width, header.pixel_height);
    let faces = header.face_count;
    let level_count = header.level_count.max(1);
    let mut end = (HEADER_LEN + index.len()) as u64;
    let mut level0_raw = 0u64;
    for p in 0..level_count as usize {
        let offset = read_u64(index, p * LEVEL_INDEX_LEN);
        let len = read_u64(index, p * LEVEL_INDEX_LEN + 8);
        let raw = read_u64(index, p * LEVEL_INDEX_LEN + 16);
        let (w, h) = ((width >> p).max(1), (height >> p).max(1));
        let want = u64::from(faces) * format.image_bytes(w, h);
        // Supercompressed levels hold any number of bytes that inflate to exactly the
        // texels; plain ones hold the texels.
        let held = if zstd { raw } else { len };
        if held != want {
            return Err(invalid(format!(
                "mip level {p} holds {held} bytes{}; {} of {w}×{h} {} need {want}",
                if zstd { " uncompressed" } else { "" },
                mirrorball_core::count(u64::from(faces), "face"),
                format.name()
            )));
        }
        if p == 0 {
            level0_raw = want;
        }
        let level_end = offset
            .checked_add(len)
            .ok_or_else(|| invalid(format!("mip level {p} has an impossible offset")))?;
        end = end.max(level_end);
    }
    Ok((end, level0_raw))
}

/// Checks the Data Format Descriptor, key/value data and supercompression global data
/// sections: their size is at most [`MAX_METADATA`], there is no global data, and together
/// with `end` (what the level index reaches) they lie inside the file's `file_len` bytes.
/// Returns the furthest byte any section reaches.
fn check_sections(
    path: &Path,
    header: &ktx2::Header,
    end: u64,
    file_len: u64,
) -> Result<u64, Error> {
    let invalid = |problem: String| Error::input(path, problem);
    let index_fields = &header.index;
    let metadata =
        u64::from(index_fields.dfd_byte_length) + u64::from(index_fields.kvd_byte_length);
    if metadata > MAX_METADATA {
        return Err(invalid(format!(
            "implausibly large KTX2 metadata ({metadata} bytes of descriptor and key/value data)"
        )));
    }
    let end = end
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
    Ok(end)
}

/// Reads the file's first `end` bytes, fails if it has shrunk below them meanwhile, and
/// rejects a Data Format Descriptor the `ktx2` crate would panic on ([`dfd_problem`]).
fn read_checked_prefix(
    path: &Path,
    header: &ktx2::Header,
    mut file: Reader,
    end: u64,
) -> Result<Vec<u8>, Error> {
    let io = |e| Error::io(path, e);
    let invalid = |problem: String| Error::input(path, problem);
    let index_fields = &header.index;
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
    Ok(bytes)
}

/// Tells RGBD from RGBM for `R8G8B8A8_UNORM` data by the value `get` finds under
/// [`ENCODING_KEY`] (an error when it is neither); other formats are returned as they are.
fn resolve_8bit_encoding(
    path: &Path,
    format: TexelFormat,
    get: &impl Fn(&str) -> Option<String>,
) -> Result<TexelFormat, Error> {
    Ok(match format {
        TexelFormat::Encoded(Encoding::Rgbd) => match get(ENCODING_KEY).as_deref() {
            Some("rgbd") => TexelFormat::Encoded(Encoding::Rgbd),
            Some("rgbm") => TexelFormat::Encoded(Encoding::Rgbm),
            other => {
                return Err(Error::input(
                    path,
                    format!(
                        "8-bit KTX2 (R8G8B8A8_UNORM) is read only as RGBD or RGBM, recorded under \
                         {ENCODING_KEY}; this file records {}",
                        other.map_or("nothing".to_string(), |o| format!("'{o}'"))
                    ),
                ))
            }
        },
        f => f,
    })
}

/// Inflates the Zstandard-compressed level 0 (`data`), which must come to exactly
/// `level0_raw` bytes.
fn inflate_level0(path: &Path, data: &[u8], level0_raw: u64) -> Result<Vec<u8>, Error> {
    let invalid = |problem: String| Error::input(path, problem);
    let inflated = zstd::bulk::decompress(data, level0_raw as usize)
        .map_err(|e| invalid(format!("mip level 0 is not valid Zstandard data: {e}")))?;
    if inflated.len() as u64 != level0_raw {
        return Err(invalid(format!(
            "mip level 0 inflates to {} bytes, not the {level0_raw} its index gives",
            inflated.len()
        )));
    }
    Ok(inflated)
}

/// Decodes the `faces` images of `format` (`width`×`height` each) that level 0 holds, in
/// the order they are stored.
fn decode_faces(
    path: &Path,
    format: TexelFormat,
    level0: &[u8],
    width: u32,
    height: u32,
    faces: u32,
) -> Result<Vec<Image>, Error> {
    let face_len = format.image_bytes(width, height) as usize;
    let mut layers = Vec::with_capacity(faces as usize);
    for face in level0.chunks_exact(face_len).take(faces as usize) {
        layers.push(format.decode(face, width, height));
    }
    if layers.len() != faces as usize {
        return Err(Error::input(
            path,
            "mip level 0 is shorter than its faces".into(),
        ));
    }
    Ok(layers)
}

/// The declared projection and the description of what was read. Six layers are a cube
/// map, kept as they are; one is a 2D texture, flipped to top-row-first, left-column-first
/// by its `KTXorientation` (`l…` flips it left to right, `.u` top to bottom).
fn orient_and_describe(
    reader: &ktx2::Reader<&[u8]>,
    format: TexelFormat,
    levels: &str,
    layers: &mut [Image],
) -> (Option<ProjectionKind>, String) {
    if layers.len() == 6 {
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
    }
}
