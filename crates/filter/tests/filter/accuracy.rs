//! Agreement with brute force at 256 directions: Lambert within 1%, GGX and Phong within
//! 2%, in relative L2 (see `main.rs`), on the bundled HDRs and an analytic environment.
use crate::util::{analytic_env, bundled, bundled_cube, max_rel, rel_l2};
use mirrorball_core::{EnvMap, ProjectionKind};
use mirrorball_filter::{directions, BruteForce, Lobe, PrefilterOptions, Prefilterer};

fn lobes() -> Vec<(Lobe, f64)> {
    vec![
        (Lobe::Lambert, 0.01),
        (Lobe::Ggx { roughness: 0.1 }, 0.02),
        (Lobe::Ggx { roughness: 0.25 }, 0.02),
        (Lobe::Ggx { roughness: 0.5 }, 0.02),
        (Lobe::Ggx { roughness: 1.0 }, 0.02),
        (Lobe::Phong { exponent: 200.0 }, 0.02),
    ]
}

fn check(name: &str, env: &EnvMap, lobes: &[(Lobe, f64)]) {
    let dirs = directions::fibonacci(256);
    let bf = BruteForce::new(env);
    let pf = Prefilterer::new(env, PrefilterOptions::default());
    for (lobe, tol) in lobes {
        let r = bf.eval_many(lobe, &dirs);
        let p = pf.eval(lobe, &dirs);
        let e = rel_l2(&p, &r);
        println!(
            "{name} {lobe:?}: relative L2 {e:.2e}, max per-direction {:.2e}",
            max_rel(&p, &r)
        );
        assert!(e < *tol, "{name} {lobe:?}: relative L2 error {e} ≥ {tol}");
    }
}

#[test]
fn bundled_city() {
    check("city", &bundled_cube("city.exr", 128), &lobes());
}

#[test]
fn bundled_sky_with_sun() {
    check("sky", &bundled_cube("sky.exr", 128), &lobes());
}

#[test]
fn bundled_studio_lights() {
    check("studio", &bundled_cube("studio.exr", 128), &lobes());
}

#[test]
fn analytic_environment() {
    check(
        "analytic",
        &analytic_env(ProjectionKind::Cube, 128),
        &lobes(),
    );
}

#[test]
fn latlong_source_directly() {
    // The prefilterer converts to its working cube; the reference sums the lat-long texels.
    check(
        "venice lat-long",
        &bundled("venice.exr"),
        &[
            (Lobe::Lambert, 0.01),
            (Lobe::Ggx { roughness: 0.3 }, 0.02),
            (Lobe::Ggx { roughness: 0.8 }, 0.02),
        ],
    );
}
