//! Mip pyramids for every projection: solid-angle weights preserve energy.
use crate::util::analytic_env;
use mirrorball_core::{EnvMap, ProjectionKind, WorldProjection};
use mirrorball_filter::mip::level_count;
use mirrorball_filter::{MipChain, MipFilter};

fn energy(env: &EnvMap) -> [f64; 3] {
    let p = env.projection();
    let (w, h) = (env.width(), env.height());
    let mut e = [0.0; 3];
    for (l, img) in env.layers().iter().enumerate() {
        for y in 0..h {
            for x in 0..w {
                let o = p.texel_solid_angle(l, x, y, w, h);
                let t = img.get(x, y);
                for k in 0..3 {
                    e[k] += t[k] as f64 * o;
                }
            }
        }
    }
    e
}

#[test]
fn box_pyramids_preserve_energy() {
    for (kind, size) in [
        (ProjectionKind::Cube, 32),
        (ProjectionKind::LatLong, 64),
        (ProjectionKind::Sphere, 48),
        (ProjectionKind::Paraboloid, 32),
        (ProjectionKind::EqualAreaOctahedral, 40),
    ] {
        let env = analytic_env(kind, size);
        let chain = MipChain::build(&env, MipFilter::Box);
        assert_eq!(chain.len(), level_count(env.width(), env.height()));
        let e0 = energy(&env);
        for (i, l) in chain.levels().iter().enumerate() {
            let e = energy(l);
            for k in 0..3 {
                assert!(
                    (e[k] - e0[k]).abs() < 2e-5 * e0[k],
                    "{kind} level {i}: {e:?} vs {e0:?}"
                );
            }
        }
        let last = chain.level(chain.len() - 1);
        assert_eq!((last.width(), last.height()), (1, 1));
    }
}

#[test]
fn tent_keeps_constants_and_energy_roughly() {
    let env = EnvMap::from_fn(ProjectionKind::Cube.default_projection(), 16, 3, |_| {
        [2.0, 1.0, 0.5, 1.0]
    });
    for l in MipChain::build(&env, MipFilter::Tent).levels() {
        for img in l.layers() {
            for px in img.data().chunks_exact(3) {
                assert!((px[0] - 2.0).abs() < 1e-5 && (px[2] - 0.5).abs() < 1e-5);
            }
        }
    }
    let env = analytic_env(ProjectionKind::Cube, 32);
    let e0 = energy(&env);
    let e1 = energy(MipChain::build(&env, MipFilter::Tent).level(1));
    for k in 0..3 {
        assert!((e1[k] - e0[k]).abs() < 0.01 * e0[k]);
    }
}

#[test]
fn odd_sizes() {
    assert_eq!(level_count(1, 1), 1);
    assert_eq!(level_count(5, 3), 3);
    assert_eq!(level_count(512, 256), 10);
    let env = analytic_env(ProjectionKind::LatLong, 100);
    let chain = MipChain::build(&env, MipFilter::Box);
    let sizes: Vec<(u32, u32)> = chain
        .levels()
        .iter()
        .map(|l| (l.width(), l.height()))
        .collect();
    assert_eq!(sizes[..4], [(100, 50), (50, 25), (25, 12), (12, 6)]);
    // Odd sizes split a fine texel between two coarse ones in proportion to its uv area,
    // not its exact solid angle: energy holds to 1e-3.
    let e0 = energy(&env);
    let e3 = energy(chain.level(3));
    for k in 0..3 {
        assert!((e3[k] - e0[k]).abs() < 1e-3 * e0[k], "{e3:?} {e0:?}");
    }
}
