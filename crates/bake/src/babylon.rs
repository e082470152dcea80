//! Lighting for Babylon.js: one `.env` file (the container: `mirrorball_io::babylon_env`),
//! and the rules Babylon reads it by, each from its source (`@babylonjs/core` 9.35):
//!
//! - **Directions.** Babylon samples a cube at the direction in its own left-handed world
//!   (+X right, +Y up, +Z ahead), with OpenGL's face rules (its
//!   `CubeMapToSphericalPolynomialTools._FileFaces`, `Misc/HighDynamicRange/
//!   cubemapToSphericalPolynomial.js:269`, are OpenGL's face axes). A right-handed scene
//!   (`scene.useRightHandedSystem`) samples at `(x, y, −z)` of its world direction
//!   (`REFLECTIONMAP_OPPOSITEZ`, `Materials/materialHelper.functions.js:778`,
//!   `Shaders/ShadersInclude/pbrBlockReflection.js:39`), so both see mirrorball's world
//!   (viewer along −Z) through the lookup `(x, y, −z)`: the cube Babylon gets shows, at
//!   `d`, what mirrorball's shows at `(d.x, d.y, −d.z)` ([`Target::orientation`], applied by the
//!   bake before [`Target::write`]).
//! - **Rows.** Each PNG is uploaded with `invertY` (`_OnImageReadyAsync`,
//!   `Misc/environmentTextureTools.pure.js:358`) and drawn into the face by a full-screen
//!   pass whose `vUV = 0` is the face's row `t = 0`: the picture's bottom row is `t = 0`,
//!   so a PNG holds OpenGL's face upside down ([`rgbd_faces`]).
//! - **Levels.** The shader reads `lod = log2(width · α) · lodGenerationScale + offset`
//!   with `α = roughness² + 0.0005` (`getLodFromAlphaG`, `Shaders/ShadersInclude/
//!   pbrIBLFunctions.js:5`; `convertRoughnessToAverageSlope`, `pbrHelperFunctions.js:9`;
//!   the scale and offset, `pbrBlockReflection.js:95`), the offset 0 for a `.env`; level
//!   `i` is therefore GGX at `α = 2^(i/scale)/width`, as Babylon's own prefilter makes it
//!   (`HDRFiltering`, `Materials/Textures/Filtering/hdrFiltering.js:85`, level 0 a
//!   mirror), roughness clamped to 1 ([`level_roughness`]). The scale is Babylon's 0.8.
//! - **Diffuse.** A spherical polynomial made from SH as Babylon makes it
//!   ([`babylon_harmonics`], [`spherical_polynomial`]); no irradiance cube.
//! - **Texels.** RGBD (`mirrorball_encode`'s, Babylon's `toRGBD`), 8-bit PNG.

use crate::{mip_levels, BakeOptions, ChainSpec, Description, Lighting, Target};
use mirrorball_core::{Axis, AxisMap, EnvMap};
use mirrorball_filter::sh::Sh9;
use mirrorball_io::{write_babylon_env, BabylonEnv, Encoding, Error, Rgba8Face};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

/// Babylon's `lodGenerationScale` for the files written here: its default (`HDRFiltering`'s
/// `_lodGenerationScale`, and `GetEnvInfo`'s fallback).
pub(crate) const LOD_GENERATION_SCALE: f64 = 0.8;

/// `MINIMUMVARIANCE` (`pbrHelperFunctions.js:4`): the shader's `α = r² + 0.0005`.
const MINIMUM_VARIANCE: f64 = 0.0005;

/// The `.env` file's name in the output folder.
pub(crate) const FILE: &str = "environment.env";

/// Babylon.js's rules.
pub(crate) struct Babylon;

impl Target for Babylon {
    /// How Babylon looks its cubes up: at `(x, y, −z)` of mirrorball's world (the module
    /// documentation), so its cube shows at `e` what mirrorball's shows at `e` mirrored in z.
    fn orientation(&self) -> AxisMap {
        AxisMap::mirror(Axis::Z)
    }

