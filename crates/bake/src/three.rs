//! Lighting for three.js (r187, the npm version the browser tests pin): the files, the
//! convention and the roughness-to-mip rule. Line numbers cite `three@0.187.0`'s sources.
//!
//! **What r187 takes as prefiltered.** Its PMREM is no longer a "CubeUV" atlas (there is no
//! `CubeUVReflectionMapping` in `src/constants.js`): `PMREMGenerator` makes a cube render
//! target whose mip `lod` of `maxLod + 1` holds GGX-filtered radiance at perceptual
//! roughness `1 − √(1 − lod/maxLod)` (`src/extras/PMREMGenerator.js` 236–240,
//! `lodToRoughness`), faces `size >> lod` down to `2^LOD_MIN` = 8 (lines 25 and 279–283),
//! and marks it `isPMREMTexture`. Any texture so marked is used as it is
//! (`src/renderers/webgl/WebGLEnvironments.js` 73); the shaders read mip
//! `ENVMAP_MAX_LOD · r(2 − r)` for roughness `r` (`envmap_common_pars_fragment.glsl.js`
//! 12–18, the inverse), with `ENVMAP_MAX_LOD` = the mip count − 1, counted from
//! `image[0].mipmaps` for a `CompressedCubeTexture` (`src/renderers/webgl/WebGLPrograms.js`
//! 191 and 225), and take the diffuse light from the last, roughness-1 level times π
//! (`envmap_physical_pars_fragment.glsl.js` 4–19). So the prefiltered radiance is written
//! as exactly those levels, GGX-prefiltered by mirrorball at exactly those roughnesses.
//!
//! **Which loader.** three's `KTX2Loader` has no BC6H in its vkFormat table and returns
//! uncompressed cubes as flat `DataTexture`s (`examples/jsm/loaders/KTX2Loader.js` 992–1050
//! and 1233–1238), and `HDRCubeTextureLoader` makes one level a face (an uncompressed
//! `CubeTexture` counts its mips without the base level, `WebGLTextures.js` 1621–1625, while
//! `WebGLPrograms.js` 191 counts them with it). `DDSLoader` reads a BC6H cube with its mips
//! (`DDSLoader.js` 253–266 and 319–370), so the PMREM is `pmrem.dds`, BC6H, wrapped as a
//! `CompressedCubeTexture` (what `KTX2Loader` makes of compressed cubes) by the note's three
//! lines. The plain cube, for backgrounds and for materials three filters itself, is six
//! Radiance RGBE faces for `HDRCubeTextureLoader`, which returns a `CubeTexture`: what a
//! three user loads HDR cube maps with, and it needs no texture-compression extension.
//!
//! **Mirroring.** three looks a `CubeTexture` that is not a render target up at
//! `(−x, y, z)`: `envMapRotation` and `backgroundRotation` are premultiplied by
//! `diag(−1, 1, 1)` (`WebGLMaterials.js` 9 and 248–252, `WebGLBackground.js` 17 and
//! 144–148), and a loaded `CompressedCubeTexture` is such a cube too. Both files are
//! therefore written as the world mirrored in x ([`Target::orientation`], applied by the bake
//! before [`Target::write`]), so that three's lookup at `(−x, y, z)` returns mirrorball's radiance
//! in `(x, y, z)`. Faces are uploaded unchanged,
//! row 0 to `t = 0` (`CubeTexture` and `DataTexture` have `flipY` false).

use crate::{BakeOptions, ChainSpec, Description, Lighting, Target};
use mirrorball_core::{Axis, AxisMap, Image};
use mirrorball_io::{CubeWrite, Encoding, Error, WriteOptions};
use std::path::{Path, PathBuf};

/// Log2 of the face edge of three's roughest PMREM level (`PMREMGenerator.js` 25).
const LOD_MIN: u32 = 3;

/// The PMREM file.
pub(crate) const PMREM_FILE: &str = "pmrem.dds";
/// The folder of the plain cube's faces.
pub(crate) const CUBE_DIR: &str = "cube";
/// The plain cube's face files in three's order, +X −X +Y −Y +Z −Z (OpenGL's).
pub(crate) const CUBE_FACES: [&str; 6] =
    ["px.hdr", "nx.hdr", "py.hdr", "ny.hdr", "pz.hdr", "nz.hdr"];

