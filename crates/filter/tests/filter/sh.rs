//! Spherical harmonics: the fast projection agrees with brute force to 1e-4 relative; the
//! irradiance of a band-limited environment is exact; windows remove ringing.
use crate::util::{analytic_env, bundled, bundled_cube, rel_l2};
use mirrorball_core::glam::DVec3;
use mirrorball_core::{EnvMap, ProjectionKind};
use mirrorball_filter::sh::{project, project_reference, Sh9, Window};
use mirrorball_filter::{directions, BruteForce, Lobe};

/// Largest coefficient difference over the largest coefficient, worst channel.
fn rel_diff(a: &Sh9, b: &Sh9) -> f64 {
    (0..3)
        .map(|k| {
            let scale = b.coeffs.iter().map(|c| c[k].abs()).fold(0.0, f64::max);
            let err = a
                .coeffs
                .iter()
                .zip(&b.coeffs)
                .map(|(x, y)| (x[k] - y[k]).abs())
                .fold(0.0, f64::max);
            err / scale
        })
        .fold(0.0, f64::max)
}

#[test]
fn fast_projection_matches_brute_force() {
    let cases: Vec<(&str, EnvMap)> = vec![
        ("city cube 64", bundled_cube("city.exr", 64)),
        ("sky cube 64", bundled_cube("sky.exr", 64)),
        ("studio lat-long 512", bundled("studio.exr")),
        (
            "analytic sphere map",
            analytic_env(ProjectionKind::Sphere, 96),
        ),
        (
            "analytic octahedral",
            analytic_env(ProjectionKind::Octahedral, 64),
        ),
        (
            "analytic paraboloid",
            analytic_env(ProjectionKind::Paraboloid, 64),
        ),
    ];
    for (name, env) in cases {
        let fast = project(&env);
        let slow = project_reference(&env);
        let e = rel_diff(&fast, &slow);
        println!("{name}: SH9 relative difference {e:.2e}");
        assert!(e < 1e-4, "{name}: {e}");
    }
}

#[test]
fn band_limited_irradiance_is_exact() {
    // L(d) = a + b·d + a quadratic: within bands 0–2, so SH9 irradiance is exact.
    let f = |d: DVec3| {
        let v = 2.0 + 0.7 * d.y - 0.4 * d.x + 0.3 * d.x * d.z + 0.2 * (d.y * d.y - d.z * d.z);
        [
            v as f32,
            (1.5 + 0.5 * d.z) as f32,
            (1.0 + 0.25 * d.x * d.y) as f32,
            1.0,
        ]
    };
    let env = EnvMap::from_fn(ProjectionKind::Cube.default_projection(), 48, 3, f);
    let sh = project(&env);
    let dirs = directions::fibonacci(256);
    let reference = BruteForce::new(&env).eval_many(&Lobe::Lambert, &dirs);
    let got: Vec<[f32; 3]> = dirs
        .iter()
        .map(|&d| sh.irradiance(d, Window::None).map(|v| v as f32))
        .collect();
    let e = rel_l2(&got, &reference);
    println!("band-limited SH9 irradiance vs brute force: {e:.2e}");
    assert!(e < 1e-3, "{e}");
}

#[test]
fn irradiance_of_real_environments() {
    // Informational bounds: nine coefficients capture diffuse lighting to a few percent
    // (Ramamoorthi & Hanrahan), less well around a sun.
    for (name, tol) in [("city.exr", 0.03), ("venice.exr", 0.03), ("sky.exr", 0.15)] {
        let env = bundled_cube(name, 64);
        let sh = project(&env);
        let dirs = directions::fibonacci(256);
        let reference = BruteForce::new(&env).eval_many(&Lobe::Lambert, &dirs);
        let got: Vec<[f32; 3]> = dirs
            .iter()
            .map(|&d| sh.irradiance(d, Window::None).map(|v| v as f32))
            .collect();
        let e = rel_l2(&got, &reference);
        println!("{name}: SH9 irradiance relative L2 vs brute force {e:.3}");
        assert!(e < tol, "{name}: {e}");
    }
}

#[test]
fn windows_remove_ringing() {
    // A single bright sun: unwindowed SH9 irradiance goes negative opposite it.
    let sun = DVec3::new(0.2, 0.9, 0.1).normalize();
    let env = EnvMap::from_fn(ProjectionKind::Cube.default_projection(), 32, 3, |d| {
        let v = 0.05 + 5000.0 * (-(1.0 - d.dot(sun)) * 4000.0).exp();
        [v as f32, v as f32, v as f32, 1.0]
    });
    let sh = project(&env);
    let dirs = directions::fibonacci(2000);
    let min = |w: Window| {
        dirs.iter()
            .map(|&d| sh.irradiance(d, w)[0])
            .fold(f64::INFINITY, f64::min)
    };
    assert!(min(Window::None) < 0.0, "no ringing to remove?");
    let width = sh.nonnegative_hann_width();
    println!("non-negative Hann width {width:.3}");
    assert!(width.is_finite() && width >= 1.0);
    assert!(min(Window::NonNegative) >= -1e-6 * sh.coeffs[0][0].abs());
    // Hann and Lanczos of width 3 attenuate bands 1 and 2 as documented.
    let h = sh.windowed(Window::Hann { width: 3.0 });
    assert!((h.coeffs[1][0] - 0.75 * sh.coeffs[1][0]).abs() < 1e-12);
    assert!((h.coeffs[4][0] - 0.25 * sh.coeffs[4][0]).abs() < 1e-12);
    let l = sh.windowed(Window::Lanczos { width: 3.0 });
    assert!(l.coeffs[4][0].abs() < sh.coeffs[4][0].abs());
    // A window never changes the mean (band 0).
    assert_eq!(h.coeffs[0], sh.coeffs[0]);
}