    /// What Babylon takes.
    fn describe(&self) -> Description {
        Description {
        files: "environment.env",
        containers: "Babylon .env (JSON manifest, RGBD PNG faces per level down to 1x1)",
        encodings: &[Encoding::Rgbd],
        zstd: false,
        convention: "Babylon samples at (x, y, -z) of mirrorball's world, left- or right-handed scene (@babylonjs/core 9.35 Materials/materialHelper.functions.js:778, Shaders/ShadersInclude/pbrBlockReflection.js:39); PNG rows upside down (Misc/environmentTextureTools.pure.js:358, invertY)",
        rule: "lod = log2(width*(r^2 + 0.0005))*0.8 (pbrIBLFunctions.js:5, pbrHelperFunctions.js:9, pbrBlockReflection.js:95): level i at alpha = 2^(i/0.8)/width, level 0 a mirror (hdrFiltering.js:85)",
        diffuse: "the manifest's spherical polynomial, from SH as Babylon makes it (Maths/sphericalPolynomial.pure.js:40, 375)",
        background: None,
    }
    }

    /// The levels Babylon takes: the whole chain down to 1×1, level `i` at the roughness the
    /// shader reads it at, no irradiance cube.
    fn chain_spec(&self, opts: &BakeOptions) -> ChainSpec {
        let size = opts.size;
        ChainSpec {
            levels: mip_levels(size, |i, _| level_roughness(i, size, LOD_GENERATION_SCALE)),
            diffuse_face: None,
            background_face: None,
        }
    }

    /// [`FILE`].
    fn file_names(&self, _opts: &BakeOptions) -> Vec<String> {
        vec![FILE.to_string()]
    }

    /// Writes `environment.env` into `dir`, from lighting already in Babylon's axes
    /// ([`Target::orientation`]).
    fn write(&self, l: &Lighting, dir: &Path, _opts: &BakeOptions) -> Result<Vec<PathBuf>, Error> {
        let path = dir.join(FILE);
        let env = BabylonEnv {
            polynomial: spherical_polynomial(&babylon_harmonics(&l.sh9)),
            lod_generation_scale: LOD_GENERATION_SCALE,
            levels: l.specular.iter().map(rgbd_faces).collect(),
        };
        write_babylon_env(&path, &env)?;
        Ok(vec![path])
    }

    /// The note's body: how Babylon loads it.
    fn readme(&self, opts: &BakeOptions, _spec: &ChainSpec) -> String {
        format!(
        "## Loading it\n\n\
         `{FILE}`: a Babylon `.env` (RGBD PNG specular chain {size}² down to 1×1, level i \
         GGX at α = 2^(i/0.8)/{size}, as Babylon's shader reads it; diffuse light from its \
         spherical polynomial). Babylon's world (left-handed, or right-handed with \
         `scene.useRightHandedSystem`) sees it the right way round: +X right, +Y up, and \
         what mirrorball shows ahead (−Z) straight ahead of Babylon's default camera.\n\n\
         ```js\n\
         const env = new BABYLON.CubeTexture(\"{FILE}\", scene); // or CubeTexture.CreateFromPrefilteredData\n\
         scene.environmentTexture = env;\n\
         scene.createDefaultSkybox(env, true, 1000, 0); // optional background\n\
         ```\n",
        size = opts.size,
    )
    }
}

/// The perceptual roughness Babylon's shader reads level `level` of a `width`-edge cube at
/// (see the module documentation): `√(2^(level/scale)/width − 0.0005)`, clamped to
/// `[0, 1]`, and 0 (a mirror) for level 0, as Babylon's prefilter makes it.
pub(crate) fn level_roughness(level: usize, width: u32, scale: f64) -> f64 {
    if level == 0 {
        return 0.0;
    }
    let alpha = (level as f64 / scale).exp2() / f64::from(width);
    (alpha - MINIMUM_VARIANCE).clamp(0.0, 1.0).sqrt()
}

/// The level Babylon's shader reads at perceptual roughness `roughness` (`getLodFromAlphaG`
/// times the scale): the inverse of [`level_roughness`].
#[cfg(test)]
pub(crate) fn shader_lod(roughness: f64, width: u32, scale: f64) -> f64 {
    let alpha = roughness * roughness + MINIMUM_VARIANCE;
    (f64::from(width) * alpha).log2() * scale
}