/// The perceptual roughness three reads mip `lod` of a PMREM with last mip `max_lod` at:
/// `PMREMGenerator.lodToRoughness` (`PMREMGenerator.js` 236–240), the inverse of the
/// shaders' `roughnessToMip`, `lod = max_lod · r(2 − r)`.
pub(crate) fn lod_to_roughness(lod: u32, max_lod: u32) -> f64 {
    if max_lod == 0 {
        0.0
    } else {
        1.0 - (1.0 - lod as f64 / max_lod as f64).sqrt()
    }
}

/// three.js's rules.
pub(crate) struct Three;

impl Target for Three {
    /// Refuses a size that has no PMREM levels, before any work (the encodings and Zstandard
    /// three cannot load are refused by [`crate::Bake::new`], from [`Target::describe`]).
    fn check(&self, opts: &BakeOptions) -> Result<(), crate::Error> {
        let size = opts.size;
        if !size.is_power_of_two() || size < 2 << LOD_MIN {
            return Err(crate::Error::request(format!(
                "three.js needs a power-of-two size of at least {} (its PMREM's levels go down to \
             {0}×{0} faces, 2^LOD_MIN with LOD_MIN = {LOD_MIN}); {size} was asked",
                2 << LOD_MIN
            )));
        }
        Ok(())
    }

    /// three's PMREM levels: faces `size >> lod` for `lod` in `0..=log2(size) − LOD_MIN`, each at
    /// [`lod_to_roughness`]; no diffuse cube (three takes diffuse light from the last level);
    /// the plain cube at the background's size.
    fn chain_spec(&self, opts: &BakeOptions) -> ChainSpec {
        let max_lod = opts.size.max(1).ilog2().saturating_sub(LOD_MIN);
        ChainSpec {
            levels: (0..=max_lod)
                .map(|lod| ((opts.size >> lod).max(1), lod_to_roughness(lod, max_lod)))
                .collect(),
            diffuse_face: None,
            background_face: Some(opts.background_face()),
        }
    }

    /// How three looks its cubes up: at `(−x, y, z)` (the module documentation), so its cube
    /// shows at `e` what mirrorball's world shows at `e` mirrored in x.
    fn orientation(&self) -> AxisMap {
        AxisMap::mirror(Axis::X)
    }

    /// What three takes.
    fn describe(&self) -> Description {
        Description {
        files: "pmrem.dds (three's own PMREM), cube/{px,nx,py,ny,pz,nz}.hdr (the plain cube)",
        containers: "DDS (BC6H cube with mips, for DDSLoader), Radiance HDR faces (HDRCubeTextureLoader)",
        encodings: &[Encoding::Bc6hUnsigned, Encoding::Bc6hSigned],
        zstd: false,
        convention: "three looks CubeTextures up at (-x, y, z) (src/renderers/webgl/WebGLMaterials.js 248-252, WebGLBackground.js 144-148, r187): both files are mirrored in x",
        rule: "three's PMREM: faces size>>lod down to 8x8, level lod at roughness 1 - sqrt(1 - lod/maxLod) (PMREMGenerator.js 236-240), read at mip maxLod*r(2-r) (envmap_common_pars_fragment.glsl.js 12-18)",
        diffuse: "the PMREM's last, roughness-1 level times pi (envmap_physical_pars_fragment.glsl.js 4-19)",
        background: Some("cube/ (six RGBE faces: px nx py ny pz nz), the source as a cube, mirrored in x (scene.background)"),
    }
    }

    /// The files written, for the checks before any work.
    fn file_names(&self, _opts: &BakeOptions) -> Vec<String> {
        std::iter::once(PMREM_FILE.to_string())
            .chain(CUBE_FACES.iter().map(|f| format!("{CUBE_DIR}/{f}")))
            .collect()
    }

