//! KTX 1.1 cube maps as Filament loads them: its IBL files (`cmgen --deploy` writes
//! `NAME_ibl.ktx`, the specular chain, and `NAME_skybox.ktx`), with the spherical harmonics
//! under the key `sh` (nine lines of `r g b`, cmgen's `iblRoughnessPrefilter`).
//!
//! The layout is the Khronos KTX File Format Specification 1.1's: the 12-byte identifier,
//! endianness `0x04030201`, `glType`, `glTypeSize`, `glFormat`, `glInternalFormat`,
//! `glBaseInternalFormat`, the size, 0 array elements, 6 faces, the level count and the
//! key/value bytes (each pair `keyAndValueByteSize`, key, NUL, value, NUL, padded to 4);
//! then per level, largest first, `imageSize` (one face's bytes, as the specification says
//! for non-array cube maps) and the six faces +X −X +Y −Y +Z −Z, each padded to 4 bytes
//! (cubePadding), the level padded to 4 (mipPadding). Faces are stored as OpenGL reads them,
//! row 0 at `t = 0`, which is mirrorball's row 0, so they are written unchanged.
//!
//! Formats are those Filament's `Ktx1Reader` maps to a texture: R11F_G11F_B10F as cmgen
//! writes it (its `toPixelDataType` knows the packed type only as `glType =
//! GL_R11F_G11F_B10F`, not the specification's `GL_UNSIGNED_INT_10F_11F_11F_REV`, so that
//! is what goes there; `glFormat` and `glBaseInternalFormat` are the unsized `GL_RGB` the
//! specification asks for, which Filament's reader also takes), RGBA16F and RGBA32F.

use crate::ktx2_io::{check_encodable, key_value_data, validate_cube};
use crate::{atomic_write, CubeWrite, Error};
use mirrorball_core::Image;
use mirrorball_encode::Encoding;
use std::io::Write;
use std::path::Path;

/// The KTX 1.1 file identifier, `«KTX 11»\r\n\x1A\n`.
pub(crate) const IDENTIFIER: [u8; 12] = [
    0xAB, 0x4B, 0x54, 0x58, 0x20, 0x31, 0x31, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A,
];

const GL_HALF_FLOAT: u32 = 0x140B;
const GL_FLOAT: u32 = 0x1406;
const GL_RGB: u32 = 0x1907;
const GL_RGBA: u32 = 0x1908;
const GL_RGBA16F: u32 = 0x881A;
const GL_RGBA32F: u32 = 0x8814;
const GL_R11F_G11F_B10F: u32 = 0x8C3A;

/// `glType`, `glTypeSize`, `glFormat`, `glInternalFormat`, `glBaseInternalFormat` of the
/// encodings Filament reads from KTX1 (see the module documentation).
fn gl_format(encoding: Encoding) -> Option<[u32; 5]> {
    Some(match encoding {
        Encoding::B10G11R11 => [GL_R11F_G11F_B10F, 4, GL_RGB, GL_R11F_G11F_B10F, GL_RGB],
        Encoding::Rgba16F => [GL_HALF_FLOAT, 2, GL_RGBA, GL_RGBA16F, GL_RGBA],
        Encoding::Rgba32F => [GL_FLOAT, 4, GL_RGBA, GL_RGBA32F, GL_RGBA],
        _ => return None,
    })
}

/// The `sh` value cmgen writes: one line `r g b` per coefficient, in its order (band l,
/// then m from −l to l), which Filament's `Ktx1Bundle::getSphericalHarmonics` reads back.
/// The coefficients are cmgen's "pre-scaled" irradiance SH, as Filament's shader sums them
/// (`iblSH[i]` times the bare polynomials 1, y, z, x, yx, yz, 3z² − 1, zx, x² − y², giving
/// E/π): each basis constant times the coefficient of E/π, what `mirrorball-bake`'s
/// Filament module makes (`filament::prescaled`, derived there from cmgen's
/// `computeIrradianceSH3Bands`).
pub fn filament_sh_text(sh: &[[f32; 3]]) -> String {
    sh.iter()
        .map(|c| format!("{} {} {}\n", c[0], c[1], c[2]))
        .collect()
}

