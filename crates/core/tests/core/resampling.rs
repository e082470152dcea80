//! Conversion quality: accuracy on smooth environments, no aliasing when shrinking, no seams
//! when growing, rotations that turn the right way.
use glam::{DVec2, DVec3};
use mirrorball_core::{
    resample, EnvMap, Projection, ProjectionKind, ResampleOptions, Rotation, WorldProjection,
};

fn smooth(d: DVec3) -> [f32; 4] {
    let v = 1.0 + 0.5 * d.x + 0.25 * d.y * d.z + 0.3 * (3.0 * d.y).sin();
    [v as f32, (2.0 - d.y) as f32, (1.5 + d.z * d.x) as f32, 1.0]
}

/// Solid-angle-weighted RMS error of `e` against the analytic `f`, relative to the mean.
fn rel_rms(e: &EnvMap, f: impl Fn(DVec3) -> [f32; 4]) -> f64 {
    rel_rms_where(e, f, |_| true)
}

/// [`rel_rms`] over the directions where `keep` holds.
fn rel_rms_where(e: &EnvMap, f: impl Fn(DVec3) -> [f32; 4], keep: impl Fn(DVec3) -> bool) -> f64 {
    let p = *e.projection();
    let (w, h) = (e.width(), e.height());
    let (mut err, mut norm, mut wsum) = (0.0, 0.0, 0.0);
    for (layer, img) in e.layers().iter().enumerate() {
        for y in 0..h {
            for x in 0..w {
                let sa = p.texel_solid_angle(layer, x, y, w, h);
                let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                if sa <= 0.0 {
                    continue;
                }
                let Some(d) = p.uv_to_dir(layer, uv) else {
                    continue;
                };
                if !keep(d) {
                    continue;
                }
                let want = f(d);
                for c in 0..3 {
                    let diff = img.get(x, y)[c] as f64 - want[c] as f64;
                    err += sa * diff * diff;
                    norm += sa * (want[c] as f64).powi(2);
                }
                wsum += sa;
            }
        }
    }
    let _ = wsum;
    (err / norm).sqrt()
}

#[test]
fn every_projection_converts_a_smooth_environment_accurately() {
    let src = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 512, 3, smooth);
    // Outside a disk or an outline, the rim's value: reading back near the rim then
    // measures the projection, not a camera frame's black surround.
    let rim = ResampleOptions {
        outside: Some(mirrorball_core::Outside::Rim),
        ..ResampleOptions::default()
    };
    for kind in ProjectionKind::ALL {
        let dst = kind.default_projection();
        let out = resample(&src, dst, 128, &rim);
        let e = rel_rms(&out, smooth);
        eprintln!("{kind}: {e:.2e}");
        assert!(e < 4e-3, "{kind}: relative RMS {e}");
        // And back to lat-long.
        let back = resample(
            &out,
            src.projection().to_owned(),
            256,
            &ResampleOptions::default(),
        );
        // Only where the intermediate projection covers (Mercator stops short of the poles).
        let e2 = rel_rms_where(&back, smooth, |d| dst.dir_to_uv(d).is_some());
        eprintln!("{kind} round trip: {e2:.2e}");
        assert!(e2 < 5e-3, "{kind} round trip: relative RMS {e2}");
    }
}

/// A zone plate: rings whose frequency grows away from +Y, far above what a 16² cube face
/// can hold. Integrated, each output texel is close to the mean (0.5); point-sampled, it
/// aliases into large errors.
#[test]
fn shrinking_a_zone_plate_does_not_alias() {
    let zone = |d: DVec3| {
        let t = d.y.clamp(-1.0, 1.0).acos();
        let v = 0.5 + 0.5 * (200.0 * t * t).cos();
        [v as f32, v as f32, v as f32, 1.0]
    };
    let src = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 4096, 3, zone);
    let cube = ProjectionKind::Cube.default_projection();
    let dev = |e: &EnvMap| {
        let mut m: f64 = 0.0;
        for (layer, img) in e.layers().iter().enumerate() {
            for y in 0..e.height() {
                for x in 0..e.width() {
                    // Skip the +Y face's centre where the rings are still resolvable.
                    let uv = DVec2::new((x as f64 + 0.5) / 16.0, (y as f64 + 0.5) / 16.0);
                    let d = cube.uv_to_dir(layer, uv).unwrap();
                    if d.y.acos() < 0.6 {
                        continue;
                    }
                    m = m.max((img.get(x, y)[0] as f64 - 0.5).abs());
                }
            }
        }
        m
    };
    let good = resample(&src, cube, 16, &ResampleOptions::default());
    let point = resample(
        &src,
        cube,
        16,
        &ResampleOptions {
            max_samples: 1,
            ..Default::default()
        },
    );
    let (g, p) = (dev(&good), dev(&point));
    assert!(g < 0.1, "antialiased deviation {g}");
    assert!(
        p > 0.3,
        "point sampling should alias (deviation {p}): the test must be able to fail"
    );
}

