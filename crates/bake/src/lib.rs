//! Image-based lighting baked for an engine: everything one engine needs, written in that
//! engine's convention (handedness, mirroring, face order), with its roughness-to-mip rule,
//! in the containers and texel encodings its own loader takes, and a note saying how to
//! load it.
//!
//! The flow ([`Bake`], what `mirrorball bake` calls): [`Bake::new`] checks the request
//! against the engine before any work (size, texel encoding its loader takes); [`Bake::check`]
//! checks the source can be held (BC6H unsigned of negative values); [`Bake::lighting`]
//! prefilters it as the engine's [`ChainSpec`] says ([`Lighting::from_env`], in mirrorball's
//! world axes) and turns it into the engine's axes ([`Engine::orientation`], an exact texel
//! permutation); [`Bake::write`] writes the engine's files and a README.md into a folder,
//! all landing together. Each engine's rules (files, encodings, convention, roughness-to-mip
//! rule: [`Engine::describe`]) have one home, its module.
//!
//! **The folder is the bake's.** Every engine's files have fixed names (none carries the
//! source's name: [`Engine::file_names`]). A bake records what it wrote in the folder
//! ([`mirrorball_io::Owned`], `.mirrorball-files`): it replaces only files a bake (or
//! another mirrorball command) wrote there, refuses any other before any work
//! ([`Bake::check_folder`], unless [`BakeOptions::overwrite`]), and once its files are in
//! place removes those of the bake it replaced that it did not write again.
//!
//! **The background** (Bevy's `Skybox`, Filament's skybox, three's `scene.background`) is
//! the source itself as a cube, not a level of the chain: its face edge is
//! [`BakeOptions::background_size`], else the source's resolution decides
//! ([`Bake::fit`], [`background_face_for`]).
#![warn(missing_docs)]

mod babylon;
mod bevy;
mod dds;
mod filament;
mod gltf;
mod ktx2;
mod three;

use mirrorball_core::{AxisMap, Choice, EnvMap, Fault, ProjectionKind, ResampleOptions};
use mirrorball_filter::sh::{self, Sh9};
use mirrorball_filter::{Lobe, PrefilterOptions, Prefilterer, RoughnessMapping};
use mirrorball_io::{CubeWrite, Effort, Encoding};
use std::fmt;
use std::path::{Path, PathBuf};

/// Why a bake cannot be done or failed, and whose fault it is.
#[derive(Debug)]
pub struct Error {
    /// The message, naming the file or setting and the problem.
    pub message: String,
    /// Whose fault: the request's (a setting the engine cannot take), the input's, the
    /// system's.
    pub fault: Fault,
}

impl Error {
    /// The request's fault.
    pub fn request(message: impl Into<String>) -> Error {
        Error {
            message: message.into(),
            fault: Fault::Request,
        }
    }
}

