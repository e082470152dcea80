//! Analytic checks: orthographic mirror sphere = the sphere map; per-pixel = ray tracing;
//! per-vertex sphere mapping converges to per-pixel; GL texgen and perspective-correct
//! interpolation against independent computations.

use crate::util::*;
use glam::{DVec2, DVec3, Mat4, Vec2, Vec3};
use mirrorball_core::{ProjectionKind, SphereMap, WorldProjection};
use mirrorball_render::{mesh, sphere_map_texcoords, Attach, Camera, Indexing};

/// Pixel `(x, y)` of an `n×n` orthographic view of the unit sphere: the disk coordinates
/// `(a, b)` of its centre.
fn ab(x: u32, y: u32, n: u32) -> (f64, f64) {
    (
        2.0 * (x as f64 + 0.5) / n as f64 - 1.0,
        1.0 - 2.0 * (y as f64 + 0.5) / n as f64,
    )
}

#[test]
fn orthographic_mirror_sphere_reproduces_the_sphere_map() {
    // A mirror ball seen orthographically along −Z in a lat-long world *is* the world's
    // sphere map (that is how sphere maps were photographed): pixel (x, y) of the render
    // equals texel (x, y) of the sphere map inside the disk.
    let n = 64;
    let ll = env_of(ProjectionKind::LatLong, 512, busy);
    let sm = SphereMap::default();
    let scene = scene_with(
        mesh::sphere(256),
        Mat4::IDENTITY,
        ll.clone(),
        Attach::World,
        false,
    );
    let f = draw(&scene, &ortho_front(n), Indexing::PerPixel, 1, false);
    let mut worst = 0.0f32;
    let mut count = 0;
    for y in 0..n {
        for x in 0..n {
            let (a, b) = ab(x, y, n);
            if a * a + b * b > 0.85 {
                continue; // the polygonal silhouette and the rim's infinite magnification
            }
            let uv = DVec2::new((x as f64 + 0.5) / n as f64, (y as f64 + 0.5) / n as f64);
            let d = sm.uv_to_dir(0, uv).unwrap();
            let want = ll.sample(d);
            worst = worst.max(max_diff(px(&f.color, x, y), [want[0], want[1], want[2]]));
            count += 1;
        }
    }
    assert!(count > 2500);
    assert!(worst < 0.03, "worst difference {worst}");
}

/// Ray-traces a unit mirror sphere at the origin for the pixel centre `(x, y)`.
fn trace(cam: &Camera, x: u32, y: u32, f: impl Fn(DVec3) -> [f32; 4]) -> Option<([f32; 3], f64)> {
    let xn = 2.0 * (x as f32 + 0.5) / cam.width as f32 - 1.0;
    let yn = 1.0 - 2.0 * (y as f32 + 0.5) / cam.height as f32;
    let (o, d) = cam.ray_ndc(xn, yn);
    let (o, d) = (o.as_dvec3(), d.as_dvec3());
    let b = o.dot(d);
    let c = o.dot(o) - 1.0;
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    let t = -b - disc.sqrt();
    let p = o + d * t;
    let n = p.normalize();
    let r = d - 2.0 * n.dot(d) * n;
    let v = f(r);
    // How grazing: cos of the incidence angle.
    Some(([v[0], v[1], v[2]], -n.dot(d)))
}

#[test]
fn per_pixel_mirror_sphere_matches_ray_tracing() {
    let cam = Camera::perspective(Vec3::new(0.3, 0.4, 3.5), Vec3::ZERO, 40.0, 64, 64);
    let ll = env_of(ProjectionKind::LatLong, 512, busy);
    let cube = env_of(ProjectionKind::Cube, 128, busy);
    for env in [ll, cube] {
        let scene = scene_with(
            mesh::sphere(256),
            Mat4::IDENTITY,
            env.clone(),
            Attach::World,
            false,
        );
        let f = draw(&scene, &cam, Indexing::PerPixel, 1, false);
        let (mut worst, mut n) = (0.0f32, 0);
        for y in 0..64 {
            for x in 0..64 {
                let Some((want, cos)) = trace(&cam, x, y, |r| env.sample(r)) else {
                    continue;
                };
                if cos < 0.3 {
                    continue; // near the silhouette the polygonal mesh differs
                }
                worst = worst.max(max_diff(px(&f.color, x, y), want));
                n += 1;
            }
        }
        assert!(n > 500, "{n} pixels compared");
        assert!(worst < 0.03, "{}: worst {worst}", env.projection().name());
    }
}

