//! Lighting for three: the files, the convention and the roughness-to-mip rule.

use crate::{mip_levels, not_written, BakeOptions, ChainSpec, Description, Lighting};
use mirrorball_core::{Axis, AxisMap};
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

/// What three takes: not written yet ([`crate::unwritten`]).
pub(crate) fn describe() -> Description {
    crate::unwritten()
}

/// How three looks its cubes up, as [`crate::Engine::orientation`] says.
pub(crate) fn orientation() -> AxisMap {
    // Placeholder for three's helper to confirm: three.js samples a CubeTexture that is
    // not a render target at (-x, y, z) (flipEnvMap = -1: WebGLMaterials.js,
    // WebGLBackground.js), so the cube must show at e what mirrorball's world shows at
    // (-x, y, z).
    AxisMap::mirror(Axis::X)
}
