//! Lighting for Unity and Unreal: DDS cubes, each in its engine's convention.

use crate::{mip_levels, not_written, BakeOptions, ChainSpec, Engine, Lighting};
use mirrorball_core::Choice;
use mirrorball_io::Error;
use std::path::{Path, PathBuf};

/// The levels Unity or Unreal takes.
pub(crate) fn chain_spec(_engine: Engine, opts: &BakeOptions) -> ChainSpec {
    ChainSpec {
        levels: mip_levels(opts.size, |i, n| i as f64 / (n.max(2) - 1) as f64),
        diffuse_face: Some(32),
    }
}

/// Writes the engine's DDS files into `dir`.
pub(crate) fn write(
    engine: Engine,
    _l: &Lighting,
    dir: &Path,
    _opts: &BakeOptions,
) -> Result<Vec<PathBuf>, Error> {
    Err(not_written(dir, engine.name()))
}
