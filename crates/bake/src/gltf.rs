//! Lighting for glTF 2.0's `EXT_lights_image_based` (the file: `mirrorball_io::gltf_ibl`).
//!
//! The extension's README (KhronosGroup/glTF, `extensions/2.0/Vendor/EXT_lights_image_based`)
//! fixes the containers (N×6 images, faces +X −X +Y −Y +Z −Z, a four-channel PNG is RGBD,
//! 9×3 SH coefficients "for irradiance") but not the SH basis, the faces' exact
//! orientation or which roughness each level holds; those are what its one loader,
//! Babylon.js's (`packages/dev/loaders/src/glTF/2.0/Extensions/EXT_lights_image_based.ts`,
//! `_loadLightAsync`), reads:
//!
//! - the images go through the same upload as a `.env`'s (`updateRGBDAsync` →
//!   `UploadRadianceLevelsAsync`), so faces, rows and RGBD are [`crate::babylon`]'s;
//! - `irradianceCoefficients` are `SphericalHarmonics.FromArray`, scaled by `intensity`,
//!   then `convertIrradianceToLambertianRadiance` and `SphericalPolynomial.FromHarmonics`:
//!   Babylon's harmonics of the irradiance, [`crate::babylon::babylon_harmonics`];
//! - `lodGenerationScale = (N − 1)/log2(specularImageSize)` for N levels, so the shader
//!   (`lod = log2(size·α)·scale`) reads level `i` at `α = 2^(i/scale)/size`: roughness 1
//!   at the last level. The README's "levels evenly map to roughness values from 0 to 1"
//!   is not what that loader does; the levels here hold what it reads.
//!
//! The chain stops at [`LOWEST_EDGE`] (the README: the lowest mip "say, 16x16" holds
//! roughness 1). The glTF world is mirrorball's (right-handed, +Y up); Babylon sees the
//! light the right way round in a right-handed scene (`useRightHandedSystem`, the usual
//! setting for glTF). The light's `rotation` is the identity and its `intensity` 1.

use crate::babylon::Babylon;
use crate::babylon::{babylon_harmonics, level_roughness, rgbd_faces};
use crate::{BakeOptions, ChainSpec, Description, Lighting, Target};
use mirrorball_core::AxisMap;
use mirrorball_io::{write_gltf_ibl, Encoding, Error, GltfIbl};
use std::path::{Path, PathBuf};

/// The smallest specular level's edge (when level 0 is larger).
pub(crate) const LOWEST_EDGE: u32 = 16;

/// The glTF file's name in the output folder.
pub(crate) const FILE: &str = "lighting.gltf";

/// `EXT_lights_image_based`'s rules.
pub(crate) struct Gltf;

impl Target for Gltf {
    /// Refuses, before any work, what the extension cannot hold beyond [`crate::Bake::new`]'s
    /// checks: a level 0 under 2×2.
    fn check(&self, opts: &BakeOptions) -> Result<(), crate::Error> {
        if opts.size < 2 {
            return Err(crate::Error::request(
                "EXT_lights_image_based needs level 0 at least 2×2 (its loader divides by \
             log2 of the size)",
            ));
        }
        Ok(())
    }

    /// The light's faces are looked up as Babylon's `.env` faces are ([`crate::babylon`]).
    fn orientation(&self) -> AxisMap {
        Babylon.orientation()
    }

    /// What the extension holds.
    fn describe(&self) -> Description {
        Description {
        files: "lighting.gltf, lighting_specular_L_{px,nx,py,ny,pz,nz}.png per level L",
        containers: "glTF 2.0 JSON with EXT_lights_image_based, RGBD PNG faces",
        encodings: &[Encoding::Rgbd],
        zstd: false,
        convention: "as Babylon's .env, whose loader is the extension's one implementation (EXT_lights_image_based.pure.js:82-105): samples at (x, y, -z); a right-handed scene sees it the right way round",
        rule: "lodGenerationScale = (N-1)/log2(size): level i at alpha = 2^(i/scale)/size, roughness 1 at the last level (16x16)",
        diffuse: "irradianceCoefficients: 9x3 SH of the irradiance E in Babylon's basis",
        background: None,
    }
    }

    /// The files written, for the checks before any work.
    fn file_names(&self, opts: &BakeOptions) -> Vec<String> {
        let levels = self.chain_spec(opts).levels.len();
        let stem = FILE.trim_end_matches(".gltf");
        std::iter::once(FILE.to_string())
            .chain((0..levels).flat_map(|l| {
                ["px", "nx", "py", "ny", "pz", "nz"]
                    .into_iter()
                    .map(move |f| format!("{stem}_specular_{l}_{f}.png"))
            }))
            .collect()
    }

    /// The levels: level 0's edge halved down to [`LOWEST_EDGE`], level `i` at the roughness
    /// Babylon's loader and shader read it at; no irradiance cube (SH only).
    fn chain_spec(&self, opts: &BakeOptions) -> ChainSpec {
        let size = opts.size.max(1);
        let n = (size
            .trailing_zeros()
            .saturating_sub(LOWEST_EDGE.trailing_zeros())
            + 1) as usize;
        let scale = lod_generation_scale(n, size);
        ChainSpec {
            levels: (0..n)
                .map(|i| ((size >> i).max(1), level_roughness(i, size, scale)))
                .collect(),
            diffuse_face: None,
            background_face: None,
        }
    }

    /// Writes `lighting.gltf` and its images into `dir`, from lighting already in Babylon's
    /// axes ([`Target::orientation`]).
    fn write(&self, l: &Lighting, dir: &Path, opts: &BakeOptions) -> Result<Vec<PathBuf>, Error> {
        let ibl = GltfIbl {
            name: light_name(opts),
            intensity: 1.0,
            rotation: [0.0, 0.0, 0.0, 1.0],
            irradiance_coefficients: babylon_harmonics(&l.sh9),
            levels: l.specular.iter().map(rgbd_faces).collect(),
        };
        write_gltf_ibl(&dir.join(FILE), &ibl)
    }