/// One bilinear lookup a texel (`max_samples = 1`, and growing a cube into a lat-long,
/// where nothing is integrated) is the source's own `f64` bilinear filter (`EnvMap::sample`) at each output
/// texel's centre direction: inside layers (the resampler's gather pass) and across the
/// seams, the longitude wrap and the poles alike.
#[test]
fn one_lookup_a_texel_is_the_sources_bilinear_filter() {
    let ll = ProjectionKind::LatLong.default_projection();
    let cube = ProjectionKind::Cube.default_projection();
    let noisy = |d: DVec3| {
        let v = 1.0 + 0.5 * (37.0 * d.x).sin() * (23.0 * d.y).cos() + 0.2 * (51.0 * d.z).sin();
        [
            v as f32,
            (2.0 + d.y) as f32,
            (1.5 - 0.7 * d.x) as f32,
            (0.5 + 0.4 * d.z) as f32,
        ]
    };
    let point = ResampleOptions {
        max_samples: 1,
        ..Default::default()
    };
    let cases = [
        (EnvMap::from_fn(ll, 256, 3, noisy), cube, 64, point.clone()),
        (EnvMap::from_fn(ll, 128, 4, noisy), cube, 96, point.clone()),
        (
            EnvMap::from_fn(cube, 32, 3, noisy),
            ll,
            200,
            ResampleOptions::default(),
        ),
    ];
    for (src, dst, size, opts) in &cases {
        let out = resample(src, *dst, *size, opts);
        let (w, h) = (out.width(), out.height());
        let mut worst: f64 = 0.0;
        for (layer, img) in out.layers().iter().enumerate() {
            for y in 0..h {
                for x in 0..w {
                    let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                    let d = dst.uv_to_dir(layer, uv).unwrap();
                    let want = src.sample(d);
                    for (c, &got) in img.get(x, y).iter().enumerate() {
                        let e = (got as f64 - want[c] as f64).abs() / want[c].abs().max(0.1) as f64;
                        worst = worst.max(e);
                    }
                }
            }
        }
        // f32 directions and lookups place a sample within ~1e-6 of a texel.
        assert!(
            worst < 2e-4,
            "{:?} → {dst:?}: worst relative difference {worst}",
            src.projection()
        );
    }
}

/// Growing a small map: the values across every cube edge change no more than inside faces.
#[test]
fn growing_leaves_no_seams() {
    let src = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 64, 3, smooth);
    for kind in [ProjectionKind::Cube, ProjectionKind::ContinuousCube] {
        let out = resample(
            &src,
            kind.default_projection(),
            128,
            &ResampleOptions::default(),
        );
        let p = *out.projection();
        let n = out.width();
        // Compare each border texel with its neighbour across the edge (via wrap_texel) and
        // with its neighbour inside the face.
        let (mut across, mut inside) = (0.0f32, 0.0f32);
        for layer in 0..6 {
            for k in 0..n {
                for (x, y, ox, oy, ix, iy) in [
                    (0, k, -1i64, k as i64, 1, k),
                    (n - 1, k, n as i64, k as i64, n - 2, k),
                    (k, 0, k as i64, -1, k, 1),
                    (k, n - 1, k as i64, n as i64, k, n - 2),
                ] {
                    let v = out.layers()[layer].get(x, y)[0];
                    let (l2, x2, y2) = p.wrap_texel(layer, ox, oy, n, n);
                    across = across.max((v - out.layers()[l2].get(x2, y2)[0]).abs());
                    inside = inside.max((v - out.layers()[layer].get(ix, iy)[0]).abs());
                }
            }
        }
        assert!(
            across < 2.0 * inside,
            "{kind}: across edges {across}, inside {inside}"
        );
    }
}

