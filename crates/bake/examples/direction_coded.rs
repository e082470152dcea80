//! `cargo run -p mirrorball-bake --example direction_coded -- OUT.exr [WIDTH]`: a lat-long
//! map whose every texel stores its own direction as colour, `½ + ½·d` (so each axis flip,
//! mirroring or rotation shows), for tests that check an engine sees the world the right
//! way round.

use mirrorball_core::{EnvMap, ProjectionKind};
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(out) = args.first() else {
        eprintln!("usage: direction_coded OUT.exr [WIDTH]");
        std::process::exit(2);
    };
    let width: u32 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1024);
    let env = EnvMap::from_fn(
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
    );
    let opts = mirrorball_io::WriteOptions {
        precision: Some(mirrorball_io::Precision::Float),
        ..Default::default()
    };
    if let Err(e) = mirrorball_io::write_image(Path::new(out), &env.layers()[0], &opts) {
        eprintln!("{e}");
        std::process::exit(1);
    }
}
