//! Shared helpers: bundled environments, analytic environments, error norms.
use mirrorball_core::glam::DVec3;
use mirrorball_core::{resample, EnvMap, ProjectionKind, ResampleOptions};
use std::path::Path;
use std::sync::OnceLock;

/// A bundled lat-long HDR (512×256), NaN/negative values cleaned.
pub fn bundled(name: &str) -> EnvMap {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/env")
        .join(name);
    let l = mirrorball_io::read(&p, &Default::default()).expect("bundled asset reads");
    let mut env = EnvMap::new(ProjectionKind::LatLong.default_projection(), l.layers).unwrap();
    env.sanitize();
    env
}

/// A bundled HDR as a cube of `size²` faces (cached per name and size).
pub fn bundled_cube(name: &str, size: u32) -> EnvMap {
    static CACHE: OnceLock<std::sync::Mutex<std::collections::HashMap<(String, u32), EnvMap>>> =
        OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    if let Some(e) = cache.lock().unwrap().get(&(name.to_string(), size)) {
        return e.clone();
    }
    let e = resample(
        &bundled(name),
        ProjectionKind::Cube.default_projection(),
        size,
        &ResampleOptions::default(),
    );
    cache
        .lock()
        .unwrap()
        .insert((name.to_string(), size), e.clone());
    e
}

/// A smooth analytic environment with features at several scales and a bright spot.
pub fn analytic(d: DVec3) -> [f32; 4] {
    let sun = DVec3::new(0.3, 0.8, -0.52).normalize();
    let spot = 40.0 * (-(1.0 - d.dot(sun)) * 60.0).exp();
    let r = 1.0 + 0.5 * d.y + 0.3 * (3.0 * d.x).sin() * (2.0 * d.z).cos() + spot;
    let g = 0.8 + 0.4 * d.x * d.z + 0.6 * spot;
    let b = 1.2 - 0.4 * d.y + 0.2 * (5.0 * d.y).cos() + 0.3 * spot;
    [r as f32, g as f32, b as f32, 1.0]
}

/// `analytic` in projection `kind` at edge `size`.
pub fn analytic_env(kind: ProjectionKind, size: u32) -> EnvMap {
    EnvMap::from_fn(kind.default_projection(), size, 3, analytic)
}

/// Relative L2 error `‖p − r‖₂/‖r‖₂` over directions and channels.
pub fn rel_l2(p: &[[f32; 3]], r: &[[f64; 3]]) -> f64 {
    let (mut e, mut n) = (0.0, 0.0);
    for (a, b) in p.iter().zip(r) {
        for k in 0..3 {
            e += (a[k] as f64 - b[k]).powi(2);
            n += b[k] * b[k];
        }
    }
    (e / n).sqrt()
}

/// Largest per-direction relative error `Σ|p − r| / Σ|r|`.
pub fn max_rel(p: &[[f32; 3]], r: &[[f64; 3]]) -> f64 {
    p.iter()
        .zip(r)
        .map(|(a, b)| {
            let num: f64 = (0..3).map(|k| (a[k] as f64 - b[k]).abs()).sum();
            let den: f64 = (0..3).map(|k| b[k].abs()).sum();
            num / den.max(1e-30)
        })
        .fold(0.0, f64::max)
}
