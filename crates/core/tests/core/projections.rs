//! Properties every projection must have: exact inverses, exact solid angles, seams that
//! line up.
use crate::util::{all_projections, angle, inside, Rng};
use glam::{DVec2, DVec3};
use mirrorball_core::{
    ContinuousCube, CubeMap, DirRun, DualParaboloid, EqualAreaOctahedral, LatLong, Octahedral,
    Projection, SphereMap, WorldProjection,
};

#[test]
fn direction_to_texel_to_direction_within_1e_5_rad() {
    for p in all_projections() {
        let mut rng = Rng(7);
        let (mut worst, mut covered) = (0.0f64, 0);
        for _ in 0..100_000 {
            let d = rng.dir();
            let Some((layer, uv)) = p.dir_to_uv(d) else {
                continue;
            };
            covered += 1;
            assert!(layer < p.layer_count());
            assert!(
                (-1e-12..=1.0 + 1e-12).contains(&uv.x),
                "{} u={}",
                p.name(),
                uv.x
            );
            assert!(
                (-1e-12..=1.0 + 1e-12).contains(&uv.y),
                "{} v={}",
                p.name(),
                uv.y
            );
            let back = p.uv_to_dir(layer, uv).expect("covered uv maps back");
            worst = worst.max(angle(d, back));
        }
        assert!(worst < 1e-5, "{}: worst round trip {worst:e} rad", p.name());
        // Every projection but the limited ones covers everything.
        let frac = covered as f64 / 1e5;
        let expect = p.covered_solid_angle() / (4.0 * std::f64::consts::PI);
        assert!(
            (frac - expect).abs() < 0.01,
            "{}: covered {frac} expected {expect}",
            p.name()
        );
    }
}

#[test]
fn texel_to_direction_to_texel_round_trip() {
    for p in all_projections() {
        let mut rng = Rng(11);
        let mut worst = 0.0f64;
        let mut n = 0;
        while n < 100_000 {
            let layer = (rng.next_u64() % p.layer_count() as u64) as usize;
            let uv = rng.uv();
            if !inside(&p, layer, uv) {
                continue;
            }
            n += 1;
            let d = p.uv_to_dir(layer, uv).expect("inside");
            assert!((d.length() - 1.0).abs() < 1e-12);
            let (l2, uv2) = p.dir_to_uv(d).expect("covered");
            assert_eq!(l2, layer, "{} uv {uv}", p.name());
            worst = worst.max((uv2 - uv).length());
        }
        assert!(worst < 1e-8, "{}: worst uv round trip {worst:e}", p.name());
    }
}

#[test]
fn texel_solid_angles_sum_to_the_covered_solid_angle() {
    for p in all_projections() {
        for size in [7u32, 16, 33] {
            let (w, h) = p.layer_extent(size);
            let mut total = 0.0;
            for layer in 0..p.layer_count() {
                for y in 0..h {
                    for x in 0..w {
                        let s = p.texel_solid_angle(layer, x, y, w, h);
                        assert!(s >= 0.0 && s.is_finite());
                        total += s;
                    }
                }
            }
            let want = p.covered_solid_angle();
            let rel = (total - want).abs() / want;
            assert!(
                rel < 1e-9,
                "{} size {size}: {total} vs {want} (rel {rel:e})",
                p.name()
            );
        }
    }
}

/// Brute force: the midpoint rule over the density, texel by texel, for texels wholly inside.
#[test]
fn texel_solid_angle_agrees_with_brute_force_integral_of_density() {
    let (w, h) = (12u32, 12u32);
    for p in all_projections() {
        let (w, h) = if p.layer_count() == 1 && p.layer_extent(w).1 != p.layer_extent(w).0 {
            p.layer_extent(24)
        } else {
            (w, h)
        };
        let mut rng = Rng(3);
        let mut checked = 0;
        for _ in 0..40 {
            let layer = (rng.next_u64() % p.layer_count() as u64) as usize;
            let (x, y) = (
                (rng.next_u64() % w as u64) as u32,
                (rng.next_u64() % h as u64) as u32,
            );
            let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
            let all_in = corners.iter().all(|(cx, cy)| {
                let uv = DVec2::new((x as f64 + cx) / w as f64, (y as f64 + cy) / h as f64);
                p.uv_to_dir(layer, uv).is_some() && p.density(layer, uv) > 0.0
            });
            if !all_in {
                continue;
            }
            let n = 200;
            let mut s = 0.0;
            for j in 0..n {
                for i in 0..n {
                    let uv = DVec2::new(
                        (x as f64 + (i as f64 + 0.5) / n as f64) / w as f64,
                        (y as f64 + (j as f64 + 0.5) / n as f64) / h as f64,
                    );
                    s += p.density(layer, uv);
                }
            }
            s /= (n * n) as f64 * (w * h) as f64;
            let exact = p.texel_solid_angle(layer, x, y, w, h);
            let rel = (s - exact).abs() / exact;
            assert!(
                rel < 1e-4,
                "{} texel ({x},{y}) of {layer}: {s} vs {exact}",
                p.name()
            );
            checked += 1;
        }
        assert!(checked > 5, "{}: too few interior texels", p.name());
    }
}

