//! Samplers: the footprint goes through the projection's Jacobian, so the same cone gives
//! the same result on a cube, a sphere map and a lat-long map.
use crate::util::{analytic, analytic_env};
use mirrorball_core::glam::DVec3;
use mirrorball_core::{EnvMap, ProjectionKind, WorldProjection};
use mirrorball_filter::sampler::{footprint_ellipse, semi_axes, uv_derivatives};
use mirrorball_filter::{directions, Filter, Footprint, Sampler, SummedAreaTable};

/// The exact EWA target on the sphere: `∫ L (exp(−2θ²/β²) − exp(−2)) [θ < β] dω / ∫ …`, by
/// dense quadrature over the cap (tangent-plane polar grid mapped by the exponential map).
fn gaussian_cone(d: DVec3, beta: f64) -> [f64; 3] {
    let t1 = DVec3::new(d.z, 0.0, -d.x).normalize();
    let t2 = d.cross(t1);
    let (nr, na) = (200, 256);
    let (mut acc, mut ws) = ([0.0; 3], 0.0);
    for i in 0..nr {
        let r = (i as f64 + 0.5) / nr as f64 * beta;
        for j in 0..na {
            let a = (j as f64 + 0.5) / na as f64 * std::f64::consts::TAU;
            let l = d * r.cos() + (t1 * a.cos() + t2 * a.sin()) * r.sin();
            let w = ((-2.0 * r * r / (beta * beta)).exp() - (-2.0f64).exp()) * r.sin();
            let v = analytic(l);
            for k in 0..3 {
                acc[k] += w * v[k] as f64;
            }
            ws += w;
        }
    }
    acc.map(|v| v / ws)
}

#[test]
fn jacobian_determinant_is_the_area_element() {
    for kind in [
        ProjectionKind::Cube,
        ProjectionKind::LatLong,
        ProjectionKind::Sphere,
        ProjectionKind::Paraboloid,
        ProjectionKind::Octahedral,
        ProjectionKind::EqualAreaOctahedral,
    ] {
        let p = kind.default_projection();
        for d in directions::fibonacci(64) {
            let Some((layer, uv)) = p.dir_to_uv(d) else {
                continue;
            };
            let (du, dv) = uv_derivatives(&p, layer, uv).unwrap();
            let det = du.cross(dv).length();
            let dens = p.density(layer, uv);
            if dens < 1e-3 {
                continue; // the sphere map's rim
            }
            assert!(
                (det - dens).abs() < 1e-4 * dens,
                "{kind} {d:?}: {det} vs {dens}"
            );
        }
    }
}

#[test]
fn same_cone_same_result_in_every_projection() {
    // Tolerance: 1% of the exact Gaussian-cone average, for a 4° cone on an environment
    // whose radiance doubles across the cone near its bright spot, at resolutions where
    // texels are under a fifth of the cone; away from the two places where a projection
    // has no resolution left (the sphere map's rim, straight ahead at -Z, and the lat-long
    // poles). The maps agree with each other to 1.5%.
    let beta = 4f64.to_radians();
    let maps = [
        ("cube 128", analytic_env(ProjectionKind::Cube, 128)),
        ("lat-long 1024", analytic_env(ProjectionKind::LatLong, 1024)),
        ("sphere 1024", analytic_env(ProjectionKind::Sphere, 1024)),
    ];
    let samplers: Vec<(&str, Sampler)> = maps
        .iter()
        .map(|(n, e)| (*n, Sampler::new(e, Filter::Ewa)))
        .collect();
    let dirs: Vec<DVec3> = directions::fibonacci(48)
        .into_iter()
        .filter(|d| d.y.abs() < 0.9 && d.dot(DVec3::NEG_Z) < 0.5)
        .collect();
    assert!(dirs.len() >= 20);
    let mut worst = 0.0f64;
    for d in &dirs {
        let want = gaussian_cone(*d, beta);
        let mut got_all = Vec::new();
        for (name, s) in &samplers {
            let got = s.sample(*d, &Footprint::Cone(beta));
            let e = (0..3)
                .map(|k| (got[k] as f64 - want[k]).abs() / want[k].abs())
                .fold(0.0, f64::max);
            worst = worst.max(e);
            assert!(e < 0.01, "{name} {d:?}: {got:?} vs {want:?}");
            got_all.push(got);
        }
        // And with each other.
        for g in &got_all[1..] {
            for k in 0..3 {
                assert!((g[k] - got_all[0][k]).abs() < 0.015 * got_all[0][k].abs());
            }
        }
    }
    println!("EWA, 4° cone, cube/lat-long/sphere vs exact: worst {worst:.2e}");
}

