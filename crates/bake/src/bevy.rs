//! Lighting for bevy: the files, the convention and the roughness-to-mip rule.

use crate::{mip_levels, not_written, BakeOptions, ChainSpec, Description, Lighting};
use mirrorball_core::{Axis, AxisMap};
use mirrorball_io::Error;
use std::path::{Path, PathBuf};

/// The levels bevy takes.
pub(crate) fn chain_spec(opts: &BakeOptions) -> ChainSpec {
    ChainSpec {
        levels: mip_levels(opts.size, |i, n| i as f64 / (n.max(2) - 1) as f64),
        diffuse_face: Some(32),
    }
}

/// Writes bevy's files into `dir`.
pub(crate) fn write(_l: &Lighting, dir: &Path, _opts: &BakeOptions) -> Result<Vec<PathBuf>, Error> {
    Err(not_written(dir, "bevy"))
}

/// What bevy takes: not written yet ([`crate::unwritten`]).
pub(crate) fn describe() -> Description {
    crate::unwritten()
}

/// How bevy looks its cubes up, as [`crate::Engine::orientation`] says.
pub(crate) fn orientation() -> AxisMap {
    // Placeholder for bevy's helper to confirm: bevy_pbr's environment_map.wgsl samples
    // radiance at vec3(R.xy, -R.z) and irradiance at vec3(N.xy, -N.z), so the cube must
    // show at e what mirrorball's world shows at (x, y, -z).
    AxisMap::mirror(Axis::Z)
}