/// Mean absolute difference of two frames' colours over pixels both cover.
fn mean_diff(a: &mirrorball_core::Image, b: &mirrorball_core::Image) -> f64 {
    let (mut s, mut n) = (0.0f64, 0usize);
    for (p, q) in a.data().chunks_exact(4).zip(b.data().chunks_exact(4)) {
        if p[3] > 0.999 && q[3] > 0.999 {
            s += (0..3).map(|i| (p[i] - q[i]).abs() as f64).sum::<f64>() / 3.0;
            n += 1;
        }
    }
    s / n.max(1) as f64
}

#[test]
fn per_vertex_sphere_mapping_converges_to_per_pixel() {
    // GL_SPHERE_MAP texgen (eye-attached, as the fixed-function pipeline has it) on ever
    // finer spheres approaches the per-pixel reflection.
    let cam = Camera::perspective(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 35.0, 64, 64);
    let sm = env_of(ProjectionKind::Sphere, 256, busy);
    let mut errs = Vec::new();
    for seg in [8, 16, 32, 64, 128] {
        let scene = scene_with(
            mesh::sphere(seg),
            Mat4::IDENTITY,
            sm.clone(),
            Attach::Eye,
            false,
        );
        let reference = scene_with(
            mesh::sphere(256),
            Mat4::IDENTITY,
            sm.clone(),
            Attach::Eye,
            false,
        );
        let a = draw(&scene, &cam, Indexing::PerVertexTexgen, 1, false);
        let b = draw(&reference, &cam, Indexing::PerPixel, 1, false);
        errs.push(mean_diff(&a.color, &b.color));
    }
    for w in errs.windows(2) {
        assert!(w[1] < w[0], "not decreasing: {errs:?}");
    }
    assert!(errs[0] > 4.0 * errs[4], "{errs:?}");
    assert!(errs[4] < 0.01, "{errs:?}");
}

#[test]
fn texgen_coordinates_are_the_gl_formula_interpolated_perspective_correctly() {
    // A quad seen in perspective at an angle: the s, t the renderer used at each pixel must
    // equal GL_SPHERE_MAP at the vertices (SphereMap::gl_st, the spec's formula) interpolated
    // linearly *in the triangle's plane* — found here independently by intersecting the
    // pixel's ray with the plane.
    let n = 48;
    let cam = Camera::perspective(Vec3::new(0.4, 0.3, 2.5), Vec3::ZERO, 50.0, n, n);
    let model = Mat4::from_rotation_y(0.9) * Mat4::from_rotation_x(-0.3);
    let quad = mesh::quad(1);
    let sm = env_of(ProjectionKind::Sphere, 64, smooth);
    let scene = scene_with(quad.clone(), model, sm, Attach::Eye, false);
    let f = draw(&scene, &cam, Indexing::PerVertexTexgen, 1, true);
    let st_img = &f.aovs.as_ref().unwrap().st_face;
    let st = sphere_map_texcoords(&quad, model, &cam);
    let world: Vec<Vec3> = quad
        .positions
        .iter()
        .map(|&p| model.transform_point3(p))
        .collect();
    let mut checked = 0;
    for y in 0..n {
        for x in 0..n {
            if f.color.get(x, y)[3] < 1.0 {
                continue;
            }
            let xn = 2.0 * (x as f32 + 0.5) / n as f32 - 1.0;
            let yn = 1.0 - 2.0 * (y as f32 + 0.5) / n as f32;
            let (o, d) = cam.ray_ndc(xn, yn);
            let mut found = None;
            for t in &quad.triangles {
                let [a, b, c] = t.map(|i| world[i as usize]);
                let nn = (b - a).cross(c - a);
                let tt = nn.dot(a - o) / nn.dot(d);
                let p = o + d * tt;
                let w = [
                    (c - b).cross(p - b).dot(nn),
                    (a - c).cross(p - c).dot(nn),
                    (b - a).cross(p - a).dot(nn),
                ];
                let s = nn.length_squared();
                let w = w.map(|v| v / s);
                if w.iter().all(|&v| v >= -1e-4) {
                    let v: Vec2 = st[t[0] as usize] * w[0]
                        + st[t[1] as usize] * w[1]
                        + st[t[2] as usize] * w[2];
                    found = Some(v);
                    break;
                }
            }
            let want = found.expect("the pixel's ray hits the quad");
            let got = st_img.get(x, y);
            // The AOV holds (s, 1 − t).
            assert!(
                (got[0] - want.x).abs() < 2e-4 && (got[1] - (1.0 - want.y)).abs() < 2e-4,
                "pixel {x},{y}: got {:?}, want {want:?}",
                &got[..2]
            );
            checked += 1;
        }
    }
    assert!(checked > 200, "{checked}");
}

