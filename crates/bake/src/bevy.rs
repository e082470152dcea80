//! Lighting for Bevy's `EnvironmentMapLight` (`bevy_light/src/probe.rs`): a diffuse and a
//! specular KTX2 cube, as Bevy's shaders read them. Lines cited are bevy at 4805ca7 (0.20).
//!
//! - **Orientation.** Every environment-map lookup negates z before sampling: "Cubemaps are
//!   left-handed, so we negate the Z coordinate" (`bevy_pbr/src/light_probe/
//!   environment_map.wesl:92`, and `:259`, `:272` for the view's own map), and so does the
//!   skybox (`bevy_core_pipeline/src/skybox/skybox.wesl:80`). Bevy shows world direction
//!   `d` from its cube `B` at `(d.x, d.y, −d.z)`; for that to be the world's radiance,
//!   `B(x, y, z) = C(x, y, −z)` with `C` mirrorball's cube: [`Target::orientation`], applied by the
//!   bake before [`Target::write`].
//! - **Roughness to mip.** `radiance_level = perceptual_roughness ×
//!   smallest_specular_mip_level_for_view` (`environment_map.wesl:242`; `:161` with
//!   `textureNumLevels − 1` for probes), which is `mip_level_count − 1`
//!   (`environment_map.rs:314`). So level `m` of `L` holds GGX at perceptual roughness
//!   `m/(L−1)`. The chain goes down to 1×1, as Bevy's own filter makes it
//!   (`light_probe/generate.rs`: `compute_mip_count` = `32 − size.leading_zeros()`, roughness
//!   `mip / (num_mips − 1)` at `:717`).
//! - **Diffuse.** `out.diffuse = (FmsEms + kD) * radiances.irradiance` with `kD =
//!   diffuse_color × Edss` (`environment_map.wesl:380-383`): no 1/π in the shader, so the map
//!   holds E/π, the radiance a white Lambertian surface reflects (the cosine-weighted mean
//!   of the radiance). That is what Bevy's filter writes (`environment_filter.wesl`
//!   `generate_irradiance_map`: cosine-weighted samples, averaged) and what the
//!   glTF-IBL-Sampler's Lambertian output holds (`lib/source/shaders/filter.frag:323-333`,
//!   Bevy's documented source of its maps, `assets/environment_maps/info.txt`), and what
//!   [`Lighting::diffuse`] is. One level of 32×32: Bevy samples it at level 0 only
//!   (`environment_map.wesl:260`), and 32 is its filter's size (`generate.rs`, the 32×32
//!   diffuse image) and the IBL sampler's `-cubeMapResolution 32` in `info.txt`.
//! - **Encodings.** `bevy_image` 0.20.1's KTX2 loader maps RGBA16F, B10G11R11, RGB9E5 and
//!   BC6H to wgpu formats (`src/ktx2.rs:1271`, `:1283-1284`, `:1319-1320`). Not RGBA32F:
//!   wgpu's `Rgba32Float` is not filterable without a device feature, and Bevy samples
//!   through a filtering sampler. Not RGBD/RGBM: Bevy's shaders do not decode them. The
//!   default is RGB9E5, the encoding of Bevy's own environment maps
//!   (`assets/environment_maps/pisa_*_rgb9e5_zstd.ktx2`): half the bytes of RGBA16F at about
//!   its precision (2⁻¹⁰ of a texel's largest channel), and it loads on every backend,
//!   where BC6H (a quarter of RGB9E5's bytes: ask for it on desktop) is refused by the
//!   loader where the GPU has no BC formats (`src/ktx2.rs:250`, "Format not supported by
//!   this GPU": most phones, and WebGL2 without `EXT_texture_compression_bptc`).
//!
//! - **Sky.** `Skybox` takes any cube image (`skybox.wesl:80` samples it at level 0): the
//!   source resampled into a cube of its own size ([`crate::ChainSpec::background_face`]),
//!   mirrored in z like the others, in the same encoding.
//!
//! Zstandard supercompression (`opts.zstd`) is read by Bevy's default 3D features
//! (`zstd_rust`).

