//! `BakeArgs → Plan`: the engine (or `list`), the bake checked against it
//! (`mirrorball_bake::Bake::new`: size, encoding, supercompression), the output folder and
//! every file it will hold, checked before any file is read.

use crate::choice::parse_flag;
use crate::commands::InputPlan;
use crate::error::CliError;
use crate::guard::Files;
use crate::BakeArgs;
use mirrorball_bake::{Bake, BakeOptions, Engine};
use mirrorball_filter::{PrefilterOptions, RoughnessMapping};
use mirrorball_io::{Effort, Encoding};
use std::path::{Path, PathBuf};

/// What `bake` will do.
pub(super) enum Plan {
    /// `--for list`: print the engines.
    List,
    /// Bake for an engine.
    Bake(Box<BakePlan>),
}

/// A bake, checked.
pub(super) struct BakePlan {
    pub input: InputPlan,
    pub source: String,
    pub dir: PathBuf,
    pub bake: Bake,
    pub prefilter: PrefilterOptions,
    pub quiet: bool,
}

impl Plan {
    pub fn new(a: &BakeArgs) -> Result<Plan, CliError> {
        if a.engine.eq_ignore_ascii_case("list") {
            return Ok(Plan::List);
        }
        let engine = parse_flag::<Engine>("--for", &a.engine).map_err(|e| {
            CliError::request(format!("{} (or list, to see what each writes)", e.message))
        })?;
        let (Some(source), Some(out)) = (&a.input, &a.out_dir) else {
            return Err(CliError::request(
                "bake needs the input map and the output folder: mirrorball bake IN --for ENGINE OUT-DIR",
            ));
        };
        let input = crate::commands::input_plan(&a.input_args)?;
        let encoding = a
            .encoding
            .as_deref()
            .map(|e| parse_flag::<Encoding>("--encoding", e))
            .transpose()?;
        let effort = parse_flag::<Effort>("--effort", &a.effort)?;
        let mapping = a
            .mapping
            .as_deref()
            .map(|m| {
                RoughnessMapping::parse(m).ok_or_else(|| {
                    CliError::request(format!(
                        "--mapping: '{m}' is not linear, ue4, filament or a list of roughness values in [0, 1]"
                    ))
                })
            })
            .transpose()?;
        if let Some(l) = a.zstd {
            if !(1..=22).contains(&l) {
                return Err(CliError::request(format!("--zstd: {l} is outside 1..=22")));
            }
        }
        let takes_zstd = engine.describe().zstd;
        if a.no_zstd && !takes_zstd {
            return Err(CliError::request(format!(
                "--no-zstd: {engine} loads no Zstandard-supercompressed file ({}), so there is none to turn off",
                engine.describe().containers
            )));
        }
        let zstd = match (a.zstd, a.no_zstd) {
            (Some(l), _) => Some(l),
            (None, true) => None,
            // Zstandard level 3, KTX-Software's default, where the engine reads it.
            (None, false) => takes_zstd.then_some(3),
        };
        // A cube face: the GPU containers' limit (what mirrorball_bake::MAX_SIZE is).
        let face = crate::size::pictures(mirrorball_io::Format::Ktx2, "a baked cube face", |s| {
            (s as u64, s as u64)
        });
        let size = face.check("--size", a.size)?;
        let background_size = a
            .background_size
            .map(|b| face.check("--background-size", b))
            .transpose()?;
        let opts = BakeOptions {
            size,
            encoding,
            effort,
            zstd,
            mapping,
            source: source.clone(),
            background_size,
            overwrite: a.overwrite,
        };
        let bake = Bake::new(engine, opts).map_err(|e| CliError::new(e.fault, e.message))?;
        if let Some(RoughnessMapping::Custom(r)) = &bake.opts.mapping {
            let n = bake.spec.levels.len();
            if r.len() != n {
                return Err(CliError::request(format!(
                    "--mapping lists {} but the chain of {} has {}",
                    mirrorball_core::count(r.len() as u64, "roughness value"),
                    size,
                    mirrorball_core::count(n as u64, "level")
                )));
            }
        }
        let dir = PathBuf::from(out);
        check_dir(&dir)?;
        let mut files = Files::new();
        files
            .making(mirrorball_io::Folders::MakeAll)
            .input_arg("the input", source);
        for name in bake.file_names() {
            let path = dir.join(&name);
            if path.is_dir() {
                return Err(CliError::request(format!(
                    "{}: a folder is where bake writes {name}; move it away",
                    path.display()
                )));
            }
            files.output("a baked file", path);
        }
        files.check()?;
        files.room(file_bytes(&bake))?;
        bake.check_folder(&dir)?;
        if a.samples == 0 || a.samples > 65536 {
            return Err(CliError::request(format!(
                "--samples: {} is outside 1..=65536",
                a.samples
            )));
        }
        Ok(Plan::Bake(Box::new(BakePlan {
            input,
            source: source.clone(),
            dir,
            bake,
            prefilter: PrefilterOptions {
                samples: a.samples,
                ..Default::default()
            },
            quiet: a.quiet,
        })))
    }
}

/// The output folder: a folder or nothing yet (that it can be made, in a folder that
/// exists and can be written, is checked with its files: `guard::Files`).
/// Bake makes OUT-DIR and the folders inside it its files need (three's `cube/`), not the
/// folders above it: OUT-DIR's parent must exist.
fn check_dir(dir: &Path) -> Result<(), CliError> {
    if dir.exists() && !dir.is_dir() {
        return Err(CliError::request(format!(
            "{}: OUT-DIR is a file; bake writes a folder of files (give a folder's name)",
            dir.display()
        )));
    }
    let parent = dir.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(p) = parent.filter(|p| !dir.exists() && !p.is_dir()) {
        return Err(CliError::request(format!(
            "{}: the folder {} does not exist (bake makes OUT-DIR, not the folders above it)",
            dir.display(),
            p.display()
        )));
    }
    Ok(())
}

/// About how many bytes the bake's files take: each cube of the chain and the diffuse cube
/// in the encoding (twice over, for engines that also write the faces or a skybox).
fn file_bytes(bake: &Bake) -> u64 {
    let encoding = bake.encoding();
    let cube = |f: u32| 6 * encoding.image_bytes(f, f) as u64;
    let chain: u64 = bake.spec.levels.iter().map(|&(f, _)| cube(f)).sum();
    2 * (chain + bake.spec.diffuse_face.map_or(0, cube))
}