#[test]
fn rotation_and_exposure() {
    // A single bright region straight ahead (-Z).
    let spot = |d: DVec3| {
        let v = if d.dot(DVec3::NEG_Z) > 0.95 { 1.0 } else { 0.0 };
        [v, v, v, 1.0]
    };
    let src = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 256, 3, spot);
    let opts = ResampleOptions {
        rotation: Rotation::from_euler_deg(90.0, 0.0, 0.0),
        exposure: 1.0,
        ..Default::default()
    };
    let out = resample(&src, Projection::from(mirrorball_core::CubeMap), 32, &opts);
    // Yaw 90° turns what was ahead to the left: -X, with exposure +1 stop doubling it.
    let at = |d: DVec3| out.sample(d)[0];
    assert!(
        (at(DVec3::NEG_X) - 2.0).abs() < 1e-3,
        "{}",
        at(DVec3::NEG_X)
    );
    assert!(at(DVec3::NEG_Z).abs() < 1e-6);
    // Mirroring z puts it behind.
    let m = resample(
        &src,
        Projection::from(mirrorball_core::CubeMap),
        32,
        &ResampleOptions {
            rotation: Rotation::mirror(mirrorball_core::Axis::Z),
            ..Default::default()
        },
    );
    assert!((m.sample(DVec3::Z)[0] - 1.0).abs() < 1e-3 && m.sample(DVec3::NEG_Z)[0].abs() < 1e-6);
}

#[test]
fn env_map_refuses_wrong_layer_counts() {
    let img = mirrorball_core::Image::new(4, 4, 3);
    let err = EnvMap::new(
        ProjectionKind::Cube.default_projection(),
        vec![img.clone(); 5],
    )
    .unwrap_err();
    assert!(err.to_string().contains("6 layers"));
    let other = mirrorball_core::Image::new(4, 5, 3);
    assert!(EnvMap::new(
        ProjectionKind::Paraboloid.default_projection(),
        vec![img, other]
    )
    .is_err());
}

/// Largest difference between two maps of one shape, relative to the largest value.
fn max_rel_diff(a: &EnvMap, b: &EnvMap) -> f32 {
    assert_eq!(
        (a.layers().len(), a.width(), a.height(), a.channels()),
        (b.layers().len(), b.width(), b.height(), b.channels())
    );
    let (mut d, mut m) = (0.0f32, 0.0f32);
    for (la, lb) in a.layers().iter().zip(b.layers()) {
        for (x, y) in la.data().iter().zip(lb.data()) {
            d = d.max((x - y).abs());
            m = m.max(x.abs());
        }
    }
    d / m.max(1e-30)
}