    /// The note's body: how a glTF viewer (Babylon's loader) takes it.
    fn readme(&self, opts: &BakeOptions, _spec: &ChainSpec) -> String {
        let n = self.chain_spec(opts).levels.len();
        format!(
            "## Loading it\n\n\
         `{FILE}`: glTF 2.0 with one `EXT_lights_image_based` light, referenced by the \
         default scene: {n} specular levels of six RGBD PNG faces ({size}² down to {low}²), \
         level i GGX at α = 2^(i·log2({size})/{last})/{size} (roughness 1 at the last level, \
         as Babylon.js's loader reads them), irradiance as 9×3 SH coefficients in Babylon's \
         basis. Load it into a right-handed Babylon scene, which sees the glTF world the \
         right way round (a left-handed one turns it half a turn about +Y):\n\n\
         ```js\n\
         scene.useRightHandedSystem = true;\n\
         await BABYLON.SceneLoader.AppendAsync(\"./\", \"{FILE}\", scene); // @babylonjs/loaders\n\
         // The loader made the light scene.environmentTexture but left it marked gamma-encoded,\n\
         // so its shader would darken the light to radiance^2.2: the file's RGBD is linear.\n\
         scene.environmentTexture.gammaSpace = false;\n\
         ```\n\n\
         Babylon.js's glTF loader (`EXT_lights_image_based.pure.js`) leaves the RawCubeTexture \
         it makes at its default `gammaSpace` (true), though the extension says a \
         four-channel PNG is linear RGBD; the line above undoes that (the texture marks the \
         materials that use it for an update).\n",
            size = opts.size,
            low = opts.size >> (n - 1),
            last = (n - 1).max(1),
        )
    }
}

/// The light's name: the source's file name.
fn light_name(opts: &BakeOptions) -> String {
    std::path::Path::new(&opts.source)
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("environment")
        .to_string()
}

/// Babylon's loader's `lodGenerationScale` for `levels` levels of edge `size` down.
pub(crate) fn lod_generation_scale(levels: usize, size: u32) -> f64 {
    (levels as f64 - 1.0) / f64::from(size.max(2)).log2()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_chain_runs_from_a_mirror_to_roughness_one_at_the_lowest_level() {
        let spec = Gltf.chain_spec(&BakeOptions {
            size: 256,
            ..Default::default()
        });
        let edges: Vec<u32> = spec.levels.iter().map(|l| l.0).collect();
        assert_eq!(edges, [256, 128, 64, 32, 16]);
        assert_eq!(spec.levels[0].1, 0.0);
        assert!((spec.levels[4].1 - (1.0f64 - 0.0005).sqrt()).abs() < 1e-12);
        assert!(spec.levels.windows(2).all(|w| w[0].1 < w[1].1));
        // A 16² bake is one mirror level, as the loader reads it (scale 0).
        let small = Gltf.chain_spec(&BakeOptions {
            size: 16,
            ..Default::default()
        });
        assert_eq!(small.levels, [(16, 0.0)]);
    }

    #[test]
    fn the_gltf_reads_back_as_written_and_bad_requests_are_refused_first() {
        use mirrorball_core::{EnvMap, ProjectionKind};
        let env = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 128, 3, |d| {
            [
                (0.5 + 0.5 * d.x) as f32,
                0.5,
                (0.5 - 0.25 * d.z) as f32,
                1.0,
            ]
        });
        let opts = BakeOptions {
            size: 32,
            source: "/maps/coded.exr".into(),
            ..Default::default()
        };
        let spec = Gltf.chain_spec(&opts);
        let lighting =
            Lighting::from_env(&env, &spec, Default::default()).oriented(&Gltf.orientation());
        let dir = tempfile::tempdir().unwrap();
        let files = Gltf.write(&lighting, dir.path(), &opts).unwrap();
        assert_eq!(files.len(), 2 * 6 + 1);
        let names: Vec<String> = files
            .iter()
            .map(|f| f.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        let mut expected = Gltf.file_names(&opts);
        expected.sort();
        let mut got = names.clone();
        got.sort();
        assert_eq!(got, expected);
        let back = mirrorball_io::read_gltf_ibl(&dir.path().join(FILE)).unwrap();
        assert_eq!(back.name, "coded.exr");
        assert_eq!((back.intensity, back.rotation), (1.0, [0.0, 0.0, 0.0, 1.0]));
        let want = babylon_harmonics(&lighting.sh9);
        for (b, w) in back
            .irradiance_coefficients
            .iter()
            .flatten()
            .zip(want.iter().flatten())
        {
            assert!((b - w).abs() <= 1e-15 * w.abs().max(1.0), "{b} vs {w}");
        }
        let made: Vec<_> = lighting.specular.iter().map(rgbd_faces).collect();
        assert_eq!(back.levels, made);

        for (size, encoding) in [
            (48, None),
            (1, None),
            (32, Some(mirrorball_io::Encoding::Bc6hUnsigned)),
        ] {
            let bad = BakeOptions {
                size,
                encoding,
                ..Default::default()
            };
            let e = crate::Bake::new(crate::Engine::Gltf, bad).unwrap_err();
            assert_eq!(e.fault, mirrorball_core::Fault::Request);
            assert!(
                e.message.contains("power of two")
                    || e.message.contains("EXT_lights_image_based")
                    || e.message.contains("does not load"),
                "{e}"
            );
        }
    }
}