/// The density is |∂d/∂u × ∂d/∂v|, checked by central differences of `uv_to_dir`.
#[test]
fn density_is_the_jacobian_of_uv_to_dir() {
    for p in all_projections() {
        let mut rng = Rng(5);
        let mut n = 0;
        while n < 2000 {
            let layer = (rng.next_u64() % p.layer_count() as u64) as usize;
            let uv = rng.uv();
            let ab = uv * 2.0 - DVec2::ONE;
            let near_fold = ab.x.abs() < 1e-3
                || ab.y.abs() < 1e-3
                || (ab.x.abs() + ab.y.abs() - 1.0).abs() < 1e-3;
            let hstep = 1e-6;
            let ok = [(-1.0, 0.0), (1.0, 0.0), (0.0, -1.0), (0.0, 1.0)]
                .iter()
                .all(|(dx, dy)| inside(&p, layer, uv + DVec2::new(*dx, *dy) * 2e-3));
            if !ok || !inside(&p, layer, uv) || near_fold {
                continue;
            }
            n += 1;
            let f = |o: DVec2| p.uv_to_dir(layer, uv + o).unwrap();
            let du = (f(DVec2::new(hstep, 0.0)) - f(DVec2::new(-hstep, 0.0))) / (2.0 * hstep);
            let dv = (f(DVec2::new(0.0, hstep)) - f(DVec2::new(0.0, -hstep))) / (2.0 * hstep);
            let jac = du.cross(dv).length();
            let dens = p.density(layer, uv);
            assert!(
                (jac - dens).abs() <= 1e-5 * dens.max(1.0),
                "{} at {uv}: {jac} vs {dens}",
                p.name()
            );
        }
    }
}

#[test]
fn closed_form_area_ratios() {
    // Cube: centre / corner density ratio is 3√3.
    let c = CubeMap.density(0, DVec2::splat(0.5)) / CubeMap.density(0, DVec2::ZERO);
    assert!((c / (3.0 * 3f64.sqrt()) - 1.0).abs() < 1e-12);
    // Paraboloid: centre / rim ratio is 4.
    let dp = DualParaboloid::default();
    let r = dp.density(0, DVec2::splat(0.5)) / dp.density(0, DVec2::new(1.0, 0.5));
    assert!((r / 4.0 - 1.0).abs() < 1e-12);
    // Sphere map and equal-area octahedral: uniform.
    let s = SphereMap::default();
    for uv in [
        DVec2::new(0.5, 0.5),
        DVec2::new(0.9, 0.5),
        DVec2::new(0.2, 0.3),
    ] {
        assert!(
            (s.density(0, uv) - 16.0).abs() < 1e-9,
            "{}",
            s.density(0, uv)
        );
        assert!((EqualAreaOctahedral.density(0, uv) - 4.0 * std::f64::consts::PI).abs() < 1e-12);
    }
    // Sphere map: the hemisphere facing the viewer ends at radius 1/(2√2) in texture units.
    let side = SphereMap::default().dir_to_uv(DVec3::X).unwrap().1;
    assert!(((side - DVec2::splat(0.5)).length() - 1.0 / (2.0 * 2f64.sqrt())).abs() < 1e-15);
}