/// `cube` (mirrorball's world axes) as Babylon samples it: at `d`, what `cube` shows at
/// `(d.x, d.y, −d.z)`, texel for texel.
#[cfg(test)]
pub(crate) fn babylon_cube(cube: &EnvMap) -> EnvMap {
    cube.transformed(&Babylon.orientation()).expect("a cube")
}

/// The six PNG pictures of one level of a cube already in Babylon's directions: RGBD, each
/// face upside down (its rows `t = 1` first; see the module documentation).
pub(crate) fn rgbd_faces(cube: &EnvMap) -> [Rgba8Face; 6] {
    let mut bytes = Vec::new();
    let faces: Vec<Rgba8Face> = cube
        .layers()
        .iter()
        .map(|layer| {
            Encoding::Rgbd.encode(layer, &mut bytes);
            let row = layer.width() as usize * 4;
            let texels = bytes.chunks_exact(row).rev().flatten().copied().collect();
            Rgba8Face {
                size: layer.width(),
                texels,
            }
        })
        .collect();
    faces.try_into().expect("six faces")
}

/// Babylon's `SphericalHarmonics` of the radiance whose SH9 is `sh` (mirrorball's basis,
/// `mirrorball_filter::sh`, in Babylon's axes: [`Lighting::oriented`] turned it), after `convertIncidentRadianceToIrradiance` (its
/// cosine kernel π, 2π/3, π/4, the same as [`Sh9::lambert`]'s times π): the irradiance E,
/// `[l00, l1_1, l10, l11, l2_2, l2_1, l20, l21, l22][channel]`.
///
/// Its basis (`SH3ylmBasisConstants`, `Maths/sphericalPolynomial.pure.js:40`) has the
/// constants of ours with a minus sign on `y`, `x`, `yz`, `xz` (Condon–Shortley):
/// coefficient `i` is ours times `SIGN[i]`.
pub(crate) fn babylon_harmonics(sh: &Sh9) -> [[f64; 3]; 9] {
    const SIGN: [f64; 9] = [1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0];
    let e = sh.lambert();
    std::array::from_fn(|i| e.coeffs[i].map(|c| c * PI * SIGN[i]))
}