/// A plan made once gives what `resample` gives, for plain bilinear lookups, seams,
/// integration with and without mip levels, rotation, exposure and four channels.
#[test]
fn a_planned_remap_matches_resample() {
    use mirrorball_core::Remap;
    let ll = ProjectionKind::LatLong.default_projection();
    let cube = ProjectionKind::Cube.default_projection();
    let zone = |d: DVec3| {
        let t = d.y.clamp(-1.0, 1.0).acos();
        let v = 0.5 + 0.5 * (200.0 * t * t).cos();
        [v as f32, (1.0 + d.x) as f32, 0.5, 0.25 + d.z.abs() as f32]
    };
    let turned = ResampleOptions {
        rotation: Rotation::from_euler_deg(30.0, -20.0, 10.0),
        exposure: 1.5,
        ..Default::default()
    };
    let cases: Vec<(EnvMap, Projection, u32, ResampleOptions)> = vec![
        // Integrated near the poles, bilinear elsewhere, the longitude wrap.
        (
            EnvMap::from_fn(ll, 512, 3, smooth),
            cube,
            64,
            ResampleOptions::default(),
        ),
        // Mip levels (a 1024 lat-long onto 16² faces), four channels.
        (
            EnvMap::from_fn(ll, 1024, 4, zone),
            cube,
            16,
            ResampleOptions::default(),
        ),
        // Growing from a cube: every lookup near a face edge crosses a seam.
        (
            EnvMap::from_fn(cube, 32, 3, smooth),
            ll,
            256,
            ResampleOptions::default(),
        ),
        // Disk maps, turned and exposed.
        (
            EnvMap::from_fn(ProjectionKind::Sphere.default_projection(), 128, 3, smooth),
            ProjectionKind::EqualAreaOctahedral.default_projection(),
            96,
            turned.clone(),
        ),
        (
            EnvMap::from_fn(
                ProjectionKind::Paraboloid.default_projection(),
                64,
                4,
                smooth,
            ),
            ProjectionKind::Fisheye.default_projection(),
            80,
            turned,
        ),
    ];
    for (src, dst, size, opts) in &cases {
        let slow = resample(src, *dst, *size, opts);
        let plan = Remap::new(
            *src.projection(),
            (src.width(), src.height()),
            src.layers().len(),
            *dst,
            *size,
            opts,
        );
        let fast = plan.apply(src).unwrap();
        let e = max_rel_diff(&fast, &slow);
        assert!(
            e < 1e-4,
            "{:?} → {:?}: plan differs by {e}",
            src.projection(),
            dst
        );
        // Reusing an output gives the same texels.
        let mut again = resample(src, *dst, *size, &ResampleOptions::default());
        plan.apply_into(src, &mut again).unwrap();
        assert_eq!(max_rel_diff(&again, &fast), 0.0);
    }
}

/// A plan refuses maps of another projection or size, and outputs of the wrong shape.
#[test]
fn a_planned_remap_refuses_the_wrong_maps() {
    use mirrorball_core::{Remap, RemapError};
    let ll = ProjectionKind::LatLong.default_projection();
    let cube = ProjectionKind::Cube.default_projection();
    let plan = Remap::new(ll, (64, 32), 1, cube, 16, &ResampleOptions::default());
    let other_size = EnvMap::from_fn(ll, 128, 3, smooth);
    assert!(matches!(
        plan.apply(&other_size),
        Err(RemapError::Extent { .. })
    ));
    let other_proj = EnvMap::from_fn(
        ProjectionKind::Octahedral.default_projection(),
        32,
        3,
        smooth,
    );
    assert!(matches!(
        plan.apply(&other_proj),
        Err(RemapError::Projection { .. })
    ));
    let src = EnvMap::from_fn(ll, 64, 3, smooth);
    let mut wrong_out = EnvMap::from_fn(cube, 8, 3, smooth);
    assert_eq!(
        plan.apply_into(&src, &mut wrong_out),
        Err(RemapError::Output)
    );
    let mut wrong_channels = EnvMap::from_fn(cube, 16, 4, smooth);
    assert_eq!(
        plan.apply_into(&src, &mut wrong_channels),
        Err(RemapError::Output)
    );
    assert!(plan.apply(&src).is_ok());
}

#[test]
fn sanitize_zeroes_nan_infinite_and_negative_colour_and_counts_them() {
    // Six layers, RGB and RGBA, larger than one parallel block; alpha is left as it is.
    for c in [3, 4] {
        let proj = mirrorball_core::ProjectionKind::Cube.default_projection();
        let mut layers: Vec<mirrorball_core::Image> = (0..6)
            .map(|_| mirrorball_core::Image::new(161, 161, c))
            .collect();
        let specials = [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -1.0,
            -f32::MIN_POSITIVE,
            -0.0,
            0.0,
            f32::MIN_POSITIVE / 2.0,
            f32::MAX,
            1.5,
        ];
        let mut expect_bad = 0;
        for (l, img) in layers.iter_mut().enumerate() {
            for (i, v) in img.data_mut().iter_mut().enumerate() {
                *v = specials[(i * 7 + l) % specials.len()];
                let (alpha, bad) = (c == 4 && i % 4 == 3, !(*v >= 0.0 && v.is_finite()));
                if !alpha && bad {
                    expect_bad += 1;
                }
            }
        }
        let mut env = mirrorball_core::EnvMap::new(proj, layers.clone()).unwrap();
        assert_eq!(env.sanitize(), expect_bad);
        for (before, after) in layers.iter().zip(env.layers()) {
            for (i, (&b, &a)) in before.data().iter().zip(after.data()).enumerate() {
                if c == 4 && i % 4 == 3 {
                    assert_eq!(b.to_bits(), a.to_bits(), "alpha kept");
                } else if b >= 0.0 && b.is_finite() {
                    assert_eq!(
                        b.to_bits(),
                        a.to_bits(),
                        "valid colour kept (even −0 and subnormals)"
                    );
                } else {
                    assert_eq!(a.to_bits(), 0, "{b} becomes +0");
                }
            }
        }
        assert_eq!(env.sanitize(), 0, "nothing left to fix");
    }
}

