//! Quick timing of the headline conversion: `cargo run --release -p mirrorball-core --example convert_timing`.
//!
//! Times `resample` (planning on the fly) and a [`Remap`] planned once then applied, for a
//! 4096×2048 lat-long to a 6×1024² cube and back. `MB_SAMPLES=1` turns integration off.
use mirrorball_core::{resample, EnvMap, ProjectionKind, Remap, ResampleOptions};
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
    let ll = *src.projection();
    if std::env::var_os("MB_APPLY_ONLY").is_some() {
        // For `perf record`: the planned forward conversion into new outputs, 30 times.
        let fwd = Remap::new(ll, (4096, 2048), 1, cube, 1024, &opts);
        let t = Instant::now();
        for _ in 0..30 {
            std::hint::black_box(fwd.apply(&src).unwrap());
        }
        println!("apply: {:.4}s each", t.elapsed().as_secs_f64() / 30.0);
        return;
    }
    for _ in 0..3 {
        let t = Instant::now();
        let c = resample(&src, cube, 1024, &opts);
        let f = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let b = resample(&c, ll, 4096, &opts);
        let bk = t.elapsed().as_secs_f64();
        println!(
            "resample: forward {f:.3}s ({:.1} Mtexel/s)  back {bk:.3}s ({:.1} Mtexel/s)  psnr {:.2}",
            6.0 * 1024.0 * 1024.0 / f / 1e6,
            4096.0 * 2048.0 / bk / 1e6,
            mirrorball_core::metrics::log_psnr(&src, &b).unwrap()
        );
    }
    let t = Instant::now();
    let fwd = Remap::new(ll, (4096, 2048), 1, cube, 1024, &opts);
    let back = Remap::new(cube, (1024, 1024), 6, ll, 4096, &opts);
    println!(
        "plans: {:.3}s, {:.0} + {:.0} MB, {} + {} taps",
        t.elapsed().as_secs_f64(),
        fwd.memory_bytes() as f64 / 1e6,
        back.memory_bytes() as f64 / 1e6,
        fwd.tap_count(),
        back.tap_count()
    );
    let mut c = fwd.apply(&src).unwrap();
    let mut b = back.apply(&c).unwrap();
    for _ in 0..5 {
        let t = Instant::now();
        fwd.apply_into(&src, &mut c).unwrap();
        let f = t.elapsed().as_secs_f64();
        let t = Instant::now();
        back.apply_into(&c, &mut b).unwrap();
        let bk = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let c2 = fwd.apply(&src).unwrap();
        let fa = t.elapsed().as_secs_f64();
        std::hint::black_box(c2);
        println!(
            "remap: forward {f:.4}s ({:.1} Mtexel/s; {fa:.4}s allocating)  back {bk:.4}s ({:.1} Mtexel/s)  psnr {:.2}",
            6.0 * 1024.0 * 1024.0 / f / 1e6,
            4096.0 * 2048.0 / bk / 1e6,
            mirrorball_core::metrics::log_psnr(&src, &b).unwrap()
        );
    }
}
