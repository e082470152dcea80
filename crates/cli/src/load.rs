//! Reading an environment map: file(s) → layers → projection and layout, guessed where the
//! user did not say, and the guess reported.

use crate::error::CliError;
use crate::spec::ProjSpec;
use mirrorball_core::{guess, EnvMap, Image, Layout, Projection, ProjectionKind, WorldProjection};
use mirrorball_io::{Limits, Loaded};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// The placeholder for per-layer file names.
pub const FACE: &str = "{face}";

/// Per-layer file-name parts: cube faces and paraboloid halves.
pub fn layer_names(layers: usize) -> &'static [&'static str] {
    match layers {
        6 => &["px", "nx", "py", "ny", "pz", "nz"],
        2 => &["front", "back"],
        _ => &[""],
    }
}

/// An environment map read from disk, with what was decided about it.
pub struct Source {
    /// The map.
    pub env: EnvMap,
    /// How the file was read: "OpenEXR, half, ZIP compression, RGB".
    pub description: String,
    /// How projection and layout were decided (said to the user).
    pub decided: String,
    /// NaN, infinite and negative values the reader counted in what it decoded, if it
    /// counted (see `mirrorball_io::Loaded::invalid`): `Some(0)` spares [`Source::prepare`]
    /// its scan of the whole map.
    pub invalid: Option<u64>,
}

impl Source {
    /// What was read and decided, for the user, after replacing NaN, infinite and negative
    /// texels by 0 unless `keep_invalid` (with a warning when any were).
    pub fn prepare(&mut self, input: &str, keep_invalid: bool) -> Vec<String> {
        let env = &self.env;
        let layers = if env.layers().len() > 1 {
            format!(" x{}", env.layers().len())
        } else {
            String::new()
        };
        let mut lines = vec![format!(
            "read {input} ({}): {} {}x{}{layers} — {}",
            self.description,
            env.projection().name(),
            env.width(),
            env.height(),
            self.decided
        )];
        if !keep_invalid && self.invalid != Some(0) {
            let fixed = self.env.sanitize();
            if fixed > 0 {
                lines.push(format!(
                    "warning: {input}: {fixed} NaN, infinite or negative values set to 0 (--keep-invalid keeps them)"
                ));
            }
        }
        lines
    }
}

/// Reads `input`: one file, or one per layer when the name holds `{face}`.
pub fn load(
    input: &str,
    from: Option<&ProjSpec>,
    layout: Option<Layout>,
    limits: &Limits,
) -> Result<Source, CliError> {
    if input.contains(FACE) {
        return load_layers(input, from, limits);
    }
    let path = Path::new(input);
    let loaded = mirrorball_io::read(path, limits)?;
    let Loaded {
        layers,
        declared,
        description,
        invalid,
        ..
    } = loaded;
    if layers.len() == 6 {
        // A cube container: KTX2 or DDS.
        let (spec, proj) = multi_layer(from)?;
        if proj.layer_count() != 6 {
            return Err(CliError::request(format!(
                "{input}: holds six cube faces, which cannot be read as {}",
                spec.kind
            )));
        }
        let env =
            EnvMap::new(proj, layers).map_err(|e| CliError::input(format!("{input}: {e}")))?;
        return Ok(Source {
            env,
            description,
            decided: format!("{} (six faces in the container)", spec.kind),
            invalid,
        });
    }
    let image = layers
        .into_iter()
        .next()
        .ok_or_else(|| CliError::input(format!("{input}: no image")))?;
    let (w, h) = (image.width(), image.height());
    let (spec, layout, decided) = match (from, layout) {
        (Some(spec), Some(l)) => (spec.clone(), l, "as asked".to_string()),
        (Some(spec), None) => {
            let n = spec.kind.default_projection().layer_count();
            let (l, _, _) =
                Layout::from_extent(w, h, n).ok_or_else(|| no_layout(input, w, h, spec.kind))?;
            (spec.clone(), l, format!("as asked; {w}x{h} fits {l}"))
        }
        (None, _) => {
            let g = guess(w, h, declared).ok_or_else(|| {
                CliError::input(format!(
                    "{input}: cannot tell the projection of a {w}x{h} picture (2:1 is lat-long, 4:3, 3:4, 6:1 and 1:6 are cube layouts, 1:1 a sphere map); say it with --from"
                ))
            })?;
            let l = layout.unwrap_or(g.layout);
            (
                ProjSpec::of(g.kind),
                l,
                format!(
                    "guessed {} {}: {} (override with --from/--layout)",
                    g.kind, g.layout, g.reason
                ),
            )
        }
    };
    let proj = spec
        .build(Some((w, h)))
        .map_err(|e| CliError::request(format!("--from: {e}")))?;
    if layout == Layout::Separate && proj.layer_count() > 1 {
        return Err(CliError::request(format!(
            "{input}: a {} map has {} layers; give one file per layer with {FACE} in the name, or a packed layout",
            spec.kind,
            proj.layer_count()
        )));
    }
    check_shape(input, &proj, w, h, layout)?;
    let env = layout
        .unpack_owned(image, proj)
        .map_err(|e| CliError::input(format!("{input}: {e}")))?;
    Ok(Source {
        env,
        description,
        decided,
        invalid,
    })
}

