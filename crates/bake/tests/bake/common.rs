//! A direction-coded environment and a bake of it.

use mirrorball_bake::{Bake, BakeOptions, Engine, Lighting};
use mirrorball_core::glam::{DVec2, DVec3};
use mirrorball_core::{ProjectionKind, WorldProjection};
use mirrorball_io::Encoding;
use std::path::{Path, PathBuf};

pub use mirrorball_bake::direction_coded;

/// The file names of `files`.
pub fn names(files: &[PathBuf]) -> Vec<String> {
    files
        .iter()
        .map(|f| f.file_name().unwrap().to_string_lossy().into_owned())
        .collect()
}

/// The colour a direction-coded map shows in direction `d`.
pub fn coded(d: DVec3) -> [f64; 3] {
    [0.5 + 0.5 * d.x, 0.5 + 0.5 * d.y, 0.5 + 0.5 * d.z]
}

/// The centre direction of texel `(x, y)` of cube face `face`, `n` texels a side.
pub fn texel_dir(face: usize, x: u32, y: u32, n: u32) -> DVec3 {
    let uv = DVec2::new((x as f64 + 0.5) / n as f64, (y as f64 + 0.5) / n as f64);
    ProjectionKind::Cube
        .default_projection()
        .uv_to_dir(face, uv)
        .unwrap()
}

/// Bakes the direction-coded map (256 wide) for `engine` into `dir` as `mirrorball bake`
/// does: the bake, the float lighting (in the engine's axes) and the files written.
pub fn bake(
    engine: Engine,
    size: u32,
    encoding: Option<Encoding>,
    dir: &Path,
) -> (Bake, Lighting, Vec<PathBuf>) {
    let opts = BakeOptions {
        size,
        encoding,
        source: "coded.exr".into(),
        ..Default::default()
    };
    let mut bake = Bake::new(engine, opts).unwrap();
    let env = direction_coded(256);
    bake.check(&env).unwrap();
    bake.fit(&env);
    let lighting = bake.lighting(&env, Default::default());
    let files = bake.write(&lighting, dir).unwrap();
    (bake, lighting, files)
}