/// `Resampler::layer_into` overwrites every texel of a reused buffer (those a projection
/// leaves without a direction included), so that a buffer full of garbage comes out bit for
/// bit as a fresh `layer` does, for every output projection and layer.
#[test]
fn a_resampler_fills_reused_buffers_exactly_as_fresh_ones() {
    use mirrorball_core::{Image, Resampler};
    let src = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 64, 3, smooth);
    for kind in ProjectionKind::ALL {
        let dst = kind.default_projection();
        let (w, h) = dst.layer_extent(24);
        let r = Resampler::new(&src, dst, w, h, &ResampleOptions::default());
        let mut reused = Image::new(w, h, 3);
        for layer in 0..dst.layer_count() {
            reused.data_mut().fill(f32::NAN);
            let fresh = r.layer(layer);
            r.layer_into(layer, &mut reused);
            let same = fresh
                .data()
                .iter()
                .zip(reused.data())
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(
                same,
                "{kind:?} layer {layer}: reused buffer differs from a fresh one"
            );
        }
    }
}

#[test]
#[should_panic(expected = "layer_into")]
fn a_resampler_refuses_a_buffer_of_the_wrong_size() {
    use mirrorball_core::{Image, Resampler};
    let src = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 32, 3, smooth);
    let r = Resampler::new(
        &src,
        ProjectionKind::Cube.default_projection(),
        8,
        8,
        &ResampleOptions::default(),
    );
    r.layer_into(0, &mut Image::new(8, 9, 3));
}

