//! DirectDraw Surface cube maps, with the headers of the `ddsfile` crate.
//!
//! Written files have the DX10 extension header: `DXGI_FORMAT_R16G16B16A16_FLOAT`,
//! `DXGI_FORMAT_R32G32B32A32_FLOAT`, `DXGI_FORMAT_R9G9B9E5_SHAREDEXP`,
//! `DXGI_FORMAT_R11G11B10_FLOAT` (the same bits as Vulkan's B10G11R11: R lowest),
//! `DXGI_FORMAT_BC6H_UF16` or `DXGI_FORMAT_BC6H_SF16` (4×4 blocks, small mips padded to one
//! block), `D3D10_RESOURCE_MISC_TEXTURECUBE` with an array size of
//! 1 (one cube; Direct3D counts cubes, not faces, there), `DDSCAPS2_CUBEMAP` with all six face
//! bits, and the mip count. The data is face-major: face 0 (+X) with its whole mip chain,
//! then face 1 (−X) and so on, in Direct3D's face order +X −X +Y −Y +Z −Z, which is
//! OpenGL's.
//!
//! Direct3D selects cube faces with the same major-axis table as OpenGL and addresses each
//! face with row 0 at the top (v = 0), which is mirrorball's `t = 0` row, so face images are
//! stored unchanged, exactly as in KTX2.
//!
//! DDS has no place for text, so the projection is not recorded (a DDS cube is a cube by its
//! header's cube-map flags).
//!
//! The reader takes level 0 of DX10 RGBA16F, RGBA32F, RGB32F, R11G11B10F, RGB9E5 and BC6H files and
//! of legacy `D3DFMT_A16B16G16R16F` (113) and `D3DFMT_A32B32G32R32F` (116) files, cube maps or
//! 2D textures. It parses the headers with `ddsfile`, checks the declared size against the
//! [`Limits`] and the file length, and only then reads the texels it needs.

use crate::atomic::{Dest, Written};
use crate::input::{Input, Reader};
use crate::ktx2_io::{
    check_encodable, check_limits, max_levels, mip_phrase, validate_cube, written_format,
    TexelFormat,
};
use crate::{CubeWrite, Error, Format, Limits, Loaded, WriteOptions};
use ddsfile::{
    AlphaMode, Caps2, D3D10ResourceDimension, DxgiFormat, FourCC, Header, Header10, MiscFlag,
    PixelFormat, PixelFormatFlags,
};
use mirrorball_core::{Image, ProjectionKind};
use mirrorball_encode::Encoding;
use std::io::Read;
use std::path::Path;

/// `"DDS "`, the magic number at the start of every DDS file.
const MAGIC: &[u8; 4] = b"DDS ";
/// Magic plus the 124-byte header.
const HEADER_LEN: u64 = 4 + 124;
/// The DX10 extension header.
const HEADER10_LEN: u64 = 20;

fn dds_error(path: &Path, e: ddsfile::Error) -> Error {
    match e {
        ddsfile::Error::Io(e) => Error::io(path, e),
        e => Error::input(path, format!("invalid DDS header: {e}")),
    }
}

/// Writes a cube map with its mip chain as DDS with a DX10 header, RGBA16F or RGBA32F as
/// `opts` asks; see [`write_dds`].
pub fn write(dest: Dest, levels: &[Vec<Image>], opts: &WriteOptions) -> Result<Written, Error> {
    let encoding = written_format(dest.path(), opts, "DDS")?;
    encode(
        dest,
        levels,
        &CubeWrite {
            encoding,
            ..CubeWrite::default()
        },
    )
}

/// Writes a cube map with its mip chain as DDS with a DX10 header in `how.encoding`,
/// face-major (each face with its whole mip chain). Face images are stored unchanged:
/// Direct3D uses OpenGL's face order and major-axis table and puts row 0 at the top,
/// mirrorball's `t = 0` row. DDS has no supercompression and no place for RGBD's or RGBM's
/// record, so those are refused.
pub fn write_dds(path: &Path, levels: &[Vec<Image>], how: &CubeWrite) -> Result<(), Error> {
    encode(Dest::File(path), levels, how)?.land().map(|_| ())
}