/// Walks every face edge of a six-face projection: the point just across the edge lands on
/// the neighbouring face's edge, at the same (or mirrored) position along it, so the texels
/// of adjacent faces line up. Returns the number of distinct face pairs seen.
fn check_face_edges(p: &Projection) -> usize {
    let mut pairs = std::collections::HashSet::new();
    for face in 0..6 {
        for edge in 0..4 {
            let mut along_map: Vec<(f64, f64)> = Vec::new();
            let mut other_face = None;
            for k in 1..40 {
                let t = k as f64 / 40.0;
                let (uv, out) = match edge {
                    0 => (DVec2::new(0.0, t), DVec2::new(-1e-9, 0.0)),
                    1 => (DVec2::new(1.0, t), DVec2::new(1e-9, 0.0)),
                    2 => (DVec2::new(t, 0.0), DVec2::new(0.0, -1e-9)),
                    _ => (DVec2::new(t, 1.0), DVec2::new(0.0, 1e-9)),
                };
                let d = p.uv_to_dir(face, uv).unwrap();
                let across = p.uv_to_dir(face, uv + out).unwrap();
                let (nf, nuv) = p.dir_to_uv(across).unwrap();
                assert_ne!(nf, face, "{}: point across edge stays on face", p.name());
                assert!(other_face.is_none() || other_face == Some(nf));
                other_face = Some(nf);
                // On the neighbour's border.
                let border = nuv.x.min(nuv.y).min(1.0 - nuv.x).min(1.0 - nuv.y);
                assert!(border < 1e-6, "{}: not on a border: {nuv}", p.name());
                assert!(angle(p.uv_to_dir(nf, nuv).unwrap(), d) < 1e-6);
                let along = if nuv.x.min(1.0 - nuv.x) < 1e-6 {
                    nuv.y
                } else {
                    nuv.x
                };
                along_map.push((t, along));
            }
            // Same position along the edge, or mirrored.
            let same = along_map.iter().all(|(t, a)| (t - a).abs() < 1e-6);
            let mirrored = along_map.iter().all(|(t, a)| (1.0 - t - a).abs() < 1e-6);
            assert!(
                same || mirrored,
                "{}: face {face} edge {edge}: {along_map:?}",
                p.name()
            );
            let nf = other_face.unwrap();
            pairs.insert((face.min(nf), face.max(nf)));
        }
    }
    pairs.len()
}

#[test]
fn cube_and_continuous_cube_are_continuous_across_all_12_edges() {
    assert_eq!(check_face_edges(&CubeMap.into()), 12);
    assert_eq!(check_face_edges(&ContinuousCube.into()), 12);
}

#[test]
fn continuous_cube_reaches_the_face_edges_where_the_printed_eq6_does_not() {
    // On the +Y face at x = 0, the edge with +Z is the direction (0, 1, 1)/√2.
    let d = DVec3::new(0.0, 1.0, 1.0).normalize();
    let (face, uv) = ContinuousCube.dir_to_uv(d).unwrap();
    assert!(face == 2 || face == 4);
    let border = uv.x.min(uv.y).min(1.0 - uv.x).min(1.0 - uv.y);
    assert!(border < 1e-12, "ours puts the edge on the border: {uv}");
    // The paper's eq. (6), as printed: v = (1 + asin(Rz/√(2 + Rx²/Ry²))/asin(1/√3))/2.
    let (rx, ry, rz) = (d.x, d.y, d.z);
    let v6 =
        (1.0 + (rz / (2.0 + rx * rx / (ry * ry)).sqrt()).asin() / (1.0 / 3f64.sqrt()).asin()) / 2.0;
    assert!(
        (v6 - 1.0).abs() > 0.05,
        "eq. (6) as printed misses the edge: v = {v6}"
    );
    // The Appendix A shader's T is what we compute on +Y (t axis = +z).
    let t_shader = (1.0 + rz.asin() / (1.0 / (2.0 + (rx / ry).powi(2)).sqrt()).asin()) / 2.0;
    assert!((t_shader - 1.0).abs() < 1e-12);
    // And in the face interior, our v on +Y equals the shader's T, our u its mirrored S.
    let d = DVec3::new(0.3, 0.9, -0.2).normalize();
    let (face, uv) = ContinuousCube.dir_to_uv(d).unwrap();
    assert_eq!(face, 2);
    let (x, y, z) = (d.x, d.y, d.z);
    let s = 0.5 - (x / y).atan2(2f64.sqrt()) / (2.0 * (1.0 / 3f64.sqrt()).asin());
    let t = (1.0 + z.asin() / (1.0 / (2.0 + (x / y).powi(2)).sqrt()).asin()) / 2.0;
    assert!(
        (uv.x - (1.0 - s)).abs() < 1e-12 && (uv.y - t).abs() < 1e-12,
        "{uv} vs ({s}, {t})"
    );
}

