//! A single bright texel gives the lobe's shape.
use crate::util::rel_l2;
use mirrorball_core::glam::DVec3;
use mirrorball_core::{EnvMap, Image, ProjectionKind, WorldProjection};
use mirrorball_filter::{directions, BruteForce, Lobe, PrefilterOptions, Prefilterer};

/// A black 32² cube with one texel of `value` on +X.
fn one_texel(value: f32) -> (EnvMap, DVec3) {
    let size = 32;
    let mut faces: Vec<Image> = (0..6).map(|_| Image::new(size, size, 3)).collect();
    let (x, y) = (11, 14);
    faces[0].set(x, y, &[value, 0.5 * value, 0.25 * value]);
    let p = ProjectionKind::Cube.default_projection();
    let d = p
        .uv_to_dir(
            0,
            mirrorball_core::glam::DVec2::new((x as f64 + 0.5) / 32.0, (y as f64 + 0.5) / 32.0),
        )
        .unwrap();
    (EnvMap::new(p, faces).unwrap(), d)
}

#[test]
fn one_texel_gives_the_lobe() {
    let (env, d) = one_texel(1000.0);
    let bf = BruteForce::new(&env);
    let pf = Prefilterer::new(&env, PrefilterOptions::default());
    // Directions: the lattice plus a fan through the lobe's core.
    let mut dirs = directions::fibonacci(256);
    let t = d.cross(DVec3::Y).normalize();
    for i in 0..64 {
        let a = i as f64 * 0.02;
        dirs.push((d * a.cos() + t * a.sin()).normalize());
    }
    for lobe in [
        Lobe::Lambert,
        Lobe::Ggx { roughness: 0.35 },
        Lobe::Ggx { roughness: 0.6 },
        Lobe::Ggx { roughness: 1.0 },
        Lobe::Phong { exponent: 30.0 },
        Lobe::Phong { exponent: 4.0 },
    ] {
        let r = bf.eval_many(&lobe, &dirs);
        let p = pf.eval(&lobe, &dirs);
        let e = rel_l2(&p, &r);
        println!("{lobe:?}: relative L2 {e:.2e}");
        assert!(e < 0.02, "{lobe:?}: relative L2 error {e}");
        // The shape itself: along the fan, value ∝ K(n·d).
        let k0 = lobe.kernel(1.0);
        let peak = p[256][0] as f64;
        for i in 0..64 {
            let n = dirs[256 + i];
            let want = lobe.kernel(n.dot(d)) / k0;
            let got = p[256 + i][0] as f64 / peak;
            assert!(
                (got - want).abs() < 0.02 + 0.02 * want,
                "{lobe:?} at {:.2} rad: {got} vs kernel {want}",
                i as f64 * 0.02
            );
        }
    }
}
