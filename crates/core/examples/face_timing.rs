//! Per-face timing of the headline conversion, a 4096×2048 lat-long to a 6×1024² cube with
//! `Resampler::layer_into` (buffers reused, best of 15 each):
//! `cargo run --release -p mirrorball-core --example face_timing` (`RAYON_NUM_THREADS=1`
//! for one core). The ±Y faces integrate around the poles; the others do not.
use mirrorball_core::{EnvMap, ProjectionKind, ResampleOptions, Resampler};
use std::time::Instant;
fn main() {
    let src = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 4096, 3, |d| {
        let v = 1.0 + (40.0 * d.x).sin() * (30.0 * d.y).cos();
        [v as f32, (2.0 * v) as f32, (1.0 + d.y) as f32, 1.0]
    });
    let cube = ProjectionKind::Cube.default_projection();
    let opts = ResampleOptions::default();
    let r = Resampler::new(&src, cube, 1024, 1024, &opts);
    let mut imgs: Vec<_> = (0..6).map(|l| r.layer(l)).collect();
    let mut best = [f64::MAX; 6];
    for _ in 0..15 {
        for l in 0..6 {
            let t = Instant::now();
            r.layer_into(l, &mut imgs[l]);
            best[l] = best[l].min(t.elapsed().as_secs_f64() * 1e3);
        }
    }
    println!(
        "best ms a face (+X -X +Y -Y +Z -Z): {:?}, total {:.1}",
        best.map(|b| (b * 10.0).round() / 10.0),
        best.iter().sum::<f64>()
    );
}