/// A source given as 8- or 16-bit codes or as borrowed floats (`Remap::rows_coded`)
/// converts to the same bits as the float map their table decodes them into (the floats
/// themselves), through every path of the plan: bilinear lookups, seam taps, integrated
/// texels on the base and on mip levels, exposure.
#[test]
fn a_coded_source_converts_to_the_bits_of_its_decoded_map() {
    use mirrorball_core::color::srgb_to_linear;
    use mirrorball_core::{Codes, Remap, RemapError, Rotation};
    let t8: Vec<f32> = (0..256)
        .map(|k| srgb_to_linear(k as f64 / 255.0) as f32)
        .collect();
    let t16: Vec<f32> = (0..65536)
        .map(|k| srgb_to_linear(k as f64 / 65535.0) as f32)
        .collect();
    let ll = ProjectionKind::LatLong.default_projection();
    let (sw, sh) = (512u32, 256u32);
    // Codes from a fixed linear congruential sequence: every byte value, no structure.
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut byte = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 56) as u8
    };
    let narrow: Vec<u8> = (0..sw * sh * 3).map(|_| byte()).collect();
    let wide: Vec<u8> = (0..sw * sh * 6).map(|_| byte()).collect();
    // Floats over a wide range: a sun past what a half float holds, negatives, tiny values.
    let floats: Vec<f32> = wide
        .chunks_exact(2)
        .map(|b| {
            let v = u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0;
            match b[0] % 8 {
                0 => v * 2e5,
                1 => -v,
                2 => v * 1e-6,
                _ => v,
            }
        })
        .collect();
    let opts = ResampleOptions {
        exposure: 0.5,
        rotation: Rotation::from_euler_deg(20.0, 10.0, 0.0),
        ..ResampleOptions::default()
    };
    let dsts = [
        (ProjectionKind::Cube.default_projection(), 8u32), // 16 source texels a texel: mips
        (ProjectionKind::Cube.default_projection(), 200),  // bilinear, seams
        (ProjectionKind::Octahedral.default_projection(), 64),
    ];
    for (codes, what) in [
        (Codes::u8(&narrow, &t8, (sw, sh)).unwrap(), "8-bit"),
        (Codes::u16le(&wide, &t16, (sw, sh)).unwrap(), "16-bit"),
        (Codes::f32(&floats, (sw, sh)).unwrap(), "f32"),
    ] {
        let decoded = EnvMap::new(ll, vec![codes.to_image()]).unwrap();
        for (dst, size) in dsts {
            let plan = Remap::new(ll, (sw, sh), 1, dst, size, &opts);
            assert!(plan.takes_codes());
            assert!(plan.tap_count() > 0, "{dst:?} {size}: no taps to test");
            let floats = plan.rows(&decoded).unwrap();
            let coded = plan.rows_coded(codes).unwrap();
            let (w, h) = plan.extent();
            let (mut a, mut b) = (vec![0.0f32; floats.row_len()], vec![0.0f32; w as usize * 3]);
            let mut nonzero = 0;
            for layer in 0..dst.layer_count() {
                for y in 0..h as usize {
                    floats.row_into(layer, y, &mut a);
                    coded.row_into(layer, y, &mut b);
                    let (ab, bb): (Vec<u32>, Vec<u32>) = (
                        a.iter().map(|v| v.to_bits()).collect(),
                        b.iter().map(|v| v.to_bits()).collect(),
                    );
                    assert_eq!(ab, bb, "{what} {dst:?} {size}: layer {layer} row {y}");
                    nonzero += a.iter().filter(|v| **v != 0.0).count();
                }
            }
            assert!(
                nonzero > (w * h) as usize,
                "{what} {dst:?}: rows of zeros prove nothing"
            );
        }
    }
    // Codes of another size, and a plan whose source is six layers, are refused.
    let plan = Remap::new(
        ll,
        (sw, sh),
        1,
        ProjectionKind::Cube.default_projection(),
        8,
        &opts,
    );
    let small = Codes::u8(&narrow[..64 * 32 * 3], &t8, (64, 32)).unwrap();
    assert!(matches!(
        plan.rows_coded(small),
        Err(RemapError::Extent { .. })
    ));
    let cube = ProjectionKind::Cube.default_projection();
    let from_cube = Remap::new(cube, (64, 64), 6, ll, 64, &opts);
    assert!(!from_cube.takes_codes());
    let one = Codes::u8(&narrow[..64 * 64 * 3], &t8, (64, 64)).unwrap();
    assert!(matches!(from_cube.rows_coded(one), Err(RemapError::Codes)));
    // A dual fisheye whose lenses overlap is read blended, not as it is; one that does not
    // overlap is read as it is.
    use mirrorball_core::projection::ProjectionSpec;
    let lenses = |fov: &str| {
        ProjectionSpec::parse(&format!("dfisheye:fov={fov}"))
            .unwrap()
            .build(Some((128, 64)))
            .unwrap()
    };
    let blended = Remap::new(lenses("200"), (128, 64), 1, ll, 32, &opts);
    assert!(!blended.takes_codes());
    let one = Codes::u8(&narrow[..128 * 64 * 3], &t8, (128, 64)).unwrap();
    assert!(matches!(blended.rows_coded(one), Err(RemapError::Codes)));
    assert!(Remap::new(lenses("180"), (128, 64), 1, ll, 32, &opts).takes_codes());
}

