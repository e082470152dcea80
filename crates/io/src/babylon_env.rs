//! Babylon.js's `.env` environment files, as its own writer and reader make and take them
//! (`Misc/environmentTextureTools.pure.js` in `@babylonjs/core` 9.35: `CreateEnvTextureAsync`,
//! `GetEnvInfo`, `CreateRadianceImageDataArrayBufferViews`, `UploadEnvSpherical`):
//!
//! - the eight magic bytes `86 16 87 96 F6 D6 96 36`;
//! - a JSON manifest, ASCII, ended by one NUL byte: `version` 2, `width` (level 0's face
//!   edge, a power of two), `imageType` (`"image/png"`), `irradiance` (the spherical
//!   polynomial: `x y z xx yy zz yz zx xy`, three numbers each) and `specular`
//!   (`mipmaps`: `{position, length}` of each image, level by level, faces +X −X +Y −Y +Z −Z
//!   within a level, positions counted from the first byte after the NUL;
//!   `lodGenerationScale`);
//! - the images, PNG, in that order. The reader asks for exactly `log2(width) + 1` levels
//!   (`6·levels` images), down to 1×1.
//!
//! What the texels mean (RGBD, the face orientation, the roughness of each level) is the
//! engine's business: `mirrorball-bake`'s `babylon.rs`.

use crate::rgba_png::{self, Rgba8Face};
use crate::{atomic_write, Error};
use serde_json::{json, Value};
use std::io::Write;
use std::path::Path;

/// The file's first eight bytes (`MagicBytes`).
pub const MAGIC: [u8; 8] = [0x86, 0x16, 0x87, 0x96, 0xf6, 0xd6, 0x96, 0x36];

/// The spherical polynomial's nine terms, in the manifest's order (`CreateEnvTextureIrradiance`).
pub const POLYNOMIAL_TERMS: [&str; 9] = ["x", "y", "z", "xx", "yy", "zz", "yz", "zx", "xy"];

/// The contents of a `.env` file.
#[derive(Clone, Debug, PartialEq)]
pub struct BabylonEnv {
    /// The spherical polynomial, `[term][channel]` in [`POLYNOMIAL_TERMS`]' order.
    pub polynomial: [[f64; 3]; 9],
    /// `specular.lodGenerationScale`.
    pub lod_generation_scale: f64,
    /// The specular levels, level 0 first, each six faces +X −X +Y −Y +Z −Z, as the PNG
    /// images hold them; level `i`'s edge is level 0's `>> i`, down to 1.
    pub levels: Vec<[Rgba8Face; 6]>,
}

/// Writes `env` to `path` (atomically).
pub fn write_babylon_env(path: &Path, env: &BabylonEnv) -> Result<(), Error> {
    let width = check_levels(path, &env.levels)?;
    if !env.lod_generation_scale.is_finite() || env.lod_generation_scale <= 0.0 {
        return Err(Error::request(
            path,
            format!(
                "lodGenerationScale must be positive, not {}",
                env.lod_generation_scale
            ),
        ));
    }
    let mut images = Vec::with_capacity(env.levels.len() * 6);
    for level in &env.levels {
        for face in level {
            images.push(rgba_png::encode(path, face)?);
        }
    }
    let mut position = 0usize;
    let mipmaps: Vec<Value> = images
        .iter()
        .map(|png| {
            let entry = json!({ "position": position, "length": png.len() });
            position += png.len();
            entry
        })
        .collect();
    let mut irradiance = serde_json::Map::new();
    for (term, c) in POLYNOMIAL_TERMS.iter().zip(&env.polynomial) {
        irradiance.insert((*term).into(), json!(c));
    }
    let manifest = json!({
        "version": 2,
        "width": width,
        "imageType": "image/png",
        "irradiance": irradiance,
        "specular": { "mipmaps": mipmaps, "lodGenerationScale": env.lod_generation_scale },
    });
    let text = manifest.to_string();
    atomic_write(path, |w| {
        let io = |e| Error::io(path, e);
        w.write_all(&MAGIC).map_err(io)?;
        w.write_all(text.as_bytes()).map_err(io)?;
        w.write_all(&[0]).map_err(io)?;
        for png in &images {
            w.write_all(png).map_err(io)?;
        }
        Ok(())
    })
}

