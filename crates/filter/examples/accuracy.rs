//! Accuracy of the benchmark's prefiltering against brute force.
//!
//! `cargo run --release -p mirrorball-filter --example accuracy [ENV.exr] [FACE]`
//!
//! The bundled environment (default `sky.exr`) is resampled to a 6×FACE² cube (default 512,
//! as in `cargo bench`); every lobe of the GGX chain (roughness `level/9`), a Phong lobe and
//! Lambert are evaluated at 256 Fibonacci directions by the prefilterer and by the
//! brute-force sum over all 6·FACE² texels, and compared in two norms: relative L2 over
//! directions and channels, and the largest per-direction relative error (RGB L1).

use mirrorball_core::{resample, EnvMap, ProjectionKind, ResampleOptions};
use mirrorball_filter::sh::{project, project_reference, Window};
use mirrorball_filter::{directions, BruteForce, Lobe, PrefilterOptions, Prefilterer};
use std::time::Instant;

fn main() {
    let name = std::env::args().nth(1).unwrap_or_else(|| "sky.exr".into());
    let face: u32 = std::env::args()
        .nth(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(512);
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/env")
        .join(&name);
    let l = mirrorball_io::read(&p, &Default::default()).expect("bundled asset");
    let mut env = EnvMap::new(ProjectionKind::LatLong.default_projection(), l.layers).unwrap();
    env.sanitize();
    let cube = resample(
        &env,
        ProjectionKind::Cube.default_projection(),
        face,
        &ResampleOptions::default(),
    );
    let dirs = directions::fibonacci(256);
    let bf = BruteForce::new(&cube);
    let pf = Prefilterer::new(&cube, PrefilterOptions::default());
    println!(
        "{name} as a 6×{face}² cube; {} point-source texels carry {:.1}% of the energy",
        if pf.bright_threshold().is_some() {
            "some"
        } else {
            "no"
        },
        100.0 * pf.bright_fraction()
    );
    println!("| lobe | relative L2 | max per-direction | brute force (s) |");
    println!("| --- | --- | --- | --- |");
    let mut lobes = vec![Lobe::Lambert];
    lobes.extend((1..10).map(|m| Lobe::Ggx {
        roughness: m as f64 / 9.0,
    }));
    lobes.push(Lobe::Phong { exponent: 100.0 });
    for lobe in lobes {
        let t = Instant::now();
        let r = bf.eval_many(&lobe, &dirs);
        let tb = t.elapsed().as_secs_f64();
        let f = pf.eval(&lobe, &dirs);
        let (mut e2, mut n2, mut mx) = (0.0f64, 0.0f64, 0.0f64);
        for (a, b) in f.iter().zip(&r) {
            let (mut num, mut den) = (0.0, 0.0);
            for k in 0..3 {
                e2 += (a[k] as f64 - b[k]).powi(2);
                n2 += b[k] * b[k];
                num += (a[k] as f64 - b[k]).abs();
                den += b[k].abs();
            }
            mx = mx.max(num / den.max(1e-30));
        }
        let what = match lobe {
            Lobe::Lambert => "Lambert".to_string(),
            Lobe::Ggx { roughness } => format!("GGX r={roughness:.3}"),
            Lobe::Phong { exponent } => format!("Phong s={exponent}"),
        };
        println!(
            "| {what} | {:.2e} | {:.2e} | {tb:.1} |",
            (e2 / n2).sqrt(),
            mx
        );
    }
    // SH9: fast projection against the plain f64 loop; irradiance against brute force.
    let t = Instant::now();
    let fast = project(&cube);
    let tf = t.elapsed().as_secs_f64();
    let slow = project_reference(&cube);
    let mut worst = 0.0f64;
    for k in 0..3 {
        let scale = slow.coeffs.iter().map(|c| c[k].abs()).fold(0.0, f64::max);
        for (a, b) in fast.coeffs.iter().zip(&slow.coeffs) {
            worst = worst.max((a[k] - b[k]).abs() / scale);
        }
    }
    let r = bf.eval_many(&Lobe::Lambert, &dirs);
    let (mut e2, mut n2) = (0.0, 0.0);
    for (d, b) in dirs.iter().zip(&r) {
        let a = fast.irradiance(*d, Window::None);
        for k in 0..3 {
            e2 += (a[k] - b[k]).powi(2);
            n2 += b[k] * b[k];
        }
    }
    println!(
        "SH9: {tf:.4} s, coefficients vs f64 loop {worst:.1e} (of the largest); irradiance vs brute force relative L2 {:.2e}",
        (e2 / n2).sqrt()
    );
}