/// Writes a cube map with its mip chain as KTX 1.1 (see the module documentation), with
/// `how.metadata` as its key/value data (for Filament: `sh`, from [`filament_sh_text`]).
pub fn write_ktx1(path: &Path, levels: &[Vec<Image>], how: &CubeWrite) -> Result<(), Error> {
    let encoding = how.encoding;
    let Some([gl_type, type_size, format, internal, base]) = gl_format(encoding) else {
        return Err(Error::request(
            path,
            format!(
                "KTX1 cube maps are written for Filament, which reads them as B10G11R11, \
                 RGBA16F or RGBA32F, not {}",
                encoding.label()
            ),
        ));
    };
    if how.zstd.is_some() {
        return Err(Error::request(
            path,
            "KTX1 has no supercompression; Zstandard is for KTX2".into(),
        ));
    }
    let size = validate_cube(path, levels)?;
    check_encodable(path, levels, encoding)?;

    // KTX1's key/value data is laid out as KTX2's (KTX2 only adds the order, kept here too).
    let pairs: std::collections::BTreeMap<&str, &str> = how
        .metadata
        .iter()
        .map(|(k, v)| (k.as_str(), v.as_str()))
        .collect();
    let kvd = key_value_data(&pairs.into_iter().collect::<Vec<_>>());
    let mut head = Vec::with_capacity(64 + kvd.len());
    head.extend_from_slice(&IDENTIFIER);
    for v in [
        0x0403_0201, // endianness: written little-endian
        gl_type,
        type_size,
        format,
        internal,
        base,
        size,                // pixelWidth
        size,                // pixelHeight
        0,                   // pixelDepth: not 3D
        0,                   // numberOfArrayElements: not an array
        6,                   // numberOfFaces: cube map
        levels.len() as u32, // numberOfMipmapLevels
        kvd.len() as u32,    // bytesOfKeyValueData
    ] {
        head.extend_from_slice(&u32::to_le_bytes(v));
    }
    head.extend_from_slice(&kvd);

    atomic_write(path, |w| {
        let io = |e| Error::io(path, e);
        w.write_all(&head).map_err(io)?;
        let mut buf = Vec::new();
        for (p, level) in levels.iter().enumerate() {
            let s = (size >> p).max(1);
            let face_bytes = encoding.image_bytes(s, s);
            w.write_all(&(face_bytes as u32).to_le_bytes())
                .map_err(io)?;
            for face in level {
                encoding.encode_with(face, how.effort, &mut buf);
                w.write_all(&buf).map_err(io)?;
                // cubePadding: every encoding here has texels of 4 bytes or more, so faces
                // already end on a multiple of 4, and so do levels (mipPadding).
                debug_assert_eq!(buf.len() % 4, 0);
            }
        }
        Ok(())
    })
}

/// The encoding of a KTX1 file's `glType` and `glInternalFormat`: those [`write_ktx1`]
/// writes (Filament's three).
fn encoding_of(gl_type: u32, internal: u32) -> Option<Encoding> {
    [Encoding::B10G11R11, Encoding::Rgba16F, Encoding::Rgba32F]
        .into_iter()
        .find(|&e| gl_format(e).is_some_and(|f| f[0] == gl_type && f[3] == internal))
}

