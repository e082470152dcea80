//! Texel statistics, anisotropy, crossover and used area against closed forms.
use crate::util::{close, proj, Rng};
use glam::{DVec2, DVec3};
use mirrorball_analysis::frustum::{frustum_share, texel_sum, Frustum};
use mirrorball_analysis::geom::{frustum_solid_angle, spherical_polygon_area};
use mirrorball_analysis::jacobian::{anisotropy, jacobian};
use mirrorball_analysis::texels::{crossover, size_for_budget, texel_stats, used_area_fraction};
use mirrorball_core::{ProjectionKind as K, WorldProjection};
use std::f64::consts::{PI, SQRT_2};

#[test]
fn sphere_map_crossover_is_one_over_two_root_two() {
    let c = crossover(&proj(K::Sphere), 512).expect("a crossover circle");
    close(c.radius_uv, 1.0 / (2.0 * SQRT_2), 1e-12, "crossover radius");
    assert!(!c.at_rim);
    close(c.radius_texels, 512.0 / (2.0 * SQRT_2), 1e-12, "in texels");
    // Each hemisphere gets π/8 of the texture: π r² with r = 1/(2√2).
    close(
        PI * c.radius_uv * c.radius_uv,
        PI / 8.0,
        1e-12,
        "front share",
    );
}

#[test]
fn crossovers_of_the_other_disk_maps() {
    // Angular map: θ = πρ, so 90° is at ρ = ½: a quarter of the layer.
    close(
        crossover(&proj(K::Angular), 64).unwrap().radius_uv,
        0.25,
        1e-12,
        "angular",
    );
    // Paraboloid and hemispherical fisheye: the rim.
    for k in [K::Paraboloid, K::Fisheye] {
        let c = crossover(&proj(k), 64).unwrap();
        close(c.radius_uv, 0.5, 1e-9, k.name());
        assert!(c.at_rim, "{}", k.name());
    }
    // No circle on the cube, lat-long or octahedral maps.
    for k in [K::Cube, K::LatLong, K::Octahedral, K::Mercator] {
        assert!(crossover(&proj(k), 64).is_none(), "{}", k.name());
    }
}

#[test]
fn used_area_fractions() {
    for k in K::ALL {
        let want = match k {
            // The dual fisheye: a disk inscribed in each half.
            K::Sphere | K::Paraboloid | K::Angular | K::Fisheye | K::Hammer | K::DualFisheye => {
                PI / 4.0
            }
            // |u − ½| ≤ ½ sin πv.
            K::Sinusoidal => 2.0 / PI,
            _ => 1.0,
        };
        // Disk maps accept points up to 10⁻¹² outside the rim (core's tolerance), so the
        // area can be 2·10⁻¹² large.
        close(used_area_fraction(&proj(k)), want, 1e-11, k.name());
    }
}

#[test]
fn texel_solid_angles_add_up_and_count_rims() {
    for k in K::ALL {
        let p = proj(k);
        let s = texel_stats(&p, 48);
        close(s.solid_angle_sum, p.covered_solid_angle(), 1e-9, k.name());
        assert_eq!(
            s.full_texels + s.partial_texels + s.empty_texels,
            s.texels,
            "{}",
            k.name()
        );
        close(
            s.front_share + s.back_share + s.unused_share,
            1.0,
            1e-12,
            k.name(),
        );
    }
    // Disk maps: the number of texels with any part in the disk, against the count of
    // texels whose square meets the circle x² + y² ≤ r² (independent integer geometry).
    let s = texel_stats(&proj(K::Sphere), 64);
    let r = 32i64;
    let (mut full, mut touched) = (0u64, 0u64);
    for y in 0..64i64 {
        for x in 0..64i64 {
            let (x0, x1, y0, y1) = (x - r, x + 1 - r, y - r, y + 1 - r);
            let far = x0.abs().max(x1.abs()).pow(2) + y0.abs().max(y1.abs()).pow(2);
            let nx = if x0 > 0 {
                x0
            } else if x1 < 0 {
                -x1
            } else {
                0
            };
            let ny = if y0 > 0 {
                y0
            } else if y1 < 0 {
                -y1
            } else {
                0
            };
            if far <= r * r {
                full += 1;
            }
            if nx * nx + ny * ny < r * r {
                touched += 1;
            }
        }
    }
    assert_eq!(s.full_texels, full);
    assert_eq!(s.full_texels + s.partial_texels, touched);
}