use crate::{mip_levels, BakeOptions, ChainSpec, Description, Lighting, Target};
use mirrorball_core::{Axis, AxisMap, Image};
use mirrorball_io::{write_ktx2, CubeWrite, Encoding, Error};
use std::path::{Path, PathBuf};

/// The specular cube's file name.
pub(crate) const SPECULAR_FILE: &str = "specular.ktx2";
/// The diffuse cube's file name.
pub(crate) const DIFFUSE_FILE: &str = "diffuse.ktx2";
/// The sky's file name.
pub(crate) const SKYBOX_FILE: &str = "skybox.ktx2";
/// The diffuse cube's face edge.
const DIFFUSE_FACE: u32 = 32;
/// The encoding a Bevy bake gets unless asked otherwise.
pub(crate) const DEFAULT_ENCODING: Encoding = Encoding::Rgb9E5;

/// Bevy's roughness rule: level `i` of `n` holds perceptual roughness `i/(n−1)`.
fn roughness_of_level(i: usize, n: usize) -> f64 {
    i as f64 / (n.max(2) - 1) as f64
}

/// Bevy's rules.
pub(crate) struct Bevy;

impl Target for Bevy {
    /// The levels Bevy takes: the full chain of `opts.size` at [`roughness_of_level`], the
    /// 32×32 diffuse cube and the sky.
    fn chain_spec(&self, opts: &BakeOptions) -> ChainSpec {
        ChainSpec {
            levels: mip_levels(opts.size, roughness_of_level),
            diffuse_face: Some(DIFFUSE_FACE),
            background_face: Some(opts.background_face()),
        }
    }

    /// Refuses, before any work, what Bevy cannot load: an encoding it does not sample, a face
    /// edge that is not a power of two (Bevy's filter and mip rule assume one), BC6H below 4×4.
    fn check(&self, opts: &BakeOptions) -> Result<(), crate::Error> {
        let encoding = opts.encoding.unwrap_or(DEFAULT_ENCODING);
        match encoding {
            Encoding::Rgba16F
            | Encoding::Rgb9E5
            | Encoding::B10G11R11
            | Encoding::Bc6hUnsigned
            | Encoding::Bc6hSigned => {}
            Encoding::Rgba32F => {
                return Err(crate::Error::request(
                    "Bevy samples environment maps through a filtering sampler, and \
                        RGBA32F is not filterable in wgpu without a device feature: use \
                        rgba16f, rgb9e5, b10g11r11 or bc6h",
                ))
            }
            Encoding::Rgbd | Encoding::Rgbm => {
                return Err(crate::Error::request(format!(
                    "Bevy's shaders do not decode {}: use rgba16f, rgb9e5, b10g11r11 or bc6h",
                    encoding.label()
                )))
            }
        }
        if !opts.size.is_power_of_two() {
            return Err(crate::Error::request(format!(
                "Bevy's environment maps have power-of-two faces, not {}",
                opts.size
            )));
        }
        let smallest = opts.size.min(opts.background_face());
        if encoding.is_block_compressed() && smallest < 4 {
            return Err(crate::Error::request(format!(
                "{} needs faces of at least 4×4 (one block), not {smallest}",
                encoding.label(),
            )));
        }
        Ok(())
    }

    /// How Bevy looks its cubes up: at `(x, y, −z)` (the module documentation), so its cube
    /// shows at `e` what mirrorball's world shows at `e` mirrored in z.
    fn orientation(&self) -> AxisMap {
        AxisMap::mirror(Axis::Z)
    }

    /// What Bevy takes.
    fn describe(&self) -> Description {
        Description {
        files: "specular.ktx2, diffuse.ktx2 (EnvironmentMapLight), skybox.ktx2 (Skybox)",
        containers: "KTX2 cubes with mips",
        encodings: &[
            DEFAULT_ENCODING,
            Encoding::Rgba16F,
            Encoding::B10G11R11,
            Encoding::Bc6hUnsigned,
            Encoding::Bc6hSigned,
        ],
        zstd: true,
        convention: "Bevy samples cubes at (x, y, -z) (bevy_pbr/src/light_probe/environment_map.wesl:92, skybox.wesl:80, bevy 0.20): both cubes are mirrored in z",
        rule: "mip = perceptual roughness x (levels - 1) (environment_map.wesl:242, environment_map.rs:314): level m of L at m/(L-1), down to 1x1",
        diffuse: "diffuse.ktx2: E/pi, 32x32, one level (environment_map.wesl:380-383)",
        background: Some("skybox.ktx2, the source as a cube, one level, mirrored in z (Skybox, skybox.wesl:80)"),
    }
    }