#[test]
fn texgen_matches_the_core_sphere_projection_at_vertices() {
    // The per-vertex s, t of mode 1 agree with the core's SphereMap projection of the
    // eye-space reflection vector (two independent codings of one formula).
    let cam = Camera::perspective(Vec3::new(0.0, 1.0, 3.0), Vec3::ZERO, 45.0, 8, 8);
    let m = mesh::sphere(12);
    let st = sphere_map_texcoords(&m, Mat4::IDENTITY, &cam);
    let view = cam.view();
    for (i, (&p, &nrm)) in m.positions.iter().zip(&m.normals).enumerate() {
        let u = view.transform_point3(p).normalize().as_dvec3();
        let ne = view.transform_vector3(nrm).normalize().as_dvec3();
        let r = u - 2.0 * ne.dot(u) * ne;
        if r.z < -0.99 {
            continue; // the rim: one direction, every (s, t) on the circle
        }
        let (_, uv) = SphereMap::default().dir_to_uv(r.normalize()).unwrap();
        assert!(
            (uv.x - st[i].x as f64).abs() < 1e-5,
            "vertex {i}: {uv} {} r {r}",
            st[i]
        );
        assert!(
            (1.0 - uv.y - st[i].y as f64).abs() < 1e-5,
            "vertex {i}: {uv} {} r {r}",
            st[i]
        );
    }
}

#[test]
fn eye_attached_map_shows_the_same_picture_from_every_side() {
    // Zimmons' figure 18: a view-dependent (eye-attached) map looks the same from anywhere
    // when the ball is centred; a world-attached one shows a different part of the world.
    let ll = env_of(ProjectionKind::LatLong, 256, busy);
    let cam_a = Camera::perspective(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 35.0, 32, 32);
    let cam_b = cam_a.orbited(1.2);
    let eye = scene_with(
        mesh::sphere(64),
        Mat4::IDENTITY,
        ll.clone(),
        Attach::Eye,
        false,
    );
    let world = scene_with(mesh::sphere(64), Mat4::IDENTITY, ll, Attach::World, false);
    let e1 = draw(&eye, &cam_a, Indexing::PerPixel, 1, false);
    let e2 = draw(&eye, &cam_b, Indexing::PerPixel, 1, false);
    let w1 = draw(&world, &cam_a, Indexing::PerPixel, 1, false);
    let w2 = draw(&world, &cam_b, Indexing::PerPixel, 1, false);
    let (de, dw, d0) = (
        mean_diff(&e1.color, &e2.color),
        mean_diff(&w1.color, &w2.color),
        mean_diff(&w1.color, &e1.color),
    );
    assert!(de < 2e-3, "{de}");
    assert!(dw > 0.05, "{dw}");
    assert!(d0 < 1e-6, "they agree at the default view: {d0}");
}

