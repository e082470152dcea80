//! Lighting for three: the files, the convention and the roughness-to-mip rule.

use crate::{mip_levels, not_written, BakeOptions, ChainSpec, Lighting};
use mirrorball_io::Error;
use std::path::{Path, PathBuf};

/// The levels three takes.
pub(crate) fn chain_spec(opts: &BakeOptions) -> ChainSpec {
    ChainSpec {
        levels: mip_levels(opts.size, |i, n| i as f64 / (n.max(2) - 1) as f64),
        diffuse_face: Some(32),
    }
}

/// Writes three's files into `dir`.
pub(crate) fn write(_l: &Lighting, dir: &Path, _opts: &BakeOptions) -> Result<Vec<PathBuf>, Error> {
    Err(not_written(dir, "three"))
}