    /// The files written, for the checks before any work.
    fn file_names(&self, _opts: &BakeOptions) -> Vec<String> {
        vec![
            SPECULAR_FILE.into(),
            DIFFUSE_FILE.into(),
            SKYBOX_FILE.into(),
        ]
    }

    /// Writes Bevy's files into `dir`: [`SPECULAR_FILE`], [`DIFFUSE_FILE`] and [`SKYBOX_FILE`],
    /// from lighting already in Bevy's axes ([`Target::orientation`]).
    fn write(&self, l: &Lighting, dir: &Path, opts: &BakeOptions) -> Result<Vec<PathBuf>, Error> {
        self.check(opts)
            .map_err(|e| Error::request(dir, e.message))?;
        let n = l.specular.len();
        for (i, &r) in l.roughness.iter().enumerate() {
            let want = roughness_of_level(i, n);
            if (r - want).abs() > 1e-9 {
                return Err(Error::request(
                    dir,
                    format!(
                        "specular level {i} of {n} was prefiltered at roughness {r}, but Bevy \
                     reads it as {want}: make the lighting from Engine::Bevy.chain_spec"
                    ),
                ));
            }
        }
        let (Some(diffuse), Some(sky)) = (&l.diffuse, &l.background) else {
            return Err(Error::request(
                dir,
                "Bevy needs a diffuse and a background cube; this lighting lacks one: make it \
             from Engine::Bevy.chain_spec"
                    .into(),
            ));
        };
        let encoding = opts.encoding.unwrap_or(DEFAULT_ENCODING);
        let how = |content: &str| CubeWrite {
            encoding,
            effort: opts.effort,
            zstd: opts.zstd,
            declared: None,
            metadata: vec![
                ("mirrorball:engine".into(), "bevy".into()),
                ("mirrorball:content".into(), content.into()),
                ("mirrorball:source".into(), opts.source.clone()),
            ],
        };
        let specular_path = dir.join(SPECULAR_FILE);
        let levels: Vec<Vec<Image>> = l.specular.iter().map(|m| m.layers().to_vec()).collect();
        write_ktx2(
            &specular_path,
            &levels,
            &how(&format!(
                "GGX radiance, level m of {n} at perceptual roughness m/{}, z mirrored",
                n.max(2) - 1
            )),
        )?;
        let diffuse_path = dir.join(DIFFUSE_FILE);
        write_ktx2(
            &diffuse_path,
            &[diffuse.layers().to_vec()],
            &how("Lambertian irradiance / pi, z mirrored"),
        )?;
        let sky_path = dir.join(SKYBOX_FILE);
        write_ktx2(
            &sky_path,
            &[sky.layers().to_vec()],
            &how("the source as a cube, z mirrored"),
        )?;
        Ok(vec![specular_path, diffuse_path, sky_path])
    }