#[test]
fn latlong_wraps_in_longitude_and_over_the_poles() {
    let (w, h) = (16u32, 8u32);
    assert_eq!(LatLong.wrap_texel(0, -1, 3, w, h), (0, 15, 3));
    assert_eq!(LatLong.wrap_texel(0, 16, 3, w, h), (0, 0, 3));
    // Over the north pole: row -1 is row 0, half a turn round.
    assert_eq!(LatLong.wrap_texel(0, 2, -1, w, h), (0, 10, 0));
    assert_eq!(LatLong.wrap_texel(0, 2, 8, w, h), (0, 10, 7));
    // The seam u = 0 / u = 1 is one meridian.
    let a = LatLong.uv_to_dir(0, DVec2::new(0.0, 0.3)).unwrap();
    let b = LatLong.uv_to_dir(0, DVec2::new(1.0, 0.3)).unwrap();
    assert!(angle(a, b) < 1e-12);
    // The wrapped texel really is the neighbour on the sphere: its centre is one texel away.
    let c0 = LatLong
        .uv_to_dir(0, DVec2::new(2.5 / 16.0, 0.5 / 8.0))
        .unwrap();
    let c1 = LatLong
        .uv_to_dir(0, DVec2::new(10.5 / 16.0, 0.5 / 8.0))
        .unwrap();
    let ext = LatLong
        .uv_to_dir(0, DVec2::new(2.5 / 16.0, -0.5 / 8.0))
        .unwrap();
    assert!(angle(ext, c1) < 1e-12 && angle(c0, c1) > 0.0);
}

#[test]
fn octahedral_borders_mirror_about_their_midpoints() {
    for p in [Projection::from(Octahedral), EqualAreaOctahedral.into()] {
        for k in 0..=20 {
            let t = k as f64 / 20.0;
            for (a, b) in [
                (DVec2::new(0.0, t), DVec2::new(0.0, 1.0 - t)),
                (DVec2::new(1.0, t), DVec2::new(1.0, 1.0 - t)),
                (DVec2::new(t, 0.0), DVec2::new(1.0 - t, 0.0)),
                (DVec2::new(t, 1.0), DVec2::new(1.0 - t, 1.0)),
            ] {
                let (da, db) = (p.uv_to_dir(0, a).unwrap(), p.uv_to_dir(0, b).unwrap());
                assert!(angle(da, db) < 1e-9, "{} {a} {b}", p.name());
            }
        }
        assert_eq!(p.wrap_texel(0, -1, 2, 8, 8), (0, 0, 5));
        assert_eq!(p.wrap_texel(0, 3, 8, 8, 8), (0, 4, 7));
    }
}

#[test]
fn paraboloid_rims_meet() {
    let dp = DualParaboloid::default();
    for k in 0..64 {
        let phi = k as f64 / 64.0 * std::f64::consts::TAU;
        let (a, b) = (phi.cos(), phi.sin());
        let front = dp
            .uv_to_dir(0, DVec2::new((a + 1.0) / 2.0, (1.0 - b) / 2.0))
            .unwrap();
        let back = dp
            .uv_to_dir(1, DVec2::new((-a + 1.0) / 2.0, (1.0 - b) / 2.0))
            .unwrap();
        assert!(angle(front, back) < 1e-12);
        assert!(
            front.z.abs() < 1e-12,
            "the rim is the equator around the view axis"
        );
    }
}

#[test]
fn sphere_map_rim_is_one_direction() {
    let s = SphereMap::default();
    for k in 0..16 {
        let phi = k as f64 / 16.0 * std::f64::consts::TAU;
        let uv = DVec2::new(0.5 + 0.5 * phi.cos(), 0.5 + 0.5 * phi.sin());
        let d = s.uv_to_dir(0, uv).unwrap();
        assert!(
            angle(d, DVec3::NEG_Z) < 1e-7,
            "rim shows what is straight ahead"
        );
    }
}