/// A plan laid out as a picture makes, at each picture texel, the bits of the face texel it
/// names, whatever the order (faces turned, mirrored, repeated, gaps), from a float source
/// and from codes, where the plan has integrated texels and seam taps; the picture plan
/// fills no map.
#[test]
fn a_laid_out_plan_makes_the_bits_of_the_texels_it_names() {
    use mirrorball_core::{Codes, Remap};
    let opts = ResampleOptions::default();
    let ll = ProjectionKind::LatLong.default_projection();
    let (sw, sh) = (256u32, 128u32);
    let bytes: Vec<u8> = (0..sw * sh * 3).map(|i| (i * 37 % 251) as u8).collect();
    let table: Vec<f32> = (0..256).map(|k| (k as f32 / 255.0).powf(2.2)).collect();
    let codes = Codes::u8(&bytes, &table, (sw, sh)).unwrap();
    let decoded = EnvMap::new(ll, vec![codes.to_image()]).unwrap();
    for (dst, size) in [
        (ProjectionKind::Cube.default_projection(), 13u32),
        (ProjectionKind::Eac.default_projection(), 16),
        (ProjectionKind::LatLong.default_projection(), 32),
    ] {
        let plan = Remap::new(ll, (sw, sh), 1, dst, size, &opts);
        assert!(plan.tap_count() > 0, "{dst:?}: no taps to test");
        let faces = plan.apply(&decoded).unwrap();
        let (w, h) = plan.extent();
        let n = dst.layer_count() as u32;
        // Picture: the faces side by side, every other one turned a quarter (its rows read
        // down a column), the last column of the picture a gap, one row a repeat.
        let (pw, ph) = (n * w.max(h) + 1, w.max(h) + 1);
        let source = |px: u32, py: u32| -> Option<(usize, u32, u32)> {
            let (cell, cx) = (px / w.max(h), px % w.max(h));
            let py = if py == ph - 1 { 0 } else { py };
            if cell >= n {
                return None;
            }
            let (x, y) = if cell % 2 == 1 {
                (py, w.max(h) - 1 - cx)
            } else {
                (cx, py)
            };
            (x < w && y < h).then_some((cell as usize, x, y))
        };
        let pic = plan.laid_out((pw, ph), source);
        assert_eq!(pic.picture(), Some((pw, ph)));
        for rows in [pic.rows(&decoded).unwrap(), pic.rows_coded(codes).unwrap()] {
            let mut row = vec![f32::NAN; rows.row_len()];
            assert_eq!(row.len(), pw as usize * 3);
            let mut shown = 0;
            for py in 0..ph {
                rows.row_into(0, py as usize, &mut row);
                for px in 0..pw {
                    let got: Vec<u32> = row[px as usize * 3..][..3]
                        .iter()
                        .map(|v| v.to_bits())
                        .collect();
                    let want: Vec<u32> = match source(px, py) {
                        Some((l, x, y)) => {
                            shown += 1;
                            faces.layers()[l]
                                .get(x, y)
                                .iter()
                                .map(|v| v.to_bits())
                                .collect()
                        }
                        None => vec![0; 3],
                    };
                    assert_eq!(got, want, "{dst:?}: picture texel ({px}, {py})");
                }
            }
            assert!(
                shown >= (n * w * h) as usize,
                "{dst:?}: not every texel shown"
            );
        }
        // The picture plan converts the same source but fills no map.
        assert_eq!(
            pic.apply(&decoded).err(),
            Some(mirrorball_core::RemapError::Output)
        );
        let mut out = faces.clone();
        assert_eq!(
            pic.apply_into(&decoded, &mut out).err(),
            Some(mirrorball_core::RemapError::Output)
        );
    }
}

/// `sample_texels` reads what `EnvMap::sample` reads and blends it to the same bits, inside
/// layers and across every seam (cube edges and corners, the longitude wrap, the poles).
#[test]
fn sample_texels_is_env_maps_sample() {
    use mirrorball_core::sample_texels;
    let mut rng = crate::util::Rng(7);
    let mut next = || rng.f64();
    for (kind, size) in [
        (ProjectionKind::Cube, 7u32),
        (ProjectionKind::Eac, 8),
        (ProjectionKind::LatLong, 16),
        (ProjectionKind::Paraboloid, 9),
    ] {
        let p = kind.default_projection();
        let env = EnvMap::from_fn(p, size, 3, |d| {
            [
                d.x as f32 * 3.1 + 0.2,
                (d.y * 7.0).sin() as f32,
                d.z as f32 * d.x as f32,
                1.0,
            ]
        });
        let (w, h) = (env.width(), env.height());
        for k in 0..20_000 {
            // Half the directions near a face edge or corner (coordinates near ±1).
            let mut d = DVec3::new(next() * 2.0 - 1.0, next() * 2.0 - 1.0, next() * 2.0 - 1.0);
            if k % 2 == 0 {
                let a = (next() * 3.0) as usize;
                d[a] = d[a].signum() * (d[(a + 1) % 3].abs().max(d[(a + 2) % 3].abs()));
            }
            let d = d.normalize();
            let mut reads = 0;
            let v = sample_texels::<3>(&p, (w, h), d, |l, x, y| {
                reads += 1;
                env.layers()[l].get(x, y).try_into().unwrap()
            });
            let want = env.sample(d);
            assert_eq!(
                v.map(f32::to_bits),
                [want[0].to_bits(), want[1].to_bits(), want[2].to_bits()],
                "{kind:?} {d}"
            );
            assert!(
                reads == 4 || (reads == 0 && v == [0.0; 3]),
                "{kind:?} {d}: {reads} reads"
            );
        }
    }
}