#[test]
fn equal_area_maps_have_ratio_one() {
    // Equal-area octahedral: every texel 4π/n².
    let s = texel_stats(&proj(K::EqualAreaOctahedral), 64);
    close(s.full.ratio, 1.0, 1e-12, "equal-area octahedral");
    close(
        s.full.max.value,
        4.0 * PI / (64.0 * 64.0),
        1e-12,
        "its texel",
    );
    // Sphere map (Lambert azimuthal): every full texel 16/n².
    let s = texel_stats(&proj(K::Sphere), 64);
    close(s.full.ratio, 1.0, 1e-11, "sphere map");
    close(s.full.min.value, 16.0 / (64.0 * 64.0), 1e-11, "its texel");
}

#[test]
fn cube_solid_angle_ratio_tends_to_three_root_three() {
    let c = proj(K::Cube);
    let limit = 3f64.powf(1.5);
    // Exactly, for the area element.
    close(
        c.density(0, DVec2::splat(0.5)) / c.density(0, DVec2::ZERO),
        limit,
        1e-12,
        "density",
    );
    // The scan finds the extremes at the face centre and a corner.
    let s = texel_stats(&c, 64);
    let ratio =
        |n: u32| c.texel_solid_angle(0, n / 2, n / 2, n, n) / c.texel_solid_angle(0, 0, 0, n, n);
    close(s.full.ratio, ratio(64), 1e-12, "scan vs centre/corner");
    // Texels: the ratio approaches 3√3 like 1/n; Richardson's extrapolation removes that.
    let mut prev = f64::INFINITY;
    for n in [64, 256, 1024, 4096] {
        let e = (ratio(n) / limit - 1.0).abs();
        assert!(e < prev && e < 2.5 / n as f64, "n = {n}: {e}");
        prev = e;
    }
    close(2.0 * ratio(4096) - ratio(2048), limit, 1e-6, "Richardson");
}

#[test]
fn paraboloid_ratio_tends_to_four() {
    let p = proj(K::Paraboloid);
    close(
        p.density(0, DVec2::splat(0.5)) / p.density(0, DVec2::new(1.0, 0.5)),
        4.0,
        1e-12,
        "density",
    );
    let mut prev = 0.0;
    for n in [32, 64, 128] {
        let r = texel_stats(&p, n).full.ratio;
        assert!(
            r > prev && r < 4.0 && r > 4.0 * (1.0 - 8.0 / n as f64),
            "n = {n}: {r}"
        );
        prev = r;
    }
}

#[test]
fn anisotropy_matches_closed_forms() {
    let mut rng = Rng(7);
    // Sphere map: radial stretch / tangential = 1/(1 − ρ²).
    let s = proj(K::Sphere);
    for _ in 0..50 {
        let (r, t) = (0.999 * rng.f64().sqrt(), 2.0 * PI * rng.f64());
        let uv = DVec2::new(0.5 + 0.5 * r * t.cos(), 0.5 + 0.5 * r * t.sin());
        close(
            anisotropy(&s, 0, uv, 256, 256).unwrap(),
            1.0 / (1.0 - r * r),
            1e-6,
            "sphere map",
        );
    }
    // The outermost texel of the centre row of an n² sphere map: n²/(2(n − 1)).
    let n = 512.0;
    let uv = DVec2::new((n - 0.5) / n, (n / 2.0 + 0.5) / n);
    close(
        anisotropy(&s, 0, uv, 512, 512).unwrap(),
        n * n / (2.0 * (n - 1.0)),
        1e-6,
        "rim texel",
    );
    // Cube (gnomonic): √(1 + a² + b²).
    let c = proj(K::Cube);
    for _ in 0..50 {
        let (a, b) = (2.0 * rng.f64() - 1.0, 2.0 * rng.f64() - 1.0);
        let uv = DVec2::new(0.5 * (a + 1.0), 0.5 * (b + 1.0));
        close(
            anisotropy(&c, 2, uv, 64, 64).unwrap(),
            (1.0 + a * a + b * b).sqrt(),
            1e-6,
            "cube",
        );
    }
    // Lat-long with square texels (w = 2h): 1/cos φ. Conformal maps: 1.
    let l = proj(K::LatLong);
    for _ in 0..50 {
        let v = 0.02 + 0.96 * rng.f64();
        let phi = PI * (0.5 - v);
        close(
            anisotropy(&l, 0, DVec2::new(rng.f64(), v), 512, 256).unwrap(),
            1.0 / phi.cos(),
            1e-6,
            "lat-long",
        );
        let uv = DVec2::new(rng.f64(), rng.f64());
        let m = proj(K::Mercator);
        let (w, h) = m.layer_extent(256);
        close(anisotropy(&m, 0, uv, w, h).unwrap(), 1.0, 1e-6, "Mercator");
        let ab = DVec2::new(rng.f64(), rng.f64()) * 1.4 - 0.7;
        if ab.length() < 0.99 {
            let uv = DVec2::new(0.5 * (ab.x + 1.0), 0.5 * (1.0 - ab.y));
            close(
                anisotropy(&proj(K::Paraboloid), 1, uv, 64, 64).unwrap(),
                1.0,
                1e-6,
                "paraboloid",
            );
        }
    }
}

