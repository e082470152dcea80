//! The conventions of ARCHITECTURE.md, pinned at hand-picked vectors against the OpenGL
//! specification's formulas and tables (typed in here, independent of the library code).
use crate::util::{angle, Rng};
use glam::{DVec2, DVec3};
use mirrorball_core::{
    AngularMap, CubeMap, DualParaboloid, Fisheye, Frame, LatLong, Lens, Octahedral, SphereMap,
    WorldProjection,
};

/// OpenGL 4.6 table 8.19, typed in: (face, sc, tc, ma) for a direction.
fn gl_table(r: DVec3) -> (usize, f64, f64, f64) {
    let (rx, ry, rz) = (r.x, r.y, r.z);
    let (ax, ay, az) = (rx.abs(), ry.abs(), rz.abs());
    if ax >= ay && ax >= az {
        if rx > 0.0 {
            (0, -rz, -ry, rx)
        } else {
            (1, rz, -ry, rx)
        }
    } else if ay >= az {
        if ry > 0.0 {
            (2, rx, rz, ry)
        } else {
            (3, rx, -rz, ry)
        }
    } else if rz > 0.0 {
        (4, rx, -ry, rz)
    } else {
        (5, -rx, -ry, rz)
    }
}

#[test]
fn cube_matches_the_opengl_major_axis_table() {
    // Hand-picked: one per face, with the expected (s, t) worked out by hand.
    let cases = [
        (DVec3::new(1.0, 0.2, -0.3), 0, 0.65, 0.4),
        (DVec3::new(-1.0, 0.2, -0.3), 1, 0.35, 0.4),
        (DVec3::new(0.2, 1.0, -0.3), 2, 0.6, 0.35),
        (DVec3::new(0.2, -1.0, -0.3), 3, 0.6, 0.65),
        (DVec3::new(0.2, -0.3, 1.0), 4, 0.6, 0.65),
        (DVec3::new(0.2, -0.3, -1.0), 5, 0.4, 0.65),
    ];
    for (r, face, s, t) in cases {
        let (f, uv) = CubeMap.dir_to_uv(r.normalize()).unwrap();
        assert_eq!(f, face, "{r}");
        assert!(
            (uv.x - s).abs() < 1e-12 && (uv.y - t).abs() < 1e-12,
            "{r}: {uv} vs ({s},{t})"
        );
    }
    // And at random directions against the typed-in table.
    let mut rng = Rng(1);
    for _ in 0..10_000 {
        let r = rng.dir();
        let (face, sc, tc, ma) = gl_table(r);
        let s = (sc / ma.abs() + 1.0) / 2.0;
        let t = (tc / ma.abs() + 1.0) / 2.0;
        let (f, uv) = CubeMap.dir_to_uv(r).unwrap();
        assert_eq!(f, face);
        assert!((uv - DVec2::new(s, t)).length() < 1e-12);
    }
}

#[test]
fn sphere_map_matches_the_opengl_formula() {
    let spec = |r: DVec3| {
        let m = 2.0 * (r.x * r.x + r.y * r.y + (r.z + 1.0).powi(2)).sqrt();
        DVec2::new(r.x / m + 0.5, r.y / m + 0.5)
    };
    // Hand-worked: r = +z (back at the viewer) is the centre; r = +x lands at
    // s = 1/(2√2) + ½.
    let (_, c) = SphereMap::default().dir_to_uv(DVec3::Z).unwrap();
    assert!((c - DVec2::splat(0.5)).length() < 1e-15);
    let (_, e) = SphereMap::default().dir_to_uv(DVec3::X).unwrap();
    assert!((e.x - (0.5 + 1.0 / (2.0 * 2f64.sqrt()))).abs() < 1e-15 && (e.y - 0.5).abs() < 1e-15);
    // Up in eye space (t > ½) is towards the top of the stored picture (v < ½).
    let (_, up) = SphereMap::default().dir_to_uv(DVec3::Y).unwrap();
    assert!(up.y < 0.5);
    let mut rng = Rng(2);
    for _ in 0..10_000 {
        let r = rng.dir();
        if r.z < -0.999 {
            continue; // the single rim direction has no unique (s, t)
        }
        let st = spec(r);
        let (_, uv) = SphereMap::default().dir_to_uv(r).unwrap();
        assert!((uv - DVec2::new(st.x, 1.0 - st.y)).length() < 1e-12);
        assert!((SphereMap::gl_st(r) - st).length() < 1e-15);
    }
    // A map taken looking along another direction is the same map in that eye frame.
    let eye = Frame::looking_along(DVec3::new(1.0, 0.0, 0.0)).unwrap();
    let m = SphereMap::new(eye);
    let r_eye = DVec3::new(0.2, 0.3, 0.5).normalize();
    let world = eye.right * r_eye.x + eye.up * r_eye.y - eye.forward * r_eye.z;
    let (_, uv) = m.dir_to_uv(world).unwrap();
    let st = spec(r_eye);
    assert!((uv - DVec2::new(st.x, 1.0 - st.y)).length() < 1e-12);
}