/// Texels outside an output's covered domain are black for cameras' frames and pictures
/// (fisheye, dual fisheye, Hammer, sinusoidal), the rim's value for the maps a renderer
/// samples (sphere, angular, paraboloid), and either when asked; the plan does as the
/// resampler does, texel for texel, and the inside is the same either way.
#[test]
fn outside_the_covered_domain_is_black_or_the_rim_as_the_projection_or_caller_says() {
    use mirrorball_core::{Outside, Remap};
    let ll = ProjectionKind::LatLong.default_projection();
    let src = EnvMap::from_fn(ll, 64, 4, |d| [2.0 + d.x as f32, 1.5, 1.0, 1.0]);
    for kind in ProjectionKind::ALL {
        let dst = kind.default_projection();
        for asked in [None, Some(Outside::Rim), Some(Outside::Black)] {
            let opts = ResampleOptions {
                outside: asked,
                ..ResampleOptions::default()
            };
            let out = resample(&src, dst, 32, &opts);
            let plan = Remap::new(ll, (64, 32), 1, dst, 32, &opts)
                .apply(&src)
                .unwrap();
            let black = asked.unwrap_or(kind.outside()) == Outside::Black;
            let (mut outside, mut inside) = (0, 0);
            for (layer, (img, planned)) in out.layers().iter().zip(plan.layers()).enumerate() {
                let (w, h) = (img.width(), img.height());
                for y in 0..h {
                    for x in 0..w {
                        let v = img.get(x, y);
                        let p = planned.get(x, y);
                        let uv = glam::DVec2::new(
                            (x as f64 + 0.5) / w as f64,
                            (y as f64 + 0.5) / h as f64,
                        );
                        if dst.nearest_covered(layer, uv) == uv {
                            inside += 1;
                            assert!(
                                v[1] > 1.4,
                                "{kind:?} {asked:?}: inside texel ({x}, {y}) {v:?}"
                            );
                        } else {
                            outside += 1;
                            if black {
                                assert_eq!(v, &[0.0; 4], "{kind:?} {asked:?}: ({x}, {y})");
                            } else {
                                assert!(
                                    v[1] > 1.4 && v[3] > 0.99,
                                    "{kind:?} {asked:?}: ({x}, {y}) {v:?}"
                                );
                            }
                        }
                        for c in 0..4 {
                            assert!(
                                (v[c] - p[c]).abs() <= 1e-4 * v[c].abs().max(1.0),
                                "{kind:?} {asked:?} plan ({x}, {y})"
                            );
                        }
                    }
                }
            }
            assert!(inside > 0, "{kind:?}");
            if matches!(kind, ProjectionKind::Fisheye | ProjectionKind::Sphere) {
                assert!(outside > 0, "{kind:?}: no texel outside to test");
            }
        }
    }
    // The rule as the table gives it.
    for (kind, black) in [
        (ProjectionKind::Fisheye, true),
        (ProjectionKind::DualFisheye, true),
        (ProjectionKind::Hammer, true),
        (ProjectionKind::Sinusoidal, true),
        (ProjectionKind::Sphere, false),
        (ProjectionKind::Angular, false),
        (ProjectionKind::Paraboloid, false),
    ] {
        assert_eq!(kind.outside() == Outside::Black, black, "{kind:?}");
    }
    // A fisheye's corners are outside: the test above saw black there.
    let fe = resample(
        &src,
        ProjectionKind::Fisheye.default_projection(),
        32,
        &ResampleOptions::default(),
    );
    assert_eq!(fe.layers()[0].get(0, 0), &[0.0; 4]);
}