    /// Writes three's files into `dir`: `pmrem.dds` and `cube/{px,nx,py,ny,pz,nz}.hdr` (the
    /// background), from lighting already in three's axes ([`Target::orientation`]).
    fn write(&self, l: &Lighting, dir: &Path, opts: &BakeOptions) -> Result<Vec<PathBuf>, Error> {
        let encoding = opts.encoding.unwrap_or(Encoding::Bc6hUnsigned);
        let levels: Vec<Vec<Image>> = l.specular.iter().map(|m| m.layers().to_vec()).collect();
        let pmrem = dir.join(PMREM_FILE);
        mirrorball_io::write_dds(
            &pmrem,
            &levels,
            &CubeWrite {
                encoding,
                effort: opts.effort,
                ..CubeWrite::default()
            },
        )?;
        let mut files = vec![pmrem];

        let Some(background) = &l.background else {
            return Err(Error::request(
                dir,
                "three's plain cube is the background; this lighting has none: make it from \
             Engine::Three.chain_spec"
                    .into(),
            ));
        };
        let cube = dir.join(CUBE_DIR);
        std::fs::create_dir_all(&cube).map_err(|e| Error::io(&cube, e))?;
        for (face, name) in background.layers().iter().zip(CUBE_FACES) {
            let path = cube.join(name);
            mirrorball_io::write_image(&path, face, &WriteOptions::default())?;
            files.push(path);
        }
        Ok(files)
    }

    /// The background's six Radiance faces.
    fn rgbe_texels(&self, spec: &ChainSpec) -> u64 {
        spec.background_face.map_or(0, |f| 6 * f as u64 * f as u64)
    }

    /// The note's body: what each file is and the lines of three.js that load it.
    fn readme(&self, opts: &BakeOptions, spec: &ChainSpec) -> String {
        let encoding = opts.encoding.unwrap_or(Encoding::Bc6hUnsigned);
        let faces: Vec<String> = CUBE_FACES
            .iter()
            .map(|f| format!("'{CUBE_DIR}/{f}'"))
            .collect();
        let levels: Vec<String> = spec
            .levels
            .iter()
            .enumerate()
            .map(|(lod, (face, r))| format!("{lod}: {face}×{face} at {r:.4}"))
            .collect();
        format!(
            r#"## Loading it

In three.js (r187):

- `{PMREM_FILE}`: the prefiltered radiance as three's own PMREM, a cube with mips,
  {label}, level `lod` GGX-prefiltered at perceptual roughness 1 − √(1 − lod/maxLod)
  (`PMREMGenerator.lodToRoughness`), the roughness three's shaders read it at
  (mip = maxLod · r(2 − r)); the last level is three's diffuse light.
  Levels (lod: face, roughness): {levels}.
- `{CUBE_DIR}/`: the plain cube (RGBE), {sky}² faces of the source itself, for
  `scene.background` and for materials three filters itself.

Both are mirrored left to right for three's cube lookup at (−x, y, z), so three shows
them the right way round: do not flip them again.

```js
import * as THREE from 'three';
import {{ DDSLoader }} from 'three/addons/loaders/DDSLoader.js';
import {{ HDRCubeTextureLoader }} from 'three/addons/loaders/HDRCubeTextureLoader.js';

// The PMREM (needs EXT_texture_compression_bptc: renderer.extensions.has(…)).
const dds = await new DDSLoader().loadAsync('{PMREM_FILE}');
const pmrem = new THREE.CompressedCubeTexture(dds.image, dds.format);
pmrem.isPMREMTexture = true; // already prefiltered: three uses it as it is
pmrem.minFilter = THREE.LinearMipmapLinearFilter;
pmrem.colorSpace = THREE.LinearSRGBColorSpace;
pmrem.needsUpdate = true;
scene.environment = pmrem; // or material.envMap = pmrem (MeshStandardMaterial)

// The background (or envMap of MeshBasicMaterial/MeshPhongMaterial).
scene.background = await new HDRCubeTextureLoader()
  .loadAsync([{faces}]);
// A blurred background reads the PMREM: scene.background = pmrem; scene.backgroundBlurriness = 0.5;
```

Without BC6H support, set `scene.environment` to the plain cube: three then makes its own
PMREM from it (`PMREMGenerator`).
"#,
            label = encoding.label(),
            levels = levels.join(", "),
            sky = spec.background_face.unwrap_or(opts.size),
            faces = faces.join(", "),
        )
    }
}