#[test]
fn latlong_orientation() {
    let at = |u: f64, v: f64| LatLong.uv_to_dir(0, DVec2::new(u, v)).unwrap();
    assert!(
        angle(at(0.5, 0.5), DVec3::NEG_Z) < 1e-12,
        "centre looks along -Z"
    );
    assert!(angle(at(0.75, 0.5), DVec3::X) < 1e-12, "+X right of centre");
    assert!(angle(at(0.25, 0.5), DVec3::NEG_X) < 1e-12);
    assert!(angle(at(0.0, 0.5), DVec3::Z) < 1e-12, "the seam is +Z");
    assert!(angle(at(0.3, 0.0), DVec3::Y) < 1e-12, "top row is +Y");
    assert!(angle(at(0.3, 1.0), DVec3::NEG_Y) < 1e-12);
}

#[test]
fn disk_maps_orientation() {
    // Angular and fisheye: centre straight ahead (-Z), right is +X, top is +Y.
    for p in [
        mirrorball_core::Projection::from(AngularMap::default()),
        Fisheye::default().into(),
        Fisheye::new(Frame::default(), Lens::Equisolid, 200.0)
            .unwrap()
            .into(),
    ] {
        let c = p.uv_to_dir(0, DVec2::splat(0.5)).unwrap();
        assert!(angle(c, DVec3::NEG_Z) < 1e-12);
        let (_, r) = p.dir_to_uv(DVec3::new(0.1, 0.0, -1.0).normalize()).unwrap();
        assert!(r.x > 0.5 && (r.y - 0.5).abs() < 1e-12);
        let (_, t) = p.dir_to_uv(DVec3::new(0.0, 0.1, -1.0).normalize()).unwrap();
        assert!(t.y < 0.5 && (t.x - 0.5).abs() < 1e-12);
    }
    // Angular map: radius proportional to angle; the rim is straight behind.
    let a = AngularMap::default();
    let (_, uv) = a.dir_to_uv(DVec3::X).unwrap();
    assert!((uv.x - 0.75).abs() < 1e-12, "90° is half way out");
    // Dual paraboloid: front centre -Z, back centre +Z seen by a camera turned round.
    let dp = DualParaboloid::default();
    assert!(angle(dp.uv_to_dir(0, DVec2::splat(0.5)).unwrap(), DVec3::NEG_Z) < 1e-12);
    assert!(angle(dp.uv_to_dir(1, DVec2::splat(0.5)).unwrap(), DVec3::Z) < 1e-12);
    let (l, uv) = dp
        .dir_to_uv(DVec3::new(-0.1, 0.0, 1.0).normalize())
        .unwrap();
    assert_eq!(l, 1);
    assert!(uv.x > 0.5, "on the back half, -X is to the right");
    // Heidrich–Seidel's front formula (x, y)/(1 + z) in the front frame (z towards -Z world).
    let d = DVec3::new(0.3, -0.2, -0.8).normalize();
    let (_, uv) = dp.dir_to_uv(d).unwrap();
    let (x, y, z) = (d.x, d.y, -d.z);
    let hs = DVec2::new(x / (1.0 + z), y / (1.0 + z));
    assert!((uv - DVec2::new((hs.x + 1.0) / 2.0, (1.0 - hs.y) / 2.0)).length() < 1e-12);
}

#[test]
fn octahedral_orientation() {
    let at = |u: f64, v: f64| Octahedral.uv_to_dir(0, DVec2::new(u, v)).unwrap();
    assert!(angle(at(0.5, 0.5), DVec3::Y) < 1e-12, "centre is up");
    assert!(angle(at(1.0, 0.5), DVec3::X) < 1e-12);
    assert!(
        angle(at(0.5, 0.0), DVec3::NEG_Z) < 1e-12,
        "top is straight ahead"
    );
    assert!(
        angle(at(0.0, 0.0), DVec3::NEG_Y) < 1e-12,
        "corners are down"
    );
}