    /// The note's body: what the files hold and a few lines of Bevy to load them.
    fn readme(&self, opts: &BakeOptions, spec: &ChainSpec) -> String {
        let encoding = opts.encoding.unwrap_or(DEFAULT_ENCODING);
        let level_count = spec.levels.len();
        let levels = mirrorball_core::count(level_count as u64, "level");
        let zstd = match opts.zstd {
            Some(z) => format!(", Zstandard level {z} (Bevy's `zstd_rust` or `zstd_c` feature)"),
            None => String::new(),
        };
        format!(
        "## Loading it\n\n\
         For Bevy's `EnvironmentMapLight`, {enc}{zstd}:\n\n\
         - `{SPECULAR_FILE}`: {size}² faces, {levels} down to 1×1, level m GGX-filtered at\n  \
           perceptual roughness m/{last} (Bevy picks level roughness × (levels − 1)).\n\
         - `{DIFFUSE_FILE}`: {DIFFUSE_FACE}² faces, the irradiance divided by π (Bevy multiplies by\n  \
           the diffuse colour only).\n\
         - `{SKYBOX_FILE}`: {sky}² faces, one level, the source itself for the `Skybox`.\n\n\
         All three are mirrored in z, as Bevy samples cubes at (x, y, −z). Put them under\n\
         `assets/` and:\n\n\
         ```rust\n\
         commands.spawn((\n    \
             Camera3d::default(),\n    \
             EnvironmentMapLight {{\n        \
                 diffuse_map: asset_server.load(\"{DIFFUSE_FILE}\"),\n        \
                 specular_map: asset_server.load(\"{SPECULAR_FILE}\"),\n        \
                 // the texels are the source's values; intensity scales them to cd/m²\n        \
                 intensity: 1.0,\n        \
                 ..default()\n    \
             }},\n    \
             Skybox {{\n        \
                 image: Some(asset_server.load(\"{SKYBOX_FILE}\")),\n        \
                 brightness: 1.0,\n        \
                 ..default()\n    \
             }},\n\
         ));\n\
         ```\n",
        enc = encoding.label(),
        size = opts.size,
        last = level_count.max(2) - 1,
        sky = spec.background_face.unwrap_or(opts.size),
    )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorball_core::{CubeFace, EnvMap, ProjectionKind};

    /// `mirror_z` is `B(x, y, z) = C(x, y, −z)` at every texel centre of every face.
    #[test]
    fn mirror_z_is_the_mirror_at_every_texel() {
        let cube = ProjectionKind::Cube.default_projection();
        let code = |x: f64, y: f64, z: f64| [x as f32, y as f32, z as f32, 1.0];
        let c = EnvMap::from_fn(cube, 8, 3, |d| code(d.x, d.y, d.z));
        let b = c.transformed(&Bevy.orientation()).unwrap();
        for face in CubeFace::ALL {
            for y in 0..8 {
                for x in 0..8 {
                    let (s, t) = ((x as f64 + 0.5) / 4.0 - 1.0, (y as f64 + 0.5) / 4.0 - 1.0);
                    let d = face.point(s, t).normalize();
                    let want = code(d.x, d.y, -d.z);
                    let got = b.layers()[face as usize].get(x, y);
                    for k in 0..3 {
                        assert!(
                            (got[k] - want[k]).abs() < 1e-6,
                            "{} ({x}, {y}) channel {k}: {} for {}",
                            face.name(),
                            got[k],
                            want[k]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn roughness_climbs_to_one_at_1x1() {
        let spec = Bevy.chain_spec(&BakeOptions {
            size: 512,
            ..Default::default()
        });
        assert_eq!(spec.levels.len(), 10);
        assert_eq!(spec.levels[0], (512, 0.0));
        assert_eq!(spec.levels[9], (1, 1.0));
        assert_eq!(spec.levels[3], (64, 3.0 / 9.0));
        assert_eq!(spec.diffuse_face, Some(32));
        assert_eq!(
            spec.background_face,
            Some(512),
            "level 0's until the source says"
        );
    }

    #[test]
    fn refuses_what_bevy_cannot_load() {
        let with = |size, encoding| BakeOptions {
            size,
            encoding,
            ..Default::default()
        };
        assert!(Bevy.check(&with(256, None)).is_ok());
        assert!(Bevy.check(&with(256, Some(Encoding::Bc6hUnsigned))).is_ok());
        for bad in [
            with(256, Some(Encoding::Rgba32F)),
            with(256, Some(Encoding::Rgbd)),
            with(256, Some(Encoding::Rgbm)),
            with(96, None),
            with(2, Some(Encoding::Bc6hSigned)),
        ] {
            let e = Bevy.check(&bad).unwrap_err();
            assert_eq!(e.fault, mirrorball_core::Fault::Request);
            let e = e.to_string();
            assert!(e.contains("Bevy") || e.contains("4×4"), "{e}");
        }
    }
}