/// The f32 batch path of the conversion loop agrees with the exact f64 methods.
#[test]
fn batch_lookups_agree_with_the_f64_methods() {
    use mirrorball_core::Lookup;
    for p in all_projections() {
        let mut rng = Rng(13);
        let dirs: Vec<DVec3> = (0..20_000).map(|_| rng.dir()).collect();
        let xs: Vec<f32> = dirs.iter().map(|d| d.x as f32).collect();
        let ys: Vec<f32> = dirs.iter().map(|d| d.y as f32).collect();
        let zs: Vec<f32> = dirs.iter().map(|d| d.z as f32).collect();
        let mut out = vec![Lookup::default(); dirs.len()];
        p.lookup_batch(&xs, &ys, &zs, &mut out);
        let mut checked = 0;
        for (i, d) in dirs.iter().enumerate() {
            // The f32 direction is what the batch saw.
            let d32 = DVec3::new(xs[i] as f64, ys[i] as f64, zs[i] as f64);
            match p.dir_to_uv(d32) {
                None => assert_eq!(out[i].layer, u32::MAX, "{}", p.name()),
                Some((l, uv)) => {
                    if out[i].layer as usize != l {
                        // Only on a face boundary, where both faces agree.
                        let b = p
                            .uv_to_dir(
                                out[i].layer as usize,
                                DVec2::new(out[i].u as f64, out[i].v as f64),
                            )
                            .unwrap();
                        assert!(angle(b, *d) < 1e-5, "{}", p.name());
                        continue;
                    }
                    let e = (DVec2::new(out[i].u as f64, out[i].v as f64) - uv).length();
                    // The lat-long seam: u = 0 and u = 1 are the same meridian.
                    use mirrorball_core::ProjectionKind as K;
                    let e = if matches!(
                        p.kind(),
                        K::LatLong | K::Mercator | K::Cylindrical | K::CylindricalEqualArea
                    ) {
                        e.min((e - 1.0).abs())
                    } else {
                        e
                    };
                    assert!(e < 2e-6, "{}: uv error {e:e} at {d}", p.name());
                    let dens = p.density_of_dir(d32);
                    assert!(
                        (out[i].density as f64 - dens).abs() <= 1e-5 * dens.max(1e-3),
                        "{}",
                        p.name()
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 1000, "{}", p.name());
    }
}

/// `span_dirs`, `span_dirs_f32` (which the resampler's texel loop uses) and `row_dirs`
/// (with their per-row shortcuts such as the lat-long longitude recurrence) agree with
/// `uv_to_dir` and
/// `density` at the texel centres, for spans starting anywhere in a row: the integration
/// points of a texel are such spans on a finer grid.
#[test]
fn span_dirs_in_f64_and_f32_agree_with_uv_to_dir_and_density_at_texel_centres() {
    for p in all_projections() {
        let (w, h) = p.layer_extent(36);
        for layer in 0..p.layer_count() {
            let mut row = vec![None; w as usize];
            for y in [0, 1, h / 3, h / 2, h - 1] {
                p.row_dirs(layer, y, w, h, &mut row);
                for (x0, n) in [(0, w), (1, 3), (w / 2 - 2, 4), (w - 2, 2), (w - 1, 1)] {
                    let mut span = vec![None; n as usize];
                    p.span_dirs(layer, y, w, h, x0, &mut span);
                    // The f32 arrays the resampler reads: the same to f32 precision.
                    let mut f = vec![vec![0.0f32; n as usize]; 4];
                    let [fx, fy, fz, fd] = &mut f[..] else {
                        unreachable!()
                    };
                    let run = DirRun {
                        x: fx,
                        y: fy,
                        z: fz,
                        density: fd,
                    };
                    p.span_dirs_f32(layer, y, w, h, x0, run);
                    for (i, t) in span.iter().enumerate() {
                        let (d, dens) = t.expect("a direction");
                        let g = DVec3::new(f[0][i] as f64, f[1][i] as f64, f[2][i] as f64);
                        assert!(
                            angle(d, g) < 1e-6,
                            "{} ({}, {y}) f32 direction",
                            p.name(),
                            x0 + i as u32
                        );
                        let gd = f[3][i] as f64;
                        assert!(
                            (gd - dens).abs() <= 1e-6 * dens.abs(),
                            "{} ({}, {y}) f32 density {gd} vs {dens}",
                            p.name(),
                            x0 + i as u32
                        );
                    }
                    for (i, got) in span.iter().enumerate() {
                        let x = x0 + i as u32;
                        let uv =
                            DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                        let (d, dens) = got.expect("a direction for every texel");
                        let (rd, rdens) = row[x as usize].expect("a direction for every texel");
                        assert!(
                            angle(d, rd) < 1e-9 && (dens - rdens).abs() <= 1e-9 * rdens.abs(),
                            "{} layer {layer} ({x}, {y}): span and row differ",
                            p.name()
                        );
                        let wd = p.density(layer, uv);
                        if wd == 0.0 {
                            assert_eq!(dens, 0.0, "{} ({x}, {y}) lies outside", p.name());
                            continue;
                        }
                        let want = p.uv_to_dir(layer, uv).expect("covered");
                        assert!(
                            angle(d, want) < 1e-9,
                            "{} layer {layer} ({x}, {y})",
                            p.name()
                        );
                        assert!(
                            (dens - wd).abs() <= 1e-9 * wd,
                            "{} ({x}, {y}): {dens} vs {wd}",
                            p.name()
                        );
                    }
                }
            }
        }
    }
}