/// `bilinear_corner` (every f32 bilinear filter's first step) is `floor` of the texel-centre
/// coordinate, with the fraction to the next texel, for coordinates on, between and
/// outside the texels, negative ones included.
#[test]
fn bilinear_corner_is_floor_of_the_texel_centre_coordinate() {
    let (w, h) = (7u32, 5u32);
    for i in -300..=300 {
        let u = i as f32 / 128.0; // −2.3 ..= 2.3
        let v = 1.0 - u;
        let (x0, y0, fx, fy) = mirrorball_core::bilinear_corner(u, v, w, h);
        let (x, y) = (u * w as f32 - 0.5, v * h as f32 - 0.5);
        assert_eq!((x0, y0), (x.floor() as i32, y.floor() as i32), "u = {u}");
        assert_eq!((fx, fy), (x - x.floor(), y - y.floor()), "u = {u}");
        assert!((0.0..1.0).contains(&fx) && (0.0..1.0).contains(&fy));
    }
}

/// `bilinear_taps` read with `bilinear_mix` is `bilinear_blend` at the same index, to the
/// bit, for three and four channels, at every index a footprint fits.
#[test]
fn bilinear_taps_blend_as_bilinear_blend_does() {
    for c in [3usize, 4] {
        let (w, h) = (5usize, 4usize);
        let stride = w * c;
        let a: Vec<f32> = (0..stride * h)
            .map(|i| ((i * 37) % 101) as f32 / 7.0)
            .collect();
        let b: Vec<f32> = a.iter().map(|x| 3.0 - x * x).collect();
        let taps = mirrorball_core::bilinear_taps([&a[..], &b[..]], stride, c).unwrap();
        assert_eq!(taps.last(), a.len() - (stride + c + 4));
        for (k, layer) in [&a, &b].into_iter().enumerate() {
            for i in 0..=taps.last() {
                for (fx, fy) in [(0.0, 0.0), (0.25, 0.75), (0.999, 0.5)] {
                    let want = mirrorball_core::bilinear_blend(&layer[i..], stride, c, fx, fy);
                    let got = mirrorball_core::bilinear_mix(taps.get(k, i), fx, fy);
                    assert_eq!(
                        got.to_array().map(f32::to_bits),
                        want.to_array().map(f32::to_bits)
                    );
                }
            }
        }
    }
    assert!(mirrorball_core::bilinear_taps([&[0.0f32; 12][..]], 6, 3).is_none());
}

/// The panorama projections all look along −Z at their centre, with +X to the right and +Y
/// up (as the lat-long does), and agree with the lat-long along the horizon and the
/// central meridian where each is linear there.
#[test]
fn panorama_orientation() {
    use mirrorball_core::ProjectionKind as K;
    for kind in [
        K::Cylindrical,
        K::CylindricalEqualArea,
        K::HalfEquirect,
        K::Hammer,
        K::Sinusoidal,
        K::Perspective,
        K::Pannini,
    ] {
        let p = kind.default_projection();
        let at = |u: f64, v: f64| p.uv_to_dir(0, DVec2::new(u, v)).unwrap();
        assert!(angle(at(0.5, 0.5), DVec3::NEG_Z) < 1e-12, "{kind}");
        let (right, up) = (at(0.6, 0.5), at(0.5, 0.4));
        assert!(right.x > 0.0 && right.y.abs() < 1e-12, "{kind}: {right}");
        assert!(up.y > 0.0 && up.x.abs() < 1e-12, "{kind}: {up}");
    }
    // Along the horizon of the full-turn cylinders, Hammer's and the sinusoid's, u is
    // longitude as in the lat-long only for the cylinders and the sinusoid.
    for kind in [K::Cylindrical, K::CylindricalEqualArea, K::Sinusoidal] {
        let p = kind.default_projection();
        for u in [0.1, 0.3, 0.75, 0.9] {
            let d = p.uv_to_dir(0, DVec2::new(u, 0.5)).unwrap();
            let l = mirrorball_core::LatLong
                .uv_to_dir(0, DVec2::new(u, 0.5))
                .unwrap();
            assert!(angle(d, l) < 1e-12, "{kind} at u = {u}");
        }
    }
}
