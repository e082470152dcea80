//! Image-based lighting baked for an engine: everything one engine needs, written in that
//! engine's convention (handedness, mirroring, face order), with its roughness-to-mip rule,
//! in the containers and texel encodings its own loader takes, and a note saying how to
//! load it.
//!
//! The flow: an [`Engine`] says what it needs ([`Engine::chain_spec`]: the specular levels'
//! sizes and GGX roughness, the diffuse map's size); [`Lighting::from_env`] prefilters the
//! source into that, in mirrorball's world axes (ARCHITECTURE.md's conventions); then
//! [`write`] turns it into the engine's files. Each engine's rules have one home, its module.
#![warn(missing_docs)]

mod babylon;
mod bevy;
mod dds;
mod filament;
mod gltf;
mod ktx2;
mod three;

use mirrorball_core::{EnvMap, ProjectionKind};
use mirrorball_filter::sh::{self, Sh9};
use mirrorball_filter::{Lobe, PrefilterOptions, Prefilterer};
use mirrorball_io::{Effort, Encoding, Error};
use std::path::{Path, PathBuf};

/// An engine (or plain API) mirrorball bakes lighting for, named as `--for` takes it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Engine {
    /// Bevy: a diffuse and a specular KTX2 cube (`EnvironmentMapLight`).
    Bevy,
    /// three.js.
    Three,
    /// Babylon.js: a `.env` file.
    Babylon,
    /// glTF 2.0 with `EXT_lights_image_based`.
    Gltf,
    /// Filament: KTX1 cubes and SH, as cmgen's `--deploy` writes them.
    Filament,
    /// Unity: DDS cubes.
    Unity,
    /// Unreal Engine: DDS cubes.
    Unreal,
    /// Plain OpenGL / Vulkan: KTX2 cubes in the OpenGL convention.
    Ktx2,
}

impl mirrorball_core::Choice for Engine {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (Engine::Bevy, &["bevy"]),
        (Engine::Three, &["three", "threejs", "three.js"]),
        (Engine::Babylon, &["babylon", "babylonjs", "babylon.js"]),
        (Engine::Gltf, &["gltf", "ext-lights-image-based"]),
        (Engine::Filament, &["filament", "cmgen"]),
        (Engine::Unity, &["unity"]),
        (Engine::Unreal, &["unreal", "ue", "ue5"]),
        (Engine::Ktx2, &["ktx2", "opengl", "vulkan"]),
    ];
}
mirrorball_core::choice_traits!(Engine);

/// What an engine's lighting is made of, before any of it is made: the specular levels
/// (each a cube face edge and a GGX perceptual roughness, in the order the engine stores
/// them) and the diffuse (irradiance) cube's face edge, if the engine takes one.
#[derive(Clone, Debug, PartialEq)]
pub struct ChainSpec {
    /// `(face edge, perceptual roughness)` of each specular level.
    pub levels: Vec<(u32, f64)>,
    /// The diffuse cube's face edge, or `None` when the engine's diffuse light is SH only.
    pub diffuse_face: Option<u32>,
}

/// How a bake is asked for, beyond the engine: the specular chain's level-0 face edge, the
/// texel encoding (each engine has a default), the encoder's effort and supercompression.
#[derive(Clone, Debug)]
pub struct BakeOptions {
    /// Level 0's face edge (a power of two).
    pub size: u32,
    /// The texel encoding, or `None` for the engine's default.
    pub encoding: Option<Encoding>,
    /// How hard the BC6H encoder searches.
    pub effort: Effort,
    /// Zstandard level for KTX2 supercompression, or `None`.
    pub zstd: Option<i32>,
    /// The source file's name, recorded in notes and metadata.
    pub source: String,
}

impl Default for BakeOptions {
    fn default() -> Self {
        BakeOptions {
            size: 256,
            encoding: None,
            effort: Effort::default(),
            zstd: None,
            source: String::new(),
        }
    }
}