/// Reads a `.env` file as Babylon's reader does, refusing what it would refuse (the magic,
/// a version above 2, a level count other than `log2(width) + 1`, images outside the file)
/// and images that are not RGBA 8-bit PNGs of their level's size.
pub fn read_babylon_env(path: &Path) -> Result<BabylonEnv, Error> {
    Error::check_input(path)?;
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    env_from_bytes(path, &bytes)
}

/// [`read_babylon_env`] of a file's `bytes`, called `path` in messages.
fn env_from_bytes(path: &Path, bytes: &[u8]) -> Result<BabylonEnv, Error> {
    let bad = |p: String| Error::input(path, p);
    if bytes.len() < MAGIC.len() || bytes[..MAGIC.len()] != MAGIC {
        return Err(bad(
            "not a Babylon.js environment file (no .env magic)".into()
        ));
    }
    let rest = &bytes[MAGIC.len()..];
    let nul = rest
        .iter()
        .position(|&b| b == 0)
        .ok_or_else(|| bad("the JSON manifest has no NUL end".into()))?;
    let manifest: Value =
        serde_json::from_slice(&rest[..nul]).map_err(|e| bad(format!("the JSON manifest: {e}")))?;
    let payload = &rest[nul + 1..];
    let version = manifest["version"].as_u64().unwrap_or(1);
    if version > 2 {
        return Err(bad(format!("version {version}; Babylon reads up to 2")));
    }
    if let Some(t) = manifest["imageType"].as_str() {
        if t != "image/png" {
            return Err(bad(format!("imageType {t}; only image/png is read")));
        }
    }
    let width = manifest["width"]
        .as_u64()
        .filter(|w| w.is_power_of_two() && *w <= 1 << 16)
        .ok_or_else(|| bad("width is not a power of two up to 65536".into()))?
        as u32;
    let n = width.trailing_zeros() as usize + 1;
    let mipmaps = manifest["specular"]["mipmaps"]
        .as_array()
        .ok_or_else(|| bad("no specular.mipmaps".into()))?;
    if mipmaps.len() != 6 * n {
        return Err(bad(format!(
            "{} specular images; a {width}² cube down to 1×1 has {}",
            mipmaps.len(),
            6 * n
        )));
    }
    let lod_generation_scale = manifest["specular"]["lodGenerationScale"]
        .as_f64()
        .unwrap_or(0.8);
    let mut polynomial = [[0.0; 3]; 9];
    for (term, out) in POLYNOMIAL_TERMS.iter().zip(&mut polynomial) {
        let v = manifest["irradiance"][term]
            .as_array()
            .filter(|a| a.len() == 3)
            .ok_or_else(|| bad(format!("irradiance.{term} is not three numbers")))?;
        for (o, x) in out.iter_mut().zip(v) {
            *o = x
                .as_f64()
                .ok_or_else(|| bad(format!("irradiance.{term}: not a number")))?;
        }
    }
    let mut levels = Vec::with_capacity(n);
    for level in 0..n {
        let size = (width >> level).max(1);
        let face = |f: usize| -> Result<Rgba8Face, Error> {
            let entry = &mipmaps[level * 6 + f];
            let (pos, len) = (entry["position"].as_u64(), entry["length"].as_u64());
            let (Some(pos), Some(len)) = (pos, len) else {
                return Err(bad(format!("mipmap {}: no position/length", level * 6 + f)));
            };
            let end = pos.checked_add(len).filter(|&e| e <= payload.len() as u64);
            let Some(end) = end else {
                return Err(bad(format!(
                    "level {level} face {f} lies outside the file ({pos}+{len} > {})",
                    payload.len()
                )));
            };
            let what = format!("level {level} face {f}");
            rgba_png::decode(path, &payload[pos as usize..end as usize], size, &what)
        };
        levels.push([face(0)?, face(1)?, face(2)?, face(3)?, face(4)?, face(5)?]);
    }
    Ok(BabylonEnv {
        polynomial,
        lod_generation_scale,
        levels,
    })
}

/// The cube's level-0 edge, after checking that `levels` is a whole chain of square faces
/// down to 1×1, as Babylon's reader asks.
pub(crate) fn check_levels(path: &Path, levels: &[[Rgba8Face; 6]]) -> Result<u32, Error> {
    let Some(first) = levels.first() else {
        return Err(Error::request(path, "no levels to write".into()));
    };
    let width = first[0].size;
    if !width.is_power_of_two() {
        return Err(Error::request(
            path,
            format!("the face edge {width} is not a power of two"),
        ));
    }
    check_faces(path, levels, width)?;
    let n = width.trailing_zeros() as usize + 1;
    if levels.len() != n {
        return Err(Error::request(
            path,
            format!(
                "{} levels; Babylon reads a {width}² cube's whole chain, {n} levels",
                levels.len()
            ),
        ));
    }
    Ok(width)
}

