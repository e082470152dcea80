//! The `f32` lookups against the core's `f64` ones, and the four-lane cube lookups against
//! the one-lane ones.

use super::*;
use crate::test_envs::{busy, env_of, max_diff};
use mirrorball_core::ProjectionKind;

#[test]
fn fast_lookups_agree_with_the_core() {
    // The f32 cube and lat-long paths give what EnvMap::sample gives, seams included.
    for kind in [
        ProjectionKind::Cube,
        ProjectionKind::LatLong,
        ProjectionKind::Octahedral,
    ] {
        let env = env_of(kind, 64, busy);
        let mut worst = 0.0f32;
        for i in 0..20000 {
            // A spiral over the sphere, plus the exact axes and cube edges.
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / 20000.0;
            let a = i as f64 * 2.399963229728653;
            let r = (1.0 - z * z).sqrt();
            let d = Vec3::new((r * a.cos()) as f32, z as f32, (r * a.sin()) as f32);
            let got = sample(&env, d);
            let want = sample_reference(&env, d);
            worst = worst.max(max_diff(got, want));
        }
        for d in [
            Vec3::X,
            Vec3::NEG_Y,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 1.0),
        ] {
            let d = d.normalize();
            let got = sample(&env, d);
            let want = sample_reference(&env, d);
            worst = worst.max(max_diff(got, want));
        }
        assert!(worst < 2e-3, "{}: {worst}", kind.name());
    }
}

#[test]
fn four_lane_cube_lookups_equal_one_lane_lookups_to_the_bit() {
    // CubeFaces::locate4 and fetch_tinted against locate and fetch: directions over the
    // sphere, along axes, edges and corners (ties between axes), at a face's last texel,
    // of any length, and no direction at all (zero, NaN, infinite).
    for channels in [3, 4] {
        let mut env = env_of(ProjectionKind::Cube, 16, busy);
        if channels == 4 {
            let layers = env.layers().iter().map(|l| l.with_channels(4)).collect();
            env = EnvMap::new(*env.projection(), layers).unwrap();
        }
        let cf = CubeFaces::new(&env).unwrap();
        let mut dirs: Vec<Vec3> = (0..4000)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f32 + 0.5) / 4000.0;
                let a = i as f32 * 2.399_963;
                let r = (1.0 - z * z).sqrt();
                Vec3::new(r * a.cos(), z, r * a.sin()) * (1.0 + (i % 7) as f32)
            })
            .collect();
        for x in [-1.0f32, -0.0, 0.0, 1.0] {
            for y in [-1.0f32, 0.0, 1.0] {
                for z in [-1.0f32, 0.0, 1.0] {
                    dirs.push(Vec3::new(x, y, z));
                }
            }
        }
        // The last texel centre of +X's last row, and just inside it.
        let e = 1.0 - 1.0 / 16.0;
        dirs.extend([Vec3::new(1.0, -e, -e), Vec3::new(1.0, -e + 1e-3, -e + 1e-3)]);
        dirs.extend([Vec3::NAN, Vec3::INFINITY, Vec3::new(f32::NAN, 1.0, 0.0)]);
        while !dirs.len().is_multiple_of(4) {
            dirs.push(Vec3::Z);
        }
        let tint = [0.5, 2.0, 0.25, 1.0];
        for d in dirs.chunks_exact(4) {
            let c = |f: fn(&Vec3) -> f32| -> [f32; 4] { std::array::from_fn(|k| f(&d[k])) };
            let four = cf.locate4(&c(|v| v.x), &c(|v| v.y), &c(|v| v.z));
            for (d, l) in d.iter().zip(&four) {
                assert_eq!(*l, cf.locate(*d), "{d}");
                let one = cf.fetch(l);
                let want = [one[0] * tint[0], one[1] * tint[1], one[2] * tint[2], 1.0];
                let got = cf.fetch_tinted(l, tint);
                assert_eq!(got.map(f32::to_bits), want.map(f32::to_bits), "{d}");
            }
        }
    }
}