/// Reads level 0 of a KTX 1.1 cube map as [`write_ktx1`] writes it and Filament's
/// `Ktx1Reader` reads it (B10G11R11, RGBA16F or RGBA32F, six faces, little-endian): the six
/// faces, declared a cube; every declared size checked against the file's length and
/// `limits` before anything is allocated.
pub fn read(input: &crate::input::Input, limits: &crate::Limits) -> Result<crate::Loaded, Error> {
    let path = input.path();
    let bytes = input.all().map_err(|e| Error::io(path, e))?;
    let bad = |p: String| Error::input(path, p);
    const HEAD: usize = 12 + 13 * 4;
    if bytes.len() < HEAD || bytes[..12] != IDENTIFIER {
        return Err(bad("not a KTX 1.1 file (bad identifier)".into()));
    }
    let word = |i: usize| u32::from_le_bytes(bytes[12 + 4 * i..16 + 4 * i].try_into().unwrap());
    if word(0) != 0x0403_0201 {
        return Err(bad(
            "a big-endian KTX1 file; mirrorball reads little-endian ones, as cmgen writes".into(),
        ));
    }
    let (gl_type, internal) = (word(1), word(4));
    let encoding = encoding_of(gl_type, internal).ok_or_else(|| {
        bad(format!(
            "KTX1 glType 0x{gl_type:04X}, glInternalFormat 0x{internal:04X}; mirrorball reads \
             Filament's R11F_G11F_B10F, RGBA16F and RGBA32F"
        ))
    })?;
    let (w, h, depth, array, faces, levels, kvd) = (
        word(6),
        word(7),
        word(8),
        word(9),
        word(10),
        word(11),
        word(12),
    );
    if faces != 6 || w != h || w == 0 || depth != 0 || array != 0 {
        return Err(bad(format!(
            "a KTX1 texture of {faces} faces, {w}×{h}×{depth}, {array} array elements; \
             mirrorball reads cube maps (six square faces)"
        )));
    }
    crate::ktx2_io::check_limits(path, w, h, limits)?;
    let kvd_end = HEAD
        .checked_add(kvd as usize)
        .filter(|&e| e <= bytes.len())
        .ok_or_else(|| bad(format!("{kvd} bytes of key/value data past the file's end")))?;
    // Key/value pairs: a size, then key NUL value, padded to 4.
    let mut pairs = Vec::new();
    let mut at = HEAD;
    while at + 4 <= kvd_end {
        let n = u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
        let Some(pair) = bytes
            .get(at + 4..at + 4 + n)
            .filter(|_| at + 4 + n <= kvd_end)
        else {
            return Err(bad("a key/value pair runs past the key/value data".into()));
        };
        if let Some(nul) = pair.iter().position(|&b| b == 0) {
            let key = String::from_utf8_lossy(&pair[..nul]).into_owned();
            let value = String::from_utf8_lossy(&pair[nul + 1..])
                .trim_end_matches('\0')
                .to_string();
            pairs.push((key, value));
        }
        at += 4 + n.div_ceil(4) * 4;
    }
    let face_bytes = encoding.image_bytes(w, w);
    let level0 = kvd_end + 4;
    let image_size = bytes
        .get(kvd_end..level0)
        .map(|b| u32::from_le_bytes(b.try_into().unwrap()) as usize)
        .ok_or_else(|| bad("the file ends before its first level".into()))?;
    if image_size != face_bytes {
        return Err(bad(format!(
            "level 0's imageSize is {image_size}; a {w}×{w} {} face takes {face_bytes}",
            encoding.label()
        )));
    }
    if level0 + 6 * face_bytes > bytes.len() {
        return Err(bad(format!(
            "the file is truncated: level 0's six faces need {} bytes, {} are left",
            6 * face_bytes,
            bytes.len() - level0
        )));
    }
    let layers = (0..6)
        .map(|f| {
            let start = level0 + f * face_bytes;
            encoding.decode(&bytes[start..start + face_bytes], w, w)
        })
        .collect();
    let get = |key: &str| pairs.iter().find(|(k, _)| k == key).map(|(_, v)| v.clone());
    let sh = if get("sh").is_some() {
        ", spherical harmonics"
    } else {
        ""
    };
    Ok(crate::Loaded {
        layers,
        declared: Some(mirrorball_core::ProjectionKind::Cube),
        recorded: crate::recorded(path, get, w, w),
        format: crate::Format::Ktx1,
        description: format!(
            "KTX1 cube map (Filament), {}, {}{sh}",
            encoding.label(),
            mirrorball_core::count(u64::from(levels.max(1)), "mip level")
        ),
        invalid: None,
    })
}