/// Checks that level `i`'s faces are `width >> i` square with their bytes.
pub(crate) fn check_faces(path: &Path, levels: &[[Rgba8Face; 6]], width: u32) -> Result<(), Error> {
    for (i, level) in levels.iter().enumerate() {
        let size = (width >> i).max(1);
        for (f, face) in level.iter().enumerate() {
            if face.size != size || face.texels.len() != (size * size * 4) as usize {
                return Err(Error::request(
                    path,
                    format!("level {i} face {f} is not {size}×{size} RGBA8"),
                ));
            }
        }
    }
    Ok(())
}

/// Level 0 of a bundle's specular cube (`.env`, or a glTF light's images): its six faces
/// decoded from RGBD (each face as the PNG holds it, in the engine's axes), declared a cube.
pub(crate) fn cube_loaded(
    path: &Path,
    levels: &[[Rgba8Face; 6]],
    limits: &crate::Limits,
    format: crate::Format,
    what: &str,
) -> Result<crate::Loaded, Error> {
    let level0 = levels
        .first()
        .ok_or_else(|| Error::input(path, "no specular levels".into()))?;
    let n = level0[0].size;
    crate::ktx2_io::check_limits(path, n, n, limits)?;
    let layers = level0
        .iter()
        .map(|f| mirrorball_encode::Encoding::Rgbd.decode(&f.texels, f.size, f.size))
        .collect();
    Ok(crate::Loaded {
        layers,
        declared: Some(mirrorball_core::ProjectionKind::Cube),
        recorded: None,
        format,
        description: format!(
            "{what}, RGBD 8-bit PNG faces, {} (level 0 read)",
            mirrorball_core::count(levels.len() as u64, "mip level")
        ),
        invalid: None,
    })
}

/// [`read_babylon_env`]'s level 0, for [`crate::read`].
pub(crate) fn read(
    input: &crate::input::Input,
    limits: &crate::Limits,
) -> Result<crate::Loaded, Error> {
    let path = input.path();
    let bytes = input.all().map_err(|e| Error::io(path, e))?;
    let env = env_from_bytes(path, &bytes)?;
    cube_loaded(
        path,
        &env.levels,
        limits,
        crate::Format::BabylonEnv,
        "Babylon.js environment (.env)",
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chain(width: u32) -> Vec<[Rgba8Face; 6]> {
        let n = width.trailing_zeros() + 1;
        (0..n)
            .map(|i| {
                let size = width >> i;
                std::array::from_fn(|f| Rgba8Face {
                    size,
                    texels: (0..size * size * 4)
                        .map(|b| (b as usize * 7 + f) as u8)
                        .collect(),
                })
            })
            .collect()
    }

    #[test]
    fn a_written_env_reads_back_and_damaged_ones_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.env");
        let env = BabylonEnv {
            polynomial: std::array::from_fn(|i| [i as f64, 0.5, -0.25]),
            lod_generation_scale: 0.8,
            levels: chain(8),
        };
        write_babylon_env(&path, &env).unwrap();
        assert_eq!(read_babylon_env(&path).unwrap(), env);
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(bytes[..8], MAGIC);

        let damaged = |b: &[u8], says: &str| {
            let p = dir.path().join("b.env");
            std::fs::write(&p, b).unwrap();
            let e = read_babylon_env(&p).unwrap_err();
            assert_eq!(e.fault(), crate::Fault::Input);
            assert!(e.problem().contains(says), "{e}");
        };
        let mut no_magic = bytes.clone();
        no_magic[0] ^= 1;
        damaged(&no_magic, "magic");
        damaged(&bytes[..bytes.len() - 10], "outside the file");
        let key = b"\"width\":8";
        let at = bytes.windows(key.len()).position(|w| w == key).unwrap();
        let mut narrower = bytes.clone();
        narrower[at + key.len() - 1] = b'4';
        damaged(&narrower, "specular images");

        // A chain that stops short is refused before anything is written.
        let short = BabylonEnv {
            levels: chain(8)[..2].to_vec(),
            ..env
        };
        let e = write_babylon_env(&dir.path().join("c.env"), &short).unwrap_err();
        assert_eq!(e.fault(), crate::Fault::Request);
        assert!(!dir.path().join("c.env").exists());
    }
}
