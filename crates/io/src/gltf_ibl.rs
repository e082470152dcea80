//! glTF 2.0 files holding one image-based light of the `EXT_lights_image_based` extension
//! (KhronosGroup/glTF, `extensions/2.0/Vendor/EXT_lights_image_based/README.md` and its
//! `schema/light.schema.json`): a `.gltf` (JSON) whose root `extensions` hold the light —
//! `intensity`, `rotation` (a quaternion, x y z w), `irradianceCoefficients` (9×3),
//! `specularImageSize` (level 0's edge) and `specularImages` (N×6 image indices, level 0
//! first, faces +X −X +Y −Y +Z −Z) — with the default scene referencing it
//! (`scenes[0].extensions.EXT_lights_image_based.light = 0`), and one PNG file per face per
//! level beside it (RGBA 8-bit: a four-channel PNG is RGBD, the README's "HDR Images").
//!
//! What the coefficients and texels mean (the SH basis, RGBD, face orientation, each
//! level's roughness) is the engine's business: `mirrorball-bake`'s `gltf.rs`.

use crate::babylon_env::check_faces;
use crate::rgba_png::{self, Rgba8Face};
use crate::{atomic_write, Error};
use serde_json::{json, Value};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The extension's name.
pub const EXTENSION: &str = "EXT_lights_image_based";

/// The faces' names in the images' file names, in the extension's face order.
const FACE_NAMES: [&str; 6] = ["px", "nx", "py", "ny", "pz", "nz"];

/// One `EXT_lights_image_based` light with its images.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfIbl {
    /// The light's `name`.
    pub name: String,
    /// `intensity`.
    pub intensity: f64,
    /// `rotation`, a unit quaternion `[x, y, z, w]`.
    pub rotation: [f64; 4],
    /// `irradianceCoefficients`, `[coefficient][channel]`.
    pub irradiance_coefficients: [[f64; 3]; 9],
    /// The specular levels, level 0 first (its edge is `specularImageSize`), each level's
    /// edge half the one before; six faces each, as the PNG images hold them.
    pub levels: Vec<[Rgba8Face; 6]>,
}

/// Writes `ibl` as the glTF file `path` (`NAME.gltf`) and its images beside it
/// (`NAME_specular_LEVEL_FACE.png`, FACE one of px nx py ny pz nz); returns the files
/// written, the `.gltf` last.
pub fn write_gltf_ibl(path: &Path, ibl: &GltfIbl) -> Result<Vec<PathBuf>, Error> {
    let Some(first) = ibl.levels.first() else {
        return Err(Error::request(path, "no specular levels to write".into()));
    };
    let size = first[0].size;
    if !size.is_power_of_two() || ibl.levels.len() > size.trailing_zeros() as usize + 1 {
        return Err(Error::request(
            path,
            format!(
                "{} levels of a {size}² cube: the extension asks for a power-of-two edge, \
                 halved per level",
                ibl.levels.len()
            ),
        ));
    }
    check_faces(path, &ibl.levels, size)?;
    let norm = ibl.rotation.iter().map(|q| q * q).sum::<f64>().sqrt();
    if (norm - 1.0).abs() > 1e-6 || !(ibl.intensity >= 0.0 && ibl.intensity.is_finite()) {
        return Err(Error::request(
            path,
            "the light's rotation must be a unit quaternion and its intensity ≥ 0".into(),
        ));
    }
    let stem = path
        .file_stem()
        .and_then(|s| s.to_str())
        .ok_or_else(|| Error::request(path, "the glTF file needs a UTF-8 name".into()))?;
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut written = Vec::new();
    let mut images = Vec::new();
    let mut specular = Vec::new();
    for (level, faces) in ibl.levels.iter().enumerate() {
        let mut indices = Vec::new();
        for (face, name) in faces.iter().zip(FACE_NAMES) {
            let uri = format!("{stem}_specular_{level}_{name}.png");
            let file = dir.join(&uri);
            let png = rgba_png::encode(&file, face)?;
            atomic_write(&file, |w| {
                w.write_all(&png).map_err(|e| Error::io(&file, e))
            })?;
            written.push(file);
            indices.push(images.len());
            images.push(json!({ "uri": uri, "mimeType": "image/png" }));
        }
        specular.push(indices);
    }
    let gltf = json!({
        "asset": { "version": "2.0", "generator": "mirrorball" },
        "extensionsUsed": [EXTENSION],
        "extensions": { EXTENSION: { "lights": [{
            "name": ibl.name,
            "intensity": ibl.intensity,
            "rotation": ibl.rotation,
            "irradianceCoefficients": ibl.irradiance_coefficients,
            "specularImageSize": size,
            "specularImages": specular,
        }]}},
        "images": images,
        "scene": 0,
        "scenes": [{ "name": ibl.name, "extensions": { EXTENSION: { "light": 0 } } }],
    });
    let text = serde_json::to_string_pretty(&gltf).expect("JSON of plain values");
    atomic_write(path, |w| {
        w.write_all(text.as_bytes()).map_err(|e| Error::io(path, e))
    })?;
    written.push(path.to_path_buf());
    Ok(written)
}