#[test]
fn modes_agree_where_they_should() {
    // Cube map, perspective: GL_REFLECTION_MAP texgen (mode 1) is the per-vertex reflection
    // vector (mode 2) exactly; both approach per-pixel on a fine sphere.
    let cam = Camera::perspective(Vec3::new(0.5, 0.5, 3.5), Vec3::ZERO, 40.0, 48, 48);
    let cube = env_of(ProjectionKind::Cube, 64, busy);
    let s = scene_with(
        mesh::sphere(128),
        Mat4::IDENTITY,
        cube,
        Attach::World,
        false,
    );
    let m1 = draw(&s, &cam, Indexing::PerVertexTexgen, 1, false);
    let m2 = draw(&s, &cam, Indexing::PerVertexReflection, 1, false);
    let m3 = draw(&s, &cam, Indexing::PerPixel, 1, false);
    assert!(mean_diff(&m1.color, &m2.color) < 1e-5);
    assert!(mean_diff(&m2.color, &m3.color) < 0.01);
}

#[test]
fn cone_filtering_removes_aliasing_on_a_curved_surface() {
    // A small, far sphere in a busy map: each pixel's reflected rays fan out widely. Point
    // sampling (mode 3, one sample) aliases; Greene's cones (mode 4) approach the heavily
    // supersampled reference.
    let cam = Camera::perspective(Vec3::new(0.0, 0.0, 12.0), Vec3::ZERO, 12.0, 24, 24);
    let ll = env_of(ProjectionKind::LatLong, 1024, |d| {
        let lon = d.x.atan2(-d.z);
        let lat = d.y.asin();
        let v = if ((lon * 12.0).sin() * (lat * 12.0).sin()) > 0.0 {
            1.0
        } else {
            0.0
        };
        [v, v, v]
    });
    let s = scene_with(mesh::sphere(128), Mat4::IDENTITY, ll, Attach::World, false);
    let reference = draw(&s, &cam, Indexing::PerPixel, 12, false);
    let point = draw(&s, &cam, Indexing::PerPixel, 1, false);
    let cone = draw(&s, &cam, Indexing::Cone, 1, false);
    let e_point = mean_diff(&point.color, &reference.color);
    let e_cone = mean_diff(&cone.color, &reference.color);
    assert!(e_cone < 0.5 * e_point, "cone {e_cone}, point {e_point}");
}

#[test]
fn cheap_chrome_depends_only_on_elevation() {
    let cam = ortho_front(32);
    let mut s = scene_with(
        mesh::sphere(64),
        Mat4::IDENTITY,
        env_of(ProjectionKind::LatLong, 64, smooth),
        Attach::World,
        false,
    );
    s.objects[0].material = mirrorball_render::Material::CheapChrome {
        ramp: mirrorball_render::Ramp(vec![[0.0; 3], [1.0; 3]]),
    };
    let f = draw(&s, &cam, Indexing::PerPixel, 1, true);
    let r = &f.aovs.as_ref().unwrap().reflected;
    for y in 0..32 {
        for x in 0..32 {
            if f.color.get(x, y)[3] == 1.0 {
                let want = (r.get(x, y)[1] + 1.0) * 0.5;
                assert!((f.color.get(x, y)[0] - want).abs() < 1e-5);
            }
        }
    }
}

#[test]
fn phong_sphere_map_puts_the_highlight_where_the_mirror_direction_meets_the_light() {
    // Orthographic mirror sphere, light up and to the right in eye space: the brightest
    // pixel is where n is halfway between the view direction (+Z) and L.
    let l = glam::DVec3::new(0.5, 0.6, 0.62).normalize();
    let map = mirrorball_render::phong_sphere_map(l, 60.0, [1.0; 3], 256);
    let scene = scene_with(mesh::sphere(128), Mat4::IDENTITY, map, Attach::Eye, false);
    let n = 96;
    let f = draw(&scene, &ortho_front(n), Indexing::PerPixel, 1, false);
    let (mut best, mut at) = (0.0f32, (0, 0));
    for y in 0..n {
        for x in 0..n {
            let v = f.color.get(x, y)[0];
            if v > best {
                best = v;
                at = (x, y);
            }
        }
    }
    let h = (l + glam::DVec3::Z).normalize();
    let (a, b) = ab(at.0, at.1, n);
    assert!(best > 0.95, "{best}");
    assert!(
        (a - h.x).abs() < 0.04 && (b - h.y).abs() < 0.04,
        "peak at {a},{b}, want {h}"
    );
}