/// [`write_dds`] into `dest`.
fn encode(dest: Dest, levels: &[Vec<Image>], how: &CubeWrite) -> Result<Written, Error> {
    let path = dest.path();
    let encoding = how.encoding;
    let dxgi = match encoding {
        Encoding::Rgba16F => DxgiFormat::R16G16B16A16_Float,
        Encoding::Rgba32F => DxgiFormat::R32G32B32A32_Float,
        Encoding::Rgb9E5 => DxgiFormat::R9G9B9E5_SharedExp,
        Encoding::B10G11R11 => DxgiFormat::R11G11B10_Float,
        Encoding::Bc6hUnsigned => DxgiFormat::BC6H_UF16,
        Encoding::Bc6hSigned => DxgiFormat::BC6H_SF16,
        Encoding::Rgbd | Encoding::Rgbm => {
            return Err(Error::request(
                path,
                format!(
                    "DDS has no place to record that its 8-bit texels are {}; write KTX2",
                    encoding.label()
                ),
            ))
        }
    };
    if how.zstd.is_some() {
        return Err(Error::request(
            path,
            "DDS has no supercompression; Zstandard is for KTX2".into(),
        ));
    }
    let size = validate_cube(path, levels)?;
    check_encodable(path, levels, encoding)?;
    let mut header = Header::new_dxgi(
        size,
        size,
        None,
        dxgi,
        Some(levels.len() as u32),
        Some(6),
        Some(Caps2::CUBEMAP | Caps2::CUBEMAP_ALLFACES),
    )
    .map_err(|e| Error::request(path, format!("cannot make a DDS header: {e}")))?;
    // With a DX10 header the pixel format is only the "DX10" FourCC (as Direct3D's own
    // writers have it), not also an RGB bit count.
    header.spf = PixelFormat {
        flags: PixelFormatFlags::FOURCC,
        fourcc: Some(FourCC(FourCC::DX10)),
        ..PixelFormat::default()
    };
    let header10 = Header10::new(
        dxgi,
        true,
        D3D10ResourceDimension::Texture2D,
        1,
        AlphaMode::Unknown,
    );

    dest.emit(|mut w| {
        w.write_all(MAGIC).map_err(|e| Error::io(path, e))?;
        header.write(&mut w).map_err(|e| dds_error(path, e))?;
        header10.write(&mut w).map_err(|e| dds_error(path, e))?;
        let mut buf = Vec::new();
        for face in 0..6 {
            for level in levels {
                encoding.encode_with(&level[face], how.effort, &mut buf);
                w.write_all(&buf).map_err(|e| Error::io(path, e))?;
            }
        }
        Ok(())
    })
}

/// Reads level 0 of a DDS cube map (the six faces, declared cube) or 2D texture (one flat
/// image). See the module documentation for the formats.
pub fn read(input: &Input, limits: &Limits) -> Result<Loaded, Error> {
    let path = input.path();
    let io = |e| Error::io(path, e);
    let invalid = |problem: String| Error::input(path, problem);
    let file_len = input.len();
    let mut r = input.reader().map_err(io)?;

    let mut magic = [0u8; 4];
    r.read_exact(&mut magic).map_err(io)?;
    if &magic != MAGIC {
        return Err(invalid("not a DDS file (bad magic number)".into()));
    }
    let header = Header::read(&mut r).map_err(|e| dds_error(path, e))?;
    let header10 = match header.spf.fourcc {
        Some(FourCC(FourCC::DX10)) => Some(Header10::read(&mut r).map_err(|e| dds_error(path, e))?),
        _ => None,
    };

    let (format, cube, kind) = match &header10 {
        Some(h10) => dx10_format(path, h10)?,
        None => legacy_format(path, &header)?,
    };
    let mips = check_dds_shape(path, &header, cube, limits)?;
    let (width, height) = (header.width, header.height);

    // Each face (array layer) holds its whole mip chain; check the file holds them all.
    let level0 = format.image_bytes(width, height);
    let chain: u64 = (0..mips)
        .map(|p| format.image_bytes((width >> p).max(1), (height >> p).max(1)))
        .sum();
    let faces: u64 = if cube { 6 } else { 1 };
    let data_start = HEADER_LEN + if header10.is_some() { HEADER10_LEN } else { 0 };
    let need = data_start + faces * chain;
    if file_len < need {
        return Err(invalid(format!(
            "file is truncated: its header declares {need} bytes, but the file has {file_len}"
        )));
    }

    let layers = read_faces(path, &mut r, format, (width, height), faces, level0, chain)?;

    let levels = mip_phrase(mips);
    let (declared, description) = if cube {
        (
            Some(ProjectionKind::Cube),
            format!("DDS cube map ({kind}), {}, {levels}", format.name()),
        )
    } else {
        (
            None,
            format!("DDS 2D texture ({kind}), {}, {levels}", format.name()),
        )
    };
    Ok(Loaded {
        layers,
        declared,
        recorded: None,
        format: Format::Dds,
        description,
        invalid: None,
    })
}