/// Reads the light the default scene of the glTF file `path` references, with its images.
pub fn read_gltf_ibl(path: &Path) -> Result<GltfIbl, Error> {
    Error::check_input(path)?;
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let bad = |p: String| Error::input(path, p);
    let gltf: Value = serde_json::from_slice(&bytes).map_err(|e| bad(format!("JSON: {e}")))?;
    let used = gltf["extensionsUsed"].as_array();
    if !used.is_some_and(|u| u.iter().any(|e| e == EXTENSION)) {
        return Err(bad(format!("{EXTENSION} is not in extensionsUsed")));
    }
    let scene = gltf["scene"].as_u64().unwrap_or(0) as usize;
    let index = gltf["scenes"][scene]["extensions"][EXTENSION]["light"]
        .as_u64()
        .ok_or_else(|| bad(format!("scene {scene} references no {EXTENSION} light")))?;
    let light = &gltf["extensions"][EXTENSION]["lights"][index as usize];
    if light.is_null() {
        return Err(bad(format!("no {EXTENSION} light {index}")));
    }
    let numbers = |v: &Value, what: &str| -> Result<Vec<f64>, Error> {
        v.as_array()
            .ok_or_else(|| bad(format!("{what} is not an array")))?
            .iter()
            .map(|x| {
                x.as_f64()
                    .ok_or_else(|| bad(format!("{what}: not a number")))
            })
            .collect()
    };
    let mut irradiance_coefficients = [[0.0; 3]; 9];
    let rows = light["irradianceCoefficients"]
        .as_array()
        .filter(|r| r.len() == 9)
        .ok_or_else(|| bad("irradianceCoefficients is not 9×3".into()))?;
    for (out, row) in irradiance_coefficients.iter_mut().zip(rows) {
        let row = numbers(row, "irradianceCoefficients")?;
        *out = row
            .try_into()
            .map_err(|_| bad("irradianceCoefficients is not 9×3".into()))?;
    }
    let rotation = match light.get("rotation") {
        None => [0.0, 0.0, 0.0, 1.0],
        Some(r) => numbers(r, "rotation")?
            .try_into()
            .map_err(|_| bad("rotation is not four numbers".into()))?,
    };
    let intensity = light.get("intensity").map_or(Some(1.0), Value::as_f64);
    let intensity = intensity.ok_or_else(|| bad("intensity is not a number".into()))?;
    let size = light["specularImageSize"]
        .as_u64()
        .filter(|s| s.is_power_of_two() && *s <= 1 << 16)
        .ok_or_else(|| bad("specularImageSize is not a power of two up to 65536".into()))?
        as u32;
    let specular = light["specularImages"]
        .as_array()
        .filter(|l| !l.is_empty() && l.len() <= size.trailing_zeros() as usize + 1)
        .ok_or_else(|| bad("specularImages is not 1 to log2(size) + 1 levels".into()))?;
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut levels = Vec::with_capacity(specular.len());
    for (level, faces) in specular.iter().enumerate() {
        let faces = faces
            .as_array()
            .filter(|f| f.len() == 6)
            .ok_or_else(|| bad(format!("specularImages[{level}] is not six images")))?;
        let mut out = Vec::with_capacity(6);
        for (f, image) in faces.iter().enumerate() {
            let image = &gltf["images"][image.as_u64().unwrap_or(u64::MAX) as usize];
            let uri = image["uri"]
                .as_str()
                .filter(|u| !u.contains("..") && !u.contains(':') && !u.starts_with('/'))
                .ok_or_else(|| {
                    bad(format!(
                        "specularImages[{level}][{f}]: no relative image uri"
                    ))
                })?;
            let file = dir.join(uri);
            Error::check_input(&file)?;
            let png = std::fs::read(&file).map_err(|e| Error::io(&file, e))?;
            let what = format!("level {level} face {f}");
            out.push(rgba_png::decode(
                &file,
                &png,
                (size >> level).max(1),
                &what,
            )?);
        }
        levels.push(out.try_into().expect("six faces"));
    }
    Ok(GltfIbl {
        name: light["name"].as_str().unwrap_or_default().to_string(),
        intensity,
        rotation,
        irradiance_coefficients,
        levels,
    })
}

/// [`read_gltf_ibl`]'s level 0, for [`crate::read`].
pub(crate) fn read(path: &Path, limits: &crate::Limits) -> Result<crate::Loaded, Error> {
    let ibl = read_gltf_ibl(path)?;
    crate::babylon_env::cube_loaded(
        path,
        &ibl.levels,
        limits,
        crate::Format::GltfIbl,
        &format!("glTF {EXTENSION} light '{}'", ibl.name),
    )
}