/// Prefiltered lighting in mirrorball's world axes (cube faces in OpenGL order and
/// orientation), shaped as an engine's [`ChainSpec`] asked: what [`write`] turns into files.
pub struct Lighting {
    /// The specular levels, cubes, level `i` GGX-prefiltered at `roughness[i]`.
    pub specular: Vec<EnvMap>,
    /// The perceptual roughness of each specular level.
    pub roughness: Vec<f64>,
    /// The irradiance cube, divided by π (the radiance a white Lambertian surface reflects),
    /// level 0 only; `None` when the spec asked for none.
    pub diffuse: Option<EnvMap>,
    /// The radiance's SH9 (orthonormal real basis, world axes: `mirrorball_filter::sh`).
    pub sh9: Sh9,
}

impl Lighting {
    /// Prefilters `env` (any projection, sanitized) into `spec`'s levels, the diffuse cube
    /// from the exact Lambert integral, and the SH9.
    pub fn from_env(env: &EnvMap, spec: &ChainSpec, opts: PrefilterOptions) -> Lighting {
        let cube = ProjectionKind::Cube.default_projection();
        let lobes: Vec<Lobe> = spec
            .levels
            .iter()
            .map(|&(_, roughness)| Lobe::Ggx { roughness })
            .collect();
        let mut outputs: Vec<(Lobe, mirrorball_core::Projection, u32, u32)> = spec
            .levels
            .iter()
            .zip(&lobes)
            .map(|(&(face, _), lobe)| (*lobe, cube, face, face))
            .collect();
        if let Some(face) = spec.diffuse_face {
            outputs.push((Lobe::Lambert, cube, face, face));
        }
        let pre = Prefilterer::for_outputs(env, &outputs, opts);
        let specular = spec
            .levels
            .iter()
            .zip(&lobes)
            .map(|(&(face, _), lobe)| pre.render_extent(lobe, cube, face, face))
            .collect();
        let diffuse = spec
            .diffuse_face
            .map(|face| pre.render_extent(&Lobe::Lambert, cube, face, face));
        Lighting {
            specular,
            roughness: spec.levels.iter().map(|&(_, r)| r).collect(),
            diffuse,
            sh9: sh::project(env),
        }
    }
}

impl Engine {
    /// What this engine's lighting is made of, for a bake asked as `opts` says.
    pub fn chain_spec(self, opts: &BakeOptions) -> ChainSpec {
        match self {
            Engine::Bevy => bevy::chain_spec(opts),
            Engine::Three => three::chain_spec(opts),
            Engine::Babylon => babylon::chain_spec(opts),
            Engine::Gltf => gltf::chain_spec(opts),
            Engine::Filament => filament::chain_spec(opts),
            Engine::Unity | Engine::Unreal => dds::chain_spec(self, opts),
            Engine::Ktx2 => ktx2::chain_spec(opts),
        }
    }

    /// Refuses, before any work, what this engine's files cannot be as `opts` asks (an
    /// encoding its loader or shaders do not take, a size it cannot hold).
    pub fn check(self, opts: &BakeOptions) -> Result<(), String> {
        match self {
            Engine::Bevy => bevy::check(opts),
            _ => Ok(()),
        }
    }
}

/// Writes `lighting` as `engine` loads it, into the folder `dir` (which exists); returns
/// the files written.
pub fn write(
    engine: Engine,
    lighting: &Lighting,
    dir: &Path,
    opts: &BakeOptions,
) -> Result<Vec<PathBuf>, Error> {
    match engine {
        Engine::Bevy => bevy::write(lighting, dir, opts),
        Engine::Three => three::write(lighting, dir, opts),
        Engine::Babylon => babylon::write(lighting, dir, opts),
        Engine::Gltf => gltf::write(lighting, dir, opts),
        Engine::Filament => filament::write(lighting, dir, opts),
        Engine::Unity | Engine::Unreal => dds::write(engine, lighting, dir, opts),
        Engine::Ktx2 => ktx2::write(lighting, dir, opts),
    }
}

/// The full mip chain of `size` down to 1×1, each level at the roughness `rule(i, n)`
/// gives level `i` of `n`.
pub(crate) fn mip_levels(size: u32, rule: impl Fn(usize, usize) -> f64) -> Vec<(u32, f64)> {
    let n = (32 - size.max(1).leading_zeros()) as usize;
    (0..n).map(|i| ((size >> i).max(1), rule(i, n))).collect()
}

/// The error of an engine whose writer is not in this build.
pub(crate) fn not_written(dir: &Path, engine: &str) -> Error {
    Error::request(dir, format!("baking for {engine} is not written yet"))
}