impl From<mirrorball_io::Error> for Error {
    fn from(e: mirrorball_io::Error) -> Error {
        Error {
            message: e.to_string(),
            fault: e.fault(),
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Error {}

/// Declares the engines: each row a variant, its names as `--for` takes them (canonical
/// first) and its module's [`Target`]. The one table every engine operation is dispatched
/// through ([`Engine::target`]); [`Engine`], its `Choice` names and [`ENGINES`] come from it.
macro_rules! engines {
    ($($(#[$doc:meta])* $engine:ident: [$($name:literal),+ $(,)?], $target:expr;)+) => {
        /// An engine (or plain API) mirrorball bakes lighting for, named as `--for` takes it.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum Engine {
            $($(#[$doc])* $engine,)+
        }

        impl mirrorball_core::Choice for Engine {
            const NAMES: &'static [(Self, &'static [&'static str])] =
                &[$((Engine::$engine, &[$($name),+]),)+];
        }

        /// Every engine, in the order `--for list` prints them.
        pub const ENGINES: [Engine; [$(stringify!($engine)),+].len()] = [$(Engine::$engine),+];

        impl Engine {
            /// The engine's rules, as its module states them.
            pub(crate) fn target(self) -> &'static dyn Target {
                match self {
                    $(Engine::$engine => &$target,)+
                }
            }
        }
    };
}

engines! {
    /// Bevy: a diffuse and a specular KTX2 cube (`EnvironmentMapLight`).
    Bevy: ["bevy"], bevy::Bevy;
    /// three.js.
    Three: ["three", "threejs", "three.js"], three::Three;
    /// Babylon.js: a `.env` file.
    Babylon: ["babylon", "babylonjs", "babylon.js"], babylon::Babylon;
    /// glTF 2.0 with `EXT_lights_image_based`.
    Gltf: ["gltf", "ext-lights-image-based"], gltf::Gltf;
    /// Filament: KTX1 cubes and SH, as cmgen's `--deploy` writes them.
    Filament: ["filament", "cmgen"], filament::Filament;
    /// Unity: DDS cubes.
    Unity: ["unity"], dds::Dds::Unity;
    /// Unreal Engine: DDS cubes.
    Unreal: ["unreal", "ue", "ue5"], dds::Dds::Unreal;
    /// Plain OpenGL / Vulkan: KTX2 cubes in the OpenGL convention.
    Ktx2: ["ktx2", "opengl", "vulkan"], ktx2::Ktx2;
}
mirrorball_core::choice_traits!(Engine);

/// One engine's rules, each stated once, in its module (`NAME.rs`, a unit type
/// implementing this): what its lighting is made of, what it takes, its axes, its files and
/// how to load them. [`Engine`]'s methods call it through [`Engine::target`].
pub(crate) trait Target: Sync {
    /// Refuses, before any work, what this engine's own rules forbid beyond
    /// [`Bake::new`]'s checks (which every engine shares): nothing by default.
    fn check(&self, _opts: &BakeOptions) -> Result<(), Error> {
        Ok(())
    }

    /// What the engine's lighting is made of, for a bake asked as `opts` says.
    fn chain_spec(&self, opts: &BakeOptions) -> ChainSpec;

    /// What the engine takes and how it reads it.
    fn describe(&self) -> Description;

    /// How a cube in mirrorball's world axes is turned for the engine
    /// ([`Engine::orientation`]).
    fn orientation(&self) -> AxisMap;

    /// The files a bake writes into its folder, besides `README.md`
    /// ([`Engine::file_names`]).
    fn file_names(&self, opts: &BakeOptions) -> Vec<String>;

    /// Writes the engine's files into `dir` (which exists) from lighting already in its
    /// axes; returns the files written.
    fn write(
        &self,
        l: &Lighting,
        dir: &Path,
        opts: &BakeOptions,
    ) -> Result<Vec<PathBuf>, mirrorball_io::Error>;

    /// How to load the files in the engine's own code: the README's body, naming only the
    /// files [`Target::file_names`] lists, by their paths in the folder.
    fn readme(&self, opts: &BakeOptions, spec: &ChainSpec) -> String;

    /// Texels of `spec`'s cubes written as Radiance RGBE rather than in the bake's
    /// encoding (for [`Bake::write_work`]): none by default.
    fn rgbe_texels(&self, _spec: &ChainSpec) -> u64 {
        0
    }
}

/// What an engine's lighting is made of, before any of it is made: the specular levels
/// (each a cube face edge and a GGX perceptual roughness, in the order the engine stores
/// them), the diffuse (irradiance) cube's face edge, if the engine takes one, and the
/// background cube's, if it takes one.
#[derive(Clone, Debug, PartialEq)]
pub struct ChainSpec {
    /// `(face edge, perceptual roughness)` of each specular level.
    pub levels: Vec<(u32, f64)>,
    /// The diffuse cube's face edge, or `None` when the engine's diffuse light is SH only.
    pub diffuse_face: Option<u32>,
    /// The background cube's face edge (the source resampled, not filtered), or `None` when
    /// the engine's files hold no background.
    pub background_face: Option<u32>,
}

impl ChainSpec {
    /// Every cube the prefilterer renders: `(lobe, projection, width, height)`.
    fn outputs(&self) -> Vec<(Lobe, mirrorball_core::Projection, u32, u32)> {
        let cube = ProjectionKind::Cube.default_projection();
        let mut outputs: Vec<_> = self
            .levels
            .iter()
            .map(|&(face, roughness)| (Lobe::Ggx { roughness }, cube, face, face))
            .collect();
        if let Some(face) = self.diffuse_face {
            outputs.push((Lobe::Lambert, cube, face, face));
        }
        outputs
    }
}

/// What an engine takes and how it reads it, for people (`--for list`, the README) and for
/// the checks of a request: each engine's module says it once.
#[derive(Clone, Debug)]
pub struct Description {
    /// The files written, for people.
    pub files: &'static str,
    /// The containers.
    pub containers: &'static str,
    /// The texel encodings its loader takes, the default first.
    pub encodings: &'static [Encoding],
    /// Whether its loader takes Zstandard-supercompressed KTX2.
    pub zstd: bool,
    /// How the engine's axes and cube lookups differ from mirrorball's, with the source it
    /// is read from.
    pub convention: &'static str,
    /// The roughness-to-level rule in words (the engine's own formula and where it is).
    pub rule: &'static str,
    /// What lights diffuse surfaces.
    pub diffuse: &'static str,
    /// The file that holds the background (the source as a cube, at the background size),
    /// if the engine takes one.
    pub background: Option<&'static str>,
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
    /// The roughness of each level, or `None` for the engine's own rule.
    pub mapping: Option<RoughnessMapping>,
    /// The source file's name, recorded in notes and metadata.
    pub source: String,
    /// The background cube's face edge (a power of two), or `None` for the one the
    /// source's resolution gives ([`background_face_for`], settled by [`Bake::fit`]).
    pub background_size: Option<u32>,
    /// Replace files in the folder that no mirrorball run wrote (else they are refused).
    pub overwrite: bool,
}

impl Default for BakeOptions {
    fn default() -> Self {
        BakeOptions {
            size: 256,
            encoding: None,
            effort: Effort::default(),
            zstd: None,
            mapping: None,
            source: String::new(),
            background_size: None,
            overwrite: false,
        }
    }
}

impl BakeOptions {
    /// The encoding asked for, else `engine`'s default.
    pub fn encoding_for(&self, engine: Engine) -> Encoding {
        self.encoding
            .or_else(|| engine.describe().encodings.first().copied())
            .unwrap_or_default()
    }

    /// The background's face edge until the source is known: `background_size`, else
    /// level 0's ([`Bake::fit`] then puts the source's in its place).
    pub(crate) fn background_face(&self) -> u32 {
        self.background_size.unwrap_or(self.size)
    }
}

/// Largest level-0 (and background) face edge a bake takes: the largest cube face GPUs
/// take ([`mirrorball_io::MAX_CUBE_FACE`]).
pub const MAX_SIZE: u32 = mirrorball_io::MAX_CUBE_FACE;

/// The background's face edges chosen from a source's resolution: at least this …
pub const MIN_BACKGROUND: u32 = 16;
/// … and at most this (an 8K lat-long's texel density; each doubling is four times the
/// bytes an engine keeps in memory for the sky).
pub const MAX_BACKGROUND: u32 = 2048;

/// The background cube's face edge for `env`: the power of two that keeps its texels per
/// steradian ([`EnvMap::natural_size`]), within [`MIN_BACKGROUND`]`..=`[`MAX_BACKGROUND`].
/// An 8192×4096 lat-long gives 2048², a 2048×1024 one 512².
pub fn background_face_for(env: &EnvMap) -> u32 {
    env.natural_size(ProjectionKind::Cube)
        .clamp(MIN_BACKGROUND, MAX_BACKGROUND)
}

/// Prefiltered lighting, cube faces in OpenGL order and orientation: in mirrorball's world
/// axes as [`Lighting::from_env`] makes it, in the engine's once [`Lighting::oriented`]
/// (what each engine's writer gets). Shaped as an engine's [`ChainSpec`] asked.
#[derive(Clone, Debug)]
pub struct Lighting {
    /// The specular levels, cubes, level `i` GGX-prefiltered at `roughness[i]`.
    pub specular: Vec<EnvMap>,
    /// The perceptual roughness of each specular level.
    pub roughness: Vec<f64>,
    /// The irradiance cube, divided by π (the radiance a white Lambertian surface reflects),
    /// level 0 only; `None` when the spec asked for none.
    pub diffuse: Option<EnvMap>,
    /// The background: the source resampled into a cube (antialiased, not prefiltered);
    /// `None` when the spec asked for none.
    pub background: Option<EnvMap>,
    /// The radiance's SH9 (orthonormal real basis, world axes: `mirrorball_filter::sh`).
    pub sh9: Sh9,
}

impl Lighting {
    /// Prefilters `env` (any projection, sanitized) into `spec`'s levels, the diffuse cube
    /// from the exact Lambert integral, and the SH9; resamples it into the background cube.
    pub fn from_env(env: &EnvMap, spec: &ChainSpec, opts: PrefilterOptions) -> Lighting {
        let progress = opts.progress.clone();
        let cube = ProjectionKind::Cube.default_projection();
        let lobes: Vec<Lobe> = spec
            .levels
            .iter()
            .map(|&(_, roughness)| Lobe::Ggx { roughness })
            .collect();
        let pre = Prefilterer::for_outputs(env, &spec.outputs(), opts);
        let specular = spec
            .levels
            .iter()
            .zip(&lobes)
            .map(|(&(face, _), lobe)| pre.render_extent(lobe, cube, face, face))
            .collect();
        let diffuse = spec
            .diffuse_face
            .map(|face| pre.render_extent(&Lobe::Lambert, cube, face, face));
        // The sky's rows counted as they are made, each its share of the cube's work.
        let background = spec.background_face.map(|face| {
            let rows = 6 * face as u64;
            let opts = ResampleOptions {
                progress: progress.clone(),
                progress_unit: mirrorball_filter::cube_work(env, face) / rows,
                ..ResampleOptions::default()
            };
            mirrorball_core::resample(env, cube, face, &opts)
        });
        Lighting {
            specular,
            roughness: spec.levels.iter().map(|&(_, r)| r).collect(),
            diffuse,
            background,
            sh9: sh::project(env),
        }
    }

    /// The same lighting seen through `map` (an engine's axes): every cube's texels moved
    /// exactly ([`EnvMap::transformed`]), the SH turned with them.
    pub fn oriented(self, map: &AxisMap) -> Lighting {
        if map.is_identity() {
            return self;
        }
        let turn = |e: EnvMap| e.transformed(map).expect("the lighting's maps are cubes");
        Lighting {
            specular: self.specular.into_iter().map(turn).collect(),
            roughness: self.roughness,
            diffuse: self.diffuse.map(turn),
            background: self.background.map(turn),
            sh9: self.sh9.transformed(map),
        }
    }
}

impl Engine {
    /// Refuses, before any work, what this engine's own rules forbid beyond
    /// [`Bake::new`]'s checks (which every engine shares: size, encodings, Zstandard).
    pub fn check(self, opts: &BakeOptions) -> Result<(), Error> {
        self.target().check(opts)
    }

    /// What this engine's lighting is made of, for a bake asked as `opts` says.
    pub fn chain_spec(self, opts: &BakeOptions) -> ChainSpec {
        self.target().chain_spec(opts)
    }

    /// What the engine takes and how it reads it.
    pub fn describe(self) -> Description {
        self.target().describe()
    }

    /// How a cube in mirrorball's world axes is turned for the engine: the engine, looking
    /// up its cube at direction `e`, must see what mirrorball's world shows at
    /// `orientation().source_of(e)`. The one place each engine's convention is applied
    /// (`bake`, and `convert --for`).
    pub fn orientation(self) -> AxisMap {
        self.target().orientation()
    }

    /// The files a bake writes into its folder, besides `README.md`, relative to it (`/`
    /// between folders), for the checks before any work. One rule for every engine: the
    /// folder is the bake's, so the names are the engine's own, never the source's (only
    /// how many there are may depend on `opts`: glTF's images per level).
    pub fn file_names(self, opts: &BakeOptions) -> Vec<String> {
        self.target().file_names(opts)
    }
}

/// Writes `lighting` (in mirrorball's world axes) as `engine` loads it, into the folder
/// `dir` (which exists): turned into the engine's axes, then its files. Returns the files
/// written. (Without the README and the landing together: that is [`Bake::write`].)
pub fn write(
    engine: Engine,
    lighting: &Lighting,
    dir: &Path,
    opts: &BakeOptions,
) -> Result<Vec<PathBuf>, Error> {
    let opts = &BakeOptions {
        encoding: Some(opts.encoding_for(engine)),
        ..opts.clone()
    };
    let map = engine.orientation();
    let turned;
    let l = if map.is_identity() {
        lighting
    } else {
        turned = lighting.clone().oriented(&map);
        &turned
    };
    Ok(engine.target().write(l, dir, opts)?)
}

/// The note every bake writes beside its files.
pub const README: &str = "README.md";

/// A bake, checked against its engine before any work: the pipeline `mirrorball bake`
/// runs (read and prepare the source, [`Bake::check`], [`Bake::lighting`], [`Bake::write`]).
#[derive(Clone, Debug)]
pub struct Bake {
    /// The engine.
    pub engine: Engine,
    /// As asked, with the encoding and mapping settled.
    pub opts: BakeOptions,
    /// What will be made.
    pub spec: ChainSpec,
}

impl Bake {
    /// Checks the request against the engine: a writer for it in this build, the size (a
    /// power of two, `1..=MAX_SIZE`), a background size only for an engine that takes a
    /// background (a power of two too), an encoding its loader takes, supercompression only
    /// where it reads it.
    pub fn new(engine: Engine, mut opts: BakeOptions) -> Result<Bake, Error> {
        let d = engine.describe();
        let s = opts.size;
        if s == 0 || s > MAX_SIZE || !s.is_power_of_two() {
            return Err(Error::request(format!(
                "size {s}: a cube's mip chain halves exactly only from a power of two; give one of 1, 2, 4 … {MAX_SIZE}"
            )));
        }
        if let Some(b) = opts.background_size {
            check_background_size(engine, b)?;
        }
        let encoding = opts.encoding_for(engine);
        if !d.encodings.contains(&encoding) {
            let names: Vec<&str> = d.encodings.iter().map(|e| e.name()).collect();
            return Err(Error::request(format!(
                "{engine} does not load {} ({}); it takes {}",
                encoding.name(),
                d.containers,
                names.join(", ")
            )));
        }
        if opts.zstd.is_some() && !d.zstd {
            return Err(Error::request(format!(
                "{engine}: Zstandard supercompression is for KTX2, which {engine} does not load ({})",
                d.containers
            )));
        }
        engine.check(&opts)?;
        opts.encoding = Some(encoding);
        let spec = engine.chain_spec(&opts);
        Ok(Bake { engine, opts, spec })
    }

    /// The texel encoding.
    pub fn encoding(&self) -> Encoding {
        self.opts.encoding_for(self.engine)
    }

    /// Refuses a source the encoding cannot hold (negative values as unsigned BC6H), right
    /// after reading, before any prefiltering: GGX and Lambert of non-negative radiance are
    /// non-negative, so the source decides.
    pub fn check(&self, env: &EnvMap) -> Result<(), Error> {
        let encoding = self.encoding();
        for layer in env.layers() {
            encoding.check(layer).map_err(|e| {
                Error::request(format!(
                    "{}: {} for {}: {e}",
                    self.opts.source,
                    encoding.name(),
                    self.engine
                ))
            })?;
        }
        Ok(())
    }

    /// Settles what the source decides, once it is read: the background's face edge, when
    /// none was asked for ([`background_face_for`]).
    pub fn fit(&mut self, env: &EnvMap) {
        if self.opts.background_size.is_none() {
            if let Some(face) = self.spec.background_face.as_mut() {
                *face = background_face_for(env);
            }
        }
    }

    /// The work of [`Bake::lighting`] from `env` with `opts`, in the units its
    /// [`PrefilterOptions::progress`] counts (`mirrorball_filter::work`): the prefilter and
    /// the sky's cube.
    pub fn lighting_work(&self, env: &EnvMap, opts: &PrefilterOptions) -> u64 {
        let cube = ProjectionKind::Cube.default_projection();
        let mut outputs: Vec<(Lobe, mirrorball_core::Projection, u32, u32)> = self
            .spec
            .levels
            .iter()
            .map(|&(face, roughness)| (Lobe::Ggx { roughness }, cube, face, face))
            .collect();
        if let Some(face) = self.spec.diffuse_face {
            outputs.push((Lobe::Lambert, cube, face, face));
        }
        mirrorball_filter::work(env, &outputs, opts)
            + self
                .spec
                .background_face
                .map_or(0, |face| mirrorball_filter::cube_work(env, face))
    }

    /// About the work of [`Bake::write_into`], in `mirrorball_core::work`'s units (what the
    /// encoders and container writers count there): every cube encoded in the bake's
    /// encoding, and supercompressed when asked.
    pub fn write_work(&self) -> u64 {
        let rgbe = self.engine.target().rgbe_texels(&self.spec);
        let texels = self.texels() - rgbe;
        let encoding = self.encoding();
        let zstd = self.opts.zstd.map_or(0, |_| {
            let bytes = encoding.image_bytes(1024, 1024) as u64 * texels / (1024 * 1024);
            mirrorball_io::zstd_work(bytes)
        });
        encoding.work(texels) + zstd + mirrorball_io::rgbe_work(rgbe)
    }

    /// Texels of every cube made (four `f32` channels each), for the memory estimate.
    pub fn texels(&self) -> u64 {
        let sq = |f: u32| 6 * f as u64 * f as u64;
        self.spec.levels.iter().map(|&(f, _)| sq(f)).sum::<u64>()
            + self.spec.diffuse_face.map_or(0, sq)
            + self.spec.background_face.map_or(0, sq)
    }

    /// Bytes a bake of `env` holds at its peak, `env` included: while
    /// [`lighting`](Self::lighting)`(env, opts)` works, `env`, the cubes made
    /// ([`texels`](Self::texels), `env`'s channels) and the prefilterer
    /// ([`Prefilterer::memory_for_outputs`]) with the background's conversion, made while
    /// it is held, or, the prefilterer gone, the copy of the largest cube being turned into
    /// the engine's axes; while [`write_into`](Self::write_into) writes (`env` dropped by
    /// then), the cubes, a copy of one file's cubes for its writer and their encoded texels
    /// (twice with Zstandard: the level and its compressed copy).
    pub fn memory(&self, env: &EnvMap, opts: &PrefilterOptions) -> u64 {
        let cube = ProjectionKind::Cube.default_projection();
        let c = env.channels() as u64;
        let source = env.width() as u64 * env.height() as u64 * env.layers().len() as u64 * c * 4;
        let made = self.texels() * c * 4;
        let working = Prefilterer::memory_for_outputs(env, &self.spec.outputs(), opts);
        let background = self.spec.background_face.map_or(0, |f| {
            mirrorball_core::resample_memory(env, cube, (f, f), &ResampleOptions::default())
        });
        let sq = |f: u32| 6 * f as u64 * f as u64;
        let turned = match self.engine.orientation().is_identity() {
            true => 0,
            false => {
                let largest = self
                    .spec
                    .levels
                    .iter()
                    .map(|&(f, _)| f)
                    .chain(self.spec.diffuse_face)
                    .chain(self.spec.background_face)
                    .max()
                    .unwrap_or(0);
                sq(largest) * c * 4
            }
        };
        let making = source + made + (working + background).max(turned);
        let file = self
            .spec
            .levels
            .iter()
            .map(|&(f, _)| sq(f))
            .sum::<u64>()
            .max(self.spec.background_face.map_or(0, sq));
        let encoded = file * encoded_bytes(self.opts.encoding.unwrap_or_default());
        let writing = made + file * c * 4 + encoded * if self.opts.zstd.is_some() { 2 } else { 1 };
        making.max(writing)
    }

    /// The lighting, prefiltered from `env` (sanitized, checked) and turned into the
    /// engine's axes.
    pub fn lighting(&self, env: &EnvMap, opts: PrefilterOptions) -> Lighting {
        Lighting::from_env(env, &self.spec, opts).oriented(&self.engine.orientation())
    }

    /// Every file the bake writes into its folder, relative to it: the engine's and
    /// `README.md`.
    pub fn file_names(&self) -> Vec<String> {
        let mut names = self.engine.file_names(&self.opts);
        names.push(README.to_string());
        names
    }

    /// Refuses, before any work, to replace a file in `dir` that no mirrorball run wrote
    /// (its record, [`mirrorball_io::Owned`], does not list it), unless
    /// [`BakeOptions::overwrite`]: the message names the file. A folder that does not
    /// exist yet holds none.
    pub fn check_folder(&self, dir: &Path) -> Result<(), Error> {
        let owned = mirrorball_io::Owned::read(dir)?;
        Ok(owned.check(&self.file_names(), self.opts.overwrite)?)
    }

    /// [`Bake::write_into`], returning the files written.
    pub fn write(&self, lighting: &Lighting, dir: &Path) -> Result<Vec<PathBuf>, Error> {
        self.write_into(lighting, dir).map(|w| w.files)
    }

    /// Writes the engine's files and `README.md` into `dir` (made if missing), with the
    /// folder's record of them, all landing together: on an error (or an interrupt) none is
    /// left and old files stay as they were, and a folder made for them is removed again.
    /// First refuses as [`Bake::check_folder`] does; once the files are in place, removes
    /// the files of the bake this one replaces that it did not write again.
    /// `lighting` is in the engine's axes ([`Bake::lighting`]).
    pub fn write_into(&self, lighting: &Lighting, dir: &Path) -> Result<Written, Error> {
        let mut owned = mirrorball_io::Owned::read(dir)?;
        owned.check(&self.file_names(), self.opts.overwrite)?;
        let made = make_dir(dir)?;
        if made {
            mirrorball_io::made_folder(dir);
        }
        let result = mirrorball_io::write_together(|| {
            let files = self.engine.target().write(lighting, dir, &self.opts)?;
            write_text(&dir.join(README), &self.readme(dir, &files))?;
            let mut names = relative(dir, &files);
            names.push(README.to_string());
            let stale = owned.replace(WRITER, &names);
            owned.write()?;
            Ok(stale)
        });
        if made {
            mirrorball_io::keep_folder(dir);
        }
        match result {
            Ok((stale, mut files)) => {
                files.retain(|f| f.file_name() != Some(mirrorball_io::RECORD.as_ref()));
                let removed = owned.remove(&stale);
                Ok(Written { files, removed })
            }
            Err(e) => {
                if made {
                    let _ = std::fs::remove_dir(dir);
                }
                Err(e.into())
            }
        }
    }

    /// The README: what was baked, each file, the engine's rules, and how to load it.
    fn readme(&self, dir: &Path, files: &[PathBuf]) -> String {
        let d = self.engine.describe();
        let names: Vec<String> = relative(dir, files)
            .iter()
            .map(|n| format!("`{n}`"))
            .collect();
        let background = match (d.background, self.spec.background_face) {
            (Some(what), Some(face)) => format!("- Background: {what}, {face}² faces\n"),
            _ => String::new(),
        };
        format!(
            "# Image-based lighting for {engine}\n\n\
             Baked by mirrorball {version} from `{source}`: a {size}² GGX chain of {levels}, \
             {encoding}.\n\n\
             - Files: {names}\n\
             - Convention: {convention}\n\
             - Roughness to level: {rule}\n\
             - Diffuse: {diffuse}\n{background}\n{body}",
            engine = self.engine,
            version = env!("CARGO_PKG_VERSION"),
            source = self.opts.source,
            size = self.opts.size,
            levels = mirrorball_core::count(self.spec.levels.len() as u64, "level"),
            encoding = self.encoding().label(),
            names = names.join(", "),
            convention = d.convention,
            rule = d.rule,
            diffuse = d.diffuse,
            body = self.engine.target().readme(&self.opts, &self.spec),
        )
    }
}

/// Who a bake's files are recorded as written by, in the folder's record.
const WRITER: &str = "bake";

/// What [`Bake::write_into`] did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Written {
    /// The files written (the engine's, then `README.md`), in place.
    pub files: Vec<PathBuf>,
    /// The files of the bake this one replaced that it did not write again, removed.
    pub removed: Vec<PathBuf>,
}

/// Refuses a background size that is not a power of two in `1..=MAX_SIZE`, or any for an
/// engine whose files hold no background.
fn check_background_size(engine: Engine, b: u32) -> Result<(), Error> {
    if engine.describe().background.is_none() {
        let takers: Vec<String> = ENGINES
            .iter()
            .filter(|e| e.describe().background.is_some())
            .map(|e| e.to_string())
            .collect();
        return Err(Error::request(format!(
            "background size {b}: {engine}'s files hold no background (those of {} do)",
            takers.join(", ")
        )));
    }
    if b == 0 || b > MAX_SIZE || !b.is_power_of_two() {
        return Err(Error::request(format!(
            "background size {b}: give a power of two, 1, 2, 4 … {MAX_SIZE}"
        )));
    }
    Ok(())
}

/// `files` (inside `dir`) relative to `dir`, `/` between folders.
fn relative(dir: &Path, files: &[PathBuf]) -> Vec<String> {
    files
        .iter()
        .map(|f| {
            let rel = f.strip_prefix(dir).unwrap_or(f);
            let parts: Vec<String> = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            parts.join("/")
        })
        .collect()
}

/// Makes `dir` (and its parents) when missing; `true` when it made the folder itself.
fn make_dir(dir: &Path) -> Result<bool, Error> {
    if dir.is_dir() {
        return Ok(false);
    }
    std::fs::create_dir_all(dir)
        .map_err(|e| Error::from(mirrorball_io::Error::io(dir, e)))
        .map(|()| true)
}

/// A lat-long map whose every texel holds its own direction as colour, `½ + ½·d` (so any
/// axis flip, mirroring or turn shows): the input of the tests that check an engine sees
/// the world the right way round.
pub fn direction_coded(width: u32) -> EnvMap {
    EnvMap::from_fn(
        ProjectionKind::LatLong.default_projection(),
        width,
        3,
        |d| {
            [
                (0.5 + 0.5 * d.x) as f32,
                (0.5 + 0.5 * d.y) as f32,
                (0.5 + 0.5 * d.z) as f32,
                1.0,
            ]
        },
    )
}

/// `--for list`: each engine with what it writes, one block an engine.
pub fn list() -> String {
    let mut out = String::new();
    for e in ENGINES {
        let d = e.describe();
        let encodings: Vec<&str> = d.encodings.iter().map(|e| e.name()).collect();
        let encodings = match encodings.split_first() {
            Some((first, [])) => first.to_string(),
            Some((first, rest)) => format!("{first} (default), {}", rest.join(", ")),
            None => String::new(),
        };
        out += &format!(
            "{e}\n  files:       {}\n  containers:  {}{}\n  encodings:   {encodings}\n  convention:  {}\n  cube turn:   the engine's direction (x, y, z) shows mirrorball's {}\n  roughness:   {}\n  diffuse:     {}\n  background:  {}\n",
            d.files,
            d.containers,
            if d.zstd { ", Zstandard supercompression" } else { "" },
            d.convention,
            e.orientation(),
            d.rule,
            d.diffuse,
            d.background.unwrap_or("none written"),
        );
    }
    out
}

/// The full mip chain of `size` down to 1×1, each level at the roughness `rule(i, n)`
/// gives level `i` of `n`.
pub(crate) fn mip_levels(size: u32, rule: impl Fn(usize, usize) -> f64) -> Vec<(u32, f64)> {
    let n = (32 - size.max(1).leading_zeros()) as usize;
    (0..n).map(|i| ((size >> i).max(1), rule(i, n))).collect()
}

/// The full chain at `mapping`'s roughness (the user's mapping when given).
pub(crate) fn chain_by(opts: &BakeOptions, mapping: &RoughnessMapping) -> Vec<(u32, f64)> {
    let mapping = opts.mapping.as_ref().unwrap_or(mapping);
    mip_levels(opts.size, |i, n| mapping.roughness(i, n))
}

/// Each level's faces, as the cube writers take them.
pub(crate) fn faces(levels: &[EnvMap]) -> Vec<Vec<mirrorball_core::Image>> {
    levels.iter().map(|l| l.layers().to_vec()).collect()
}

/// Bytes of one texel in `encoding`.
fn encoded_bytes(encoding: Encoding) -> u64 {
    match encoding {
        Encoding::Rgba32F => 16,
        Encoding::Rgba16F => 8,
        Encoding::Rgb9E5 | Encoding::B10G11R11 | Encoding::Rgbd | Encoding::Rgbm => 4,
        Encoding::Bc6hUnsigned | Encoding::Bc6hSigned => 1,
    }
}

/// How each cube of a bake is written: its encoding, effort and supercompression, recorded
/// as a cube map, with `metadata`.
pub(crate) fn cube_write(opts: &BakeOptions, metadata: Vec<(String, String)>) -> CubeWrite {
    CubeWrite {
        encoding: opts.encoding.unwrap_or_default(),
        effort: opts.effort,
        zstd: opts.zstd,
        declared: Some(mirrorball_io::MapInfo {
            projection: ProjectionKind::Cube.default_projection(),
            layout: None,
            stereo: Default::default(),
        }),
        metadata,
    }
}

/// Writes `text` to `path`.
pub(crate) fn write_text(path: &Path, text: &str) -> Result<(), mirrorball_io::Error> {
    mirrorball_io::atomic_write(path, |w| {
        use std::io::Write;
        w.write_all(text.as_bytes())
            .map_err(|e| mirrorball_io::Error::io(path, e))
    })
}

/// The file names of `files`, for notes.
pub(crate) fn names(files: &[PathBuf]) -> Vec<String> {
    files
        .iter()
        .filter_map(|f| f.file_name())
        .map(|n| n.to_string_lossy().into_owned())
        .collect()
}
