//! Lighting for gltf: the files, the convention and the roughness-to-mip rule.

use crate::{mip_levels, not_written, BakeOptions, ChainSpec, Description, Lighting};
use mirrorball_core::AxisMap;
use mirrorball_io::Error;
use std::path::{Path, PathBuf};

/// The levels gltf takes.
pub(crate) fn chain_spec(opts: &BakeOptions) -> ChainSpec {
    ChainSpec {
        levels: mip_levels(opts.size, |i, n| i as f64 / (n.max(2) - 1) as f64),
        diffuse_face: Some(32),
    }
}

/// Writes gltf's files into `dir`.
pub(crate) fn write(_l: &Lighting, dir: &Path, _opts: &BakeOptions) -> Result<Vec<PathBuf>, Error> {
    Err(not_written(dir, "gltf"))
}

/// What gltf takes: not written yet ([`crate::unwritten`]).
pub(crate) fn describe() -> Description {
    crate::unwritten()
}

/// How gltf looks its cubes up, as [`crate::Engine::orientation`] says.
pub(crate) fn orientation() -> AxisMap {
    // Left as the identity for gltf's helper to decide.
    AxisMap::IDENTITY
}