#[test]
fn trilinear_and_box_agree_roughly_across_projections() {
    // Mip levels and boxes are aligned with each map's own grid, and their filters are not
    // the Gaussian of EWA, so they are compared with each other: a cube and a lat-long map
    // through the same cone agree to 5% (2% on average).
    let beta = 4f64.to_radians();
    let cube = analytic_env(ProjectionKind::Cube, 128);
    let ll = analytic_env(ProjectionKind::LatLong, 1024);
    for filter in [Filter::Trilinear, Filter::SummedArea] {
        let a = Sampler::new(&cube, filter);
        let b = Sampler::new(&ll, filter);
        let (mut worst, mut sum, mut n) = (0.0f64, 0.0, 0);
        for d in directions::fibonacci(64)
            .into_iter()
            .filter(|d| d.y.abs() < 0.8)
        {
            let (x, y) = (
                a.sample(d, &Footprint::Cone(beta)),
                b.sample(d, &Footprint::Cone(beta)),
            );
            for k in 0..3 {
                let e = ((x[k] - y[k]) / x[k]).abs() as f64;
                worst = worst.max(e);
                sum += e;
                n += 1;
            }
        }
        println!(
            "{filter:?}: cube vs lat-long, worst {worst:.3}, mean {:.4}",
            sum / n as f64
        );
        assert!(
            worst < 0.05 && sum / (n as f64) < 0.02,
            "{filter:?}: {worst} {}",
            sum / n as f64
        );
    }
}

#[test]
fn differentials_match_the_cone() {
    let env = analytic_env(ProjectionKind::LatLong, 512);
    let s = Sampler::new(&env, Filter::Ewa);
    let d = DVec3::new(0.3, 0.2, -0.9).normalize();
    let beta = 0.05;
    let t1 = DVec3::new(d.z, 0.0, -d.x).normalize();
    let t2 = d.cross(t1);
    let a = s.sample(d, &Footprint::Cone(beta));
    let b = s.sample(
        d,
        &Footprint::Differentials {
            dx: t1 * beta + d * 0.3, // the radial part is ignored
            dy: t2 * beta,
        },
    );
    for k in 0..3 {
        assert!((a[k] - b[k]).abs() < 1e-5 * a[k].abs());
    }
    // An anisotropic footprint is an ellipse with the expected axes (lat-long at the
    // equator: u spans 2π, v spans π, so 1 rad is 1/(2π) in u and 1/π in v).
    let e = footprint_ellipse(
        env.projection(),
        DVec3::NEG_Z,
        &Footprint::Differentials {
            dx: DVec3::X * 0.1,
            dy: DVec3::Y * 0.02,
        },
    )
    .unwrap();
    let (major, minor) = semi_axes(e.a, e.b);
    assert!(
        (major - 0.1 / std::f64::consts::TAU).abs() < 1e-6,
        "{major}"
    );
    assert!(
        (minor - 0.02 / std::f64::consts::PI).abs() < 1e-6,
        "{minor}"
    );
}

#[test]
fn summed_area_table_sums_exactly() {
    let env = analytic_env(ProjectionKind::Cube, 16);
    let sat = SummedAreaTable::new(&env);
    let p = env.projection();
    let (x0, y0, x1, y1) = (3, 2, 11, 9);
    let (mut acc, mut ws) = ([0.0f64; 3], 0.0);
    for y in y0..y1 {
        for x in x0..x1 {
            let o = p.texel_solid_angle(2, x, y, 16, 16);
            let t = env.layers()[2].get(x, y);
            for k in 0..3 {
                acc[k] += t[k] as f64 * o;
            }
            ws += o;
        }
    }
    let m = sat
        .box_mean(2, x0 as i64, y0 as i64, x1 as i64, y1 as i64)
        .unwrap();
    for k in 0..3 {
        assert!((m[k] - acc[k] / ws).abs() < 1e-9);
    }
    // A box reaching over an edge takes texels from the neighbouring face.
    let over = sat.box_mean(2, -3, 4, 2, 8).unwrap();
    let inner = sat.box_mean(2, 0, 4, 2, 8).unwrap();
    assert_ne!(over, inner);
}