/// The texel format a DX10 extended header declares, whether it is a cube map, and the
/// header kind for the description (`"DX10"`). Only 2D textures and cube maps, not arrays,
/// are read.
fn dx10_format(path: &Path, h10: &Header10) -> Result<(TexelFormat, bool, &'static str), Error> {
    let invalid = |problem: String| Error::input(path, problem);
    let format = match h10.dxgi_format {
        DxgiFormat::R16G16B16A16_Float => TexelFormat::Encoded(Encoding::Rgba16F),
        DxgiFormat::R32G32B32A32_Float => TexelFormat::Encoded(Encoding::Rgba32F),
        DxgiFormat::R32G32B32_Float => TexelFormat::Rgb32F,
        DxgiFormat::R11G11B10_Float => TexelFormat::Encoded(Encoding::B10G11R11),
        DxgiFormat::R9G9B9E5_SharedExp => TexelFormat::Encoded(Encoding::Rgb9E5),
        DxgiFormat::BC6H_UF16 => TexelFormat::Encoded(Encoding::Bc6hUnsigned),
        DxgiFormat::BC6H_SF16 => TexelFormat::Encoded(Encoding::Bc6hSigned),
        other => return Err(unsupported_format(path, &format!("{other:?}"))),
    };
    if h10.resource_dimension != D3D10ResourceDimension::Texture2D {
        return Err(invalid(format!(
            "DDS {:?} resources are not supported (only 2D textures and cube maps)",
            h10.resource_dimension
        )));
    }
    let cube = h10.misc_flag.contains(MiscFlag::TEXTURECUBE);
    if h10.array_size > 1 {
        return Err(invalid(format!(
            "DDS {} arrays ({} elements) are not supported",
            if cube { "cube-map" } else { "texture" },
            h10.array_size
        )));
    }
    Ok((format, cube, "DX10"))
}

/// The texel format a legacy header's FourCC declares (RGBA16F or RGBA32F), whether it is a
/// cube map (which must have all six faces), and the header kind for the description
/// (`"legacy header"`).
fn legacy_format(path: &Path, header: &Header) -> Result<(TexelFormat, bool, &'static str), Error> {
    let format = match header.spf.fourcc {
        Some(FourCC(FourCC::A16B16G16R16F)) => TexelFormat::Encoded(Encoding::Rgba16F),
        Some(FourCC(FourCC::A32B32G32R32F)) => TexelFormat::Encoded(Encoding::Rgba32F),
        Some(FourCC(code)) => {
            return Err(unsupported_format(path, &format!("FourCC {code:#010x}")))
        }
        None => return Err(unsupported_format(path, "uncompressed integer (bit masks)")),
    };
    let cube = header.caps2.contains(Caps2::CUBEMAP);
    if cube && !header.caps2.contains(Caps2::CUBEMAP_ALLFACES) {
        return Err(Error::input(
            path,
            "DDS cube map without all six faces is not supported".into(),
        ));
    }
    Ok((format, cube, "legacy header"))
}

/// Checks the header's shape, in this order: not a volume texture, not empty, square when
/// a `cube` map, within the `limits`, and no more mip levels than its size has. Returns the
/// number of mip levels (at least 1).
fn check_dds_shape(
    path: &Path,
    header: &Header,
    cube: bool,
    limits: &Limits,
) -> Result<u32, Error> {
    let invalid = |problem: String| Error::input(path, problem);
    if header.caps2.contains(Caps2::VOLUME) || header.depth.unwrap_or(1) > 1 {
        return Err(invalid("DDS volume textures are not supported".into()));
    }
    let (width, height) = (header.width, header.height);
    if width == 0 || height == 0 {
        return Err(invalid(format!(
            "DDS texture declares an empty size {width}×{height}"
        )));
    }
    if cube && width != height {
        return Err(invalid(format!(
            "DDS cube map with non-square faces ({width}×{height})"
        )));
    }
    check_limits(path, width, height, limits)?;
    let mips = header.mip_map_count.unwrap_or(1).max(1);
    if mips > max_levels(width, height) {
        return Err(invalid(format!(
            "{mips} mip levels declared for a {width}×{height} texture, which has at most {}",
            max_levels(width, height)
        )));
    }
    Ok(mips)
}

/// Reads and decodes level 0 (`level0` bytes, `width`×`height` texels of `format`) of each
/// of the `faces` faces, skipping the rest of each face's mip chain (`chain` bytes a face in
/// all) to the next.
fn read_faces(
    path: &Path,
    r: &mut Reader,
    format: TexelFormat,
    (width, height): (u32, u32),
    faces: u64,
    level0: u64,
    chain: u64,
) -> Result<Vec<Image>, Error> {
    let io = |e| Error::io(path, e);
    let mut layers = Vec::with_capacity(faces as usize);
    let mut bytes = vec![0u8; level0 as usize];
    for face in 0..faces {
        r.read_exact(&mut bytes).map_err(io)?;
        layers.push(format.decode(&bytes, width, height));
        if face + 1 < faces {
            // Skip this face's smaller mips (bounded by the file length checked above).
            r.seek_relative((chain - level0) as i64).map_err(io)?;
        }
    }
    Ok(layers)
}

fn unsupported_format(path: &Path, what: &str) -> Error {
    Error::input(
        path,
        format!(
            "unsupported DDS pixel format {what}; mirrorball reads float formats: RGBA16F, \
             RGBA32F, RGB32F, R11G11B10F, RGB9E5 and BC6H"
        ),
    )
}