#[test]
fn jacobian_area_is_the_density() {
    // σ₁σ₂ = |∂d/∂X × ∂d/∂Y| must equal density/(w·h): the finite differences of uv_to_dir
    // against the projections' own analytic area elements.
    let mut rng = Rng(11);
    for k in K::ALL {
        let p = proj(k);
        let (w, h) = p.layer_extent(128);
        let mut checked = 0;
        while checked < 40 {
            let l = (rng.f64() * p.layer_count() as f64) as usize;
            let uv = DVec2::new(0.02 + 0.96 * rng.f64(), 0.02 + 0.96 * rng.f64());
            let (Some(j), d) = (jacobian(&p, l, uv, w, h), p.density(l, uv)) else {
                continue;
            };
            if d == 0.0 {
                continue;
            }
            close(j.area(), d / (w as f64 * h as f64), 1e-6, k.name());
            let (s1, s2) = j.singular_values();
            close(s1 * s2, j.area(), 1e-9, "σ₁σ₂");
            checked += 1;
        }
    }
}

#[test]
fn octahedral_creases_give_the_larger_side() {
    // A texel centre on the fold |a| + |b| = 1 (w even: a = 1/w·odd): the anisotropy there is
    // the larger of the two sides.
    let p = proj(K::Octahedral);
    let w = 64;
    let uv = DVec2::new((40.0 + 0.5) / 64.0, (55.0 + 0.5) / 64.0);
    let (a, b) = (2.0 * uv.x - 1.0, 2.0 * uv.y - 1.0);
    assert!((a.abs() + b.abs() - 1.0).abs() < 1e-12, "on the fold");
    let at = anisotropy(&p, 0, uv, w, w).unwrap();
    let e = 1e-4;
    let l = anisotropy(&p, 0, uv - DVec2::new(e, 0.0), w, w).unwrap();
    let r = anisotropy(&p, 0, uv + DVec2::new(e, 0.0), w, w).unwrap();
    close(at, l.max(r), 1e-3, "crease");
}

#[test]
fn equal_budget_sizes() {
    let b = 6 * 512 * 512;
    assert_eq!(size_for_budget(&proj(K::Cube), b), 512);
    assert_eq!(size_for_budget(&proj(K::Sphere), b), 1254); // √1572864 = 1254.1
    assert_eq!(size_for_budget(&proj(K::Paraboloid), b), 887); // √786432 = 886.8
    assert_eq!(size_for_budget(&proj(K::LatLong), b), 1774); // w·w/2: √3145728 = 1773.6
                                                             // Zimmons' fair comparison: a 512² sphere map's texels as six cube faces.
    assert_eq!(size_for_budget(&proj(K::Cube), 512 * 512), 209);
}

#[test]
fn greene_frustum_share() {
    let f = Frustum::GREENE;
    let (a, b) = f.half_angles();
    close(b, 22.5f64.to_radians(), 1e-15, "β");
    close(a.tan(), 4.0 / 3.0 * b.tan(), 1e-15, "α");
    // The closed form against the spherical polygon through the corners.
    let closed = frustum_solid_angle(a, b);
    close(
        spherical_polygon_area(&f.corners()),
        closed,
        1e-12,
        "polygon",
    );
    // A sanity value: about 6% (Greene), 5.92% exactly.
    let share = closed / (4.0 * PI);
    assert!((share - 0.0592).abs() < 5e-5, "{share}");
    // Brute force: exact solid angles of the texels whose centre is inside, on two maps. The
    // frustum's edges cut texels, so this converges like 1/n.
    let r = frustum_share(
        f,
        &[(proj(K::Cube), 512), (proj(K::EqualAreaOctahedral), 1024)],
    );
    for bf in &r.brute_force {
        assert!(
            bf.relative_error.abs() < 4e-3,
            "{}: {}",
            bf.projection,
            bf.relative_error
        );
    }
    let e = |n: u32| {
        frustum_share(f, &[(proj(K::Cube), n)]).brute_force[0]
            .relative_error
            .abs()
    };
    assert!(e(2048) < e(512) / 3.0, "converges");
    // A frustum of 90° × 90° is one cube face: exactly 4π/6 by texels too.
    let face = Frustum {
        aspect: 1.0,
        vertical_fov_deg: 90.0,
    };
    let (a, b) = face.half_angles();
    close(frustum_solid_angle(a, b), 4.0 * PI / 6.0, 1e-12, "a face");
    let (_, s) = texel_sum(&proj(K::Cube), 16, |d: DVec3| face.contains(d));
    close(s, 4.0 * PI / 6.0, 1e-12, "a face by texels");
}