#[test]
fn nearest_and_bilinear() {
    let env: EnvMap = analytic_env(ProjectionKind::LatLong, 64);
    let n = Sampler::new(&env, Filter::Nearest);
    let b = Sampler::new(&env, Filter::Bilinear);
    let d = DVec3::new(0.2, 0.1, -0.97).normalize();
    let (layer, uv) = env.projection().dir_to_uv(d).unwrap();
    let x = (uv.x * 64.0) as u32;
    let y = (uv.y * 32.0) as u32;
    let t = env.layers()[layer].get(x, y);
    let got = n.sample(d, &Footprint::Cone(0.3));
    assert_eq!(&got[..3], &t[..3]);
    assert_eq!(b.sample(d, &Footprint::Point), env.sample(d));
}

#[test]
fn ewa_magnifies_smoothly() {
    // Lat-long maps of 45° and 5.6° texels read along dense lines of directions with
    // footprints far smaller than a texel: EWA must interpolate as smoothly as bilinear (no
    // step between neighbouring directions much larger than bilinear's largest) and stay
    // close to it, rather than hold texels as blocks. "Close": the two kernels differ at
    // most where a lookup sits a quarter texel from a centre on both axes (bilinear weights
    // 9/16, 3/16, 3/16, 1/16; the Gaussian of one texel's radius, 0.712, 0.144, 0.144, 0),
    // by 0.15 of the texels' range; on 45° texels the sphere's curvature across a texel
    // (the Gaussian is measured on the sphere) adds a little.
    let proj = ProjectionKind::LatLong.default_projection();
    for (w, h, close) in [(8u32, 4u32, 0.2f32), (64, 32, 0.15)] {
        let mut img = mirrorball_core::Image::new(w, h, 3);
        for y in 0..h {
            for x in 0..w {
                let v = ((x * 7 + y * 3) % 5) as f32 / 4.0;
                img.set(x, y, &[v, 1.0 - v, 0.5 * v]);
            }
        }
        let env = EnvMap::new(proj, vec![img]).unwrap();
        let ewa = Sampler::new(&env, Filter::Ewa);
        let n = 8000;
        let lines: [Box<dyn Fn(f64) -> DVec3>; 2] = [
            // Along a parallel.
            Box::new(|t: f64| {
                let (lon, lat) = (t * std::f64::consts::TAU, 0.3f64);
                DVec3::new(lon.sin() * lat.cos(), lat.sin(), -lon.cos() * lat.cos())
            }),
            // Across rows and columns at once.
            Box::new(|t: f64| {
                let lon = t * std::f64::consts::TAU;
                let lat = 0.9 * (3.0 * lon).sin();
                DVec3::new(lon.sin() * lat.cos(), lat.sin(), -lon.cos() * lat.cos())
            }),
        ];
        for (li, line) in lines.iter().enumerate() {
            let (mut step_b, mut step_e, mut diff) = (0.0f32, 0.0f32, 0.0f32);
            let mut prev: Option<([f32; 4], [f32; 4])> = None;
            for i in 0..=n {
                let d = line(i as f64 / n as f64);
                let b = env.sample(d);
                let e = ewa.sample(d, &Footprint::Cone(1e-5));
                for k in 0..3 {
                    diff = diff.max((e[k] - b[k]).abs());
                }
                if let Some((pb, pe)) = prev {
                    for k in 0..3 {
                        step_b = step_b.max((b[k] - pb[k]).abs());
                        step_e = step_e.max((e[k] - pe[k]).abs());
                    }
                }
                prev = Some((b, e));
            }
            assert!(
                step_b > 0.0 && step_b < 0.1,
                "{w}×{h} line {li}: bilinear step {step_b}"
            );
            assert!(
                step_e < 2.0 * step_b,
                "{w}×{h} line {li}: EWA steps by {step_e}, bilinear by at most {step_b}"
            );
            // Values span [0, 1].
            assert!(
                diff < close,
                "{w}×{h} line {li}: EWA is {diff} from bilinear"
            );
        }
    }
}
