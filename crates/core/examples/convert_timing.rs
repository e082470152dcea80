//! Quick timing of the headline conversion: `cargo run --release -p mirrorball-core --example convert_timing`.
use mirrorball_core::{resample, EnvMap, ProjectionKind, ResampleOptions};
use std::time::Instant;

fn main() {
    let src = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 4096, 3, |d| {
        let v = 1.0 + (40.0 * d.x).sin() * (30.0 * d.y).cos();
        [v as f32, (2.0 * v) as f32, (1.0 + d.y) as f32, 1.0]
    });
    let n: u32 = std::env::var("MB_SAMPLES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(4);
    let opts = ResampleOptions {
        max_samples: n,
        ..Default::default()
    };
    let cube = ProjectionKind::Cube.default_projection();
    for _ in 0..3 {
        let t = Instant::now();
        let c = resample(&src, cube, 1024, &opts);
        let f = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let b = resample(&c, *src.projection(), 4096, &opts);
        let bk = t.elapsed().as_secs_f64();
        println!(
            "forward {f:.3}s ({:.1} Mtexel/s)  back {bk:.3}s ({:.1} Mtexel/s)  psnr {:.2}",
            6.0 * 1024.0 * 1024.0 / f / 1e6,
            4096.0 * 2048.0 / bk / 1e6,
            mirrorball_core::metrics::log_psnr(&src, &b).unwrap()
        );
    }
}