fn no_layout(input: &str, w: u32, h: u32, kind: ProjectionKind) -> CliError {
    CliError::input(format!(
        "{input}: a {w}x{h} picture fits no layout of a {kind} map (six square faces: 4:3 or 3:4 cross, 6:1 or 1:6 strip; two halves: 2:1 or 1:2)"
    ))
}

/// Single-layer projections have a natural shape; refuse pictures far from it.
fn check_shape(
    input: &str,
    proj: &mirrorball_core::Projection,
    w: u32,
    h: u32,
    layout: Layout,
) -> Result<(), CliError> {
    if layout != Layout::Separate || proj.layer_count() != 1 {
        return Ok(());
    }
    let (ew, eh) = proj.layer_extent(w);
    let ratio_err = ((h as f64) - (eh as f64)).abs() / eh as f64;
    if proj.kind() != ProjectionKind::Mercator && ratio_err > 0.01 {
        return Err(CliError::input(format!(
            "{input}: a {} map is {}:{} ({ew}x{eh} for this width) but the picture is {w}x{h}; use --from to read it as another projection",
            proj.name(),
            ew / gcd(ew, eh),
            eh / gcd(ew, eh)
        )));
    }
    Ok(())
}

fn gcd(a: u32, b: u32) -> u32 {
    if b == 0 {
        a.max(1)
    } else {
        gcd(b, a % b)
    }
}

/// The projection of a multi-layer input: as asked, or a cube.
fn multi_layer(from: Option<&ProjSpec>) -> Result<(ProjSpec, Projection), CliError> {
    let spec = from
        .cloned()
        .unwrap_or_else(|| ProjSpec::of(ProjectionKind::Cube));
    let proj = spec
        .build(None)
        .map_err(|e| CliError::request(format!("--from: {e}")))?;
    Ok((spec, proj))
}

/// Reads one file per layer: `{face}` becomes px nx py ny pz nz (cube) or front back.
fn load_layers(input: &str, from: Option<&ProjSpec>, limits: &Limits) -> Result<Source, CliError> {
    let (spec, proj) = multi_layer(from)?;
    let names = layer_names(proj.layer_count());
    if names.len() < 2 {
        return Err(CliError::request(format!("{input}: {FACE} files need a projection with several layers (cube, continuous-cube, paraboloid), not {}", spec.kind)));
    }
    let paths: Vec<PathBuf> = names
        .iter()
        .map(|n| PathBuf::from(input.replace(FACE, n)))
        .collect();
    let loaded: Vec<Loaded> = paths
        .par_iter()
        .map(|p| mirrorball_io::read(p, limits))
        .collect::<Result<_, _>>()?;
    // Counted in every file, or not known.
    let invalid = loaded.iter().map(|l| l.invalid).sum::<Option<u64>>();
    let mut layers: Vec<Image> = Vec::new();
    for (l, p) in loaded.into_iter().zip(&paths) {
        let img = l
            .layers
            .into_iter()
            .next()
            .ok_or_else(|| CliError::input(format!("{}: no image", p.display())))?;
        if img.width() != img.height() {
            return Err(CliError::input(format!(
                "{}: a face must be square, this one is {}x{}",
                p.display(),
                img.width(),
                img.height()
            )));
        }
        layers.push(img);
    }
    let c = layers.iter().map(|l| l.channels()).max().unwrap_or(3);
    let layers: Vec<Image> = layers.iter().map(|l| l.with_channels(c)).collect();
    let env = EnvMap::new(proj, layers).map_err(|e| CliError::input(format!("{input}: {e}")))?;
    Ok(Source {
        env,
        description: format!("{} files", names.len()),
        decided: format!("{} from one file per layer", spec.kind),
        invalid,
    })
}