/// Babylon's `SphericalPolynomial.FromHarmonics` of harmonics `h` after its
/// `convertIrradianceToLambertianRadiance` (÷π), constants and signs as
/// `updateFromHarmonics` has them (`Maths/sphericalPolynomial.pure.js:375`), its own final
/// ÷π included: the `.env` manifest's `irradiance`, terms `x y z xx yy zz yz zx xy`.
pub(crate) fn spherical_polynomial(irradiance: &[[f64; 3]; 9]) -> [[f64; 3]; 9] {
    let h = |i: usize, k: usize| irradiance[i][k] / PI;
    std::array::from_fn(|term| {
        std::array::from_fn(|k| {
            let v = match term {
                0 => -1.02333 * h(3, k),
                1 => -1.02333 * h(1, k),
                2 => 1.02333 * h(2, k),
                3 => 0.886277 * h(0, k) - 0.247708 * h(6, k) + 0.429043 * h(8, k),
                4 => 0.886277 * h(0, k) - 0.247708 * h(6, k) - 0.429043 * h(8, k),
                5 => 0.886277 * h(0, k) + 0.495417 * h(6, k),
                6 => -0.858086 * h(5, k),
                7 => -0.858086 * h(7, k),
                _ => 0.858086 * h(4, k),
            };
            v / PI
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorball_core::glam::DVec3;
    use mirrorball_core::CubeFace;
    use mirrorball_core::ProjectionKind;

    #[test]
    fn each_level_is_read_at_the_roughness_it_holds() {
        for width in [16u32, 64, 256, 1024] {
            let n = width.trailing_zeros() as usize + 1;
            for i in 1..n {
                let r = level_roughness(i, width, LOD_GENERATION_SCALE);
                if r < 1.0 {
                    let lod = shader_lod(r, width, LOD_GENERATION_SCALE);
                    assert!(
                        (lod - i as f64).abs() < 1e-9,
                        "{width}: level {i} read at {lod}"
                    );
                } else {
                    // Past roughness 1 the shader never asks for this level.
                    assert!(shader_lod(1.0, width, LOD_GENERATION_SCALE) < i as f64);
                }
            }
            // A mirror reads level 0 (the lod is below 0 and clamps there).
            assert!(shader_lod(0.0, width, LOD_GENERATION_SCALE) < 0.0);
        }
    }

    #[test]
    fn the_cube_babylon_gets_shows_mirrorballs_world_at_x_y_minus_z() {
        let cube = ProjectionKind::Cube.default_projection();
        let n = 8;
        let coded = EnvMap::from_fn(cube, n, 3, |d| [d.x as f32, d.y as f32, d.z as f32, 1.0]);
        let b = babylon_cube(&coded);
        for (f, face) in CubeFace::ALL.iter().enumerate() {
            for y in 0..n {
                for x in 0..n {
                    let sc = 2.0 * (f64::from(x) + 0.5) / f64::from(n) - 1.0;
                    let tc = 2.0 * (f64::from(y) + 0.5) / f64::from(n) - 1.0;
                    let d = face.point(sc, tc).normalize();
                    let got = b.layers()[f].get(x, y);
                    let want = [d.x, d.y, -d.z];
                    for k in 0..3 {
                        assert!((f64::from(got[k]) - want[k]).abs() < 1e-6, "{f} {x} {y}");
                    }
                }
            }
        }
    }

    /// Babylon's own sum (`ConvertCubeMapToSphericalPolynomial`: `addLight` with its basis
    /// at its lookup direction, the cosine kernel, ÷π, `FromHarmonics`), ported, of a smooth
    /// radiance, against the polynomial made here from mirrorball's SH9 of the same radiance.
    #[test]
    fn the_polynomial_is_the_one_babylon_sums_from_the_cube_it_samples() {
        let radiance = |d: DVec3| {
            [
                1.0 + 0.5 * d.x + 0.2 * d.x * d.z,
                1.0 + 0.4 * d.y + 0.3 * d.y * d.y,
                1.0 - 0.3 * d.z + 0.1 * d.x * d.y,
            ]
        };
        let n = 64;
        let env = EnvMap::from_fn(ProjectionKind::Cube.default_projection(), n, 3, |d| {
            let r = radiance(d);
            [r[0] as f32, r[1] as f32, r[2] as f32, 1.0]
        });
        let sh = mirrorball_filter::sh::project(&env).transformed(&Babylon.orientation());
        let ours = spherical_polynomial(&babylon_harmonics(&sh));
        // Babylon's basis (SH3ylmBasisConstants × SH3ylmBasisTrigonometricTerms).
        let k = |a: f64| a.sqrt();
        let basis = |d: DVec3| {
            [
                k(1.0 / (4.0 * PI)),
                -k(3.0 / (4.0 * PI)) * d.y,
                k(3.0 / (4.0 * PI)) * d.z,
                -k(3.0 / (4.0 * PI)) * d.x,
                k(15.0 / (4.0 * PI)) * d.x * d.y,
                -k(15.0 / (4.0 * PI)) * d.y * d.z,
                k(5.0 / (16.0 * PI)) * (3.0 * d.z * d.z - 1.0),
                -k(15.0 / (4.0 * PI)) * d.x * d.z,
                k(15.0 / (16.0 * PI)) * (d.x * d.x - d.y * d.y),
            ]
        };
        let area = |x: f64, y: f64| (x * y).atan2((x * x + y * y + 1.0).sqrt());
        let babylon = babylon_cube(&env);
        let mut h = [[0.0f64; 3]; 9];
        let mut total = 0.0;
        for (f, face) in CubeFace::ALL.iter().enumerate() {
            for y in 0..n {
                for x in 0..n {
                    let u = 2.0 * (f64::from(x) + 0.5) / f64::from(n) - 1.0;
                    let v = 2.0 * (f64::from(y) + 0.5) / f64::from(n) - 1.0;
                    let e = 1.0 / f64::from(n);
                    let da = area(u - e, v - e) - area(u - e, v + e) - area(u + e, v - e)
                        + area(u + e, v + e);
                    let d = face.point(u, v).normalize();
                    let c = babylon.layers()[f].get(x, y);
                    for (hi, b) in h.iter_mut().zip(basis(d)) {
                        for ch in 0..3 {
                            hi[ch] += f64::from(c[ch]) * b * da;
                        }
                    }
                    total += da;
                }
            }
        }
        let kernel = [PI, 2.0 * PI / 3.0, PI / 4.0];
        for (i, hi) in h.iter_mut().enumerate() {
            for v in hi.iter_mut() {
                *v *= 4.0 * PI / total * kernel[mirrorball_filter::sh::band(i)];
            }
        }
        let theirs = spherical_polynomial(&h);
        for t in 0..9 {
            for ch in 0..3 {
                let (a, b) = (ours[t][ch], theirs[t][ch]);
                assert!(
                    (a - b).abs() < 1e-4,
                    "term {t} channel {ch}: {a} vs Babylon's {b}"
                );
            }
        }
        // Not all zero: the test sees the signs.
        assert!(ours[0][0].abs() > 0.01 && ours[1][1].abs() > 0.01 && ours[2][2].abs() > 0.01);
    }
}

#[cfg(test)]
mod round_trip {
    use super::*;
    use mirrorball_encode::Encoding;
    use mirrorball_io::read_babylon_env;

    /// The direction-coded world (colour ½ + ½·d) baked for Babylon at 16², written, read
    /// back by the `.env` reader, each picture turned back (rows, then the z flip, its own
    /// inverse) and decoded: the prefiltered levels again, within RGBD's 8-bit steps.
    #[test]
    fn the_env_reads_back_as_the_levels_and_polynomial_it_was_made_from() {
        let env = crate::direction_coded(128);
        let opts = BakeOptions {
            size: 16,
            ..Default::default()
        };
        let spec = Babylon.chain_spec(&opts);
        let world = Lighting::from_env(&env, &spec, Default::default());
        let lighting = world.clone().oriented(&Babylon.orientation());
        let dir = tempfile::tempdir().unwrap();
        let files = Babylon.write(&lighting, dir.path(), &opts).unwrap();
        assert_eq!(files[0], dir.path().join(FILE));
        let back = read_babylon_env(&files[0]).unwrap();
        assert_eq!(back.lod_generation_scale, LOD_GENERATION_SCALE);
        assert_eq!(back.levels.len(), 5);
        let want = spherical_polynomial(&babylon_harmonics(&lighting.sh9));
        // serde_json writes the shortest round-trip text and parses it to within an ulp.
        for (b, w) in back.polynomial.iter().flatten().zip(want.iter().flatten()) {
            assert!((b - w).abs() <= 1e-15 * w.abs().max(1.0), "{b} vs {w}");
        }
        for (i, (faces, level)) in back.levels.iter().zip(&world.specular).enumerate() {
            let n = 16 >> i;
            let layers = faces
                .iter()
                .map(|f| {
                    let rows: Vec<u8> = f
                        .texels
                        .chunks_exact(n * 4)
                        .rev()
                        .flatten()
                        .copied()
                        .collect();
                    Encoding::Rgbd.decode(&rows, n as u32, n as u32)
                })
                .collect();
            let cube = babylon_cube(&EnvMap::new(*level.projection(), layers).unwrap());
            for (got, want) in cube.layers().iter().zip(level.layers()) {
                let (g, w) = (got.data(), want.data());
                let (gc, wc) = (got.channels(), want.channels());
                for (gp, wp) in g.chunks_exact(gc).zip(w.chunks_exact(wc)) {
                    for k in 0..3 {
                        // RGBD of values in [0, 1]: D = 1, one step of x^(1/2.2) in 255.
                        assert!((gp[k] - wp[k]).abs() < 0.01, "level {i}: {gp:?} vs {wp:?}");
                    }
                }
            }
        }
        // The levels differ (a mirror down to roughness 1), so the comparison sees the order.
        let centre = |i: usize| {
            let c = 8 >> i;
            world.specular[i].layers()[4].get(c, c)[2]
        };
        assert!(centre(0) - centre(3) > 0.05);
    }
}
