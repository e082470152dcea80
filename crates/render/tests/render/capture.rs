//! Scenes captured into world projections; dynamic reflection.

use crate::util::*;
use glam::{DVec2, Mat4, Vec3};
use mirrorball_core::{resample, CubeMap, ProjectionKind, ResampleOptions, WorldProjection};
use mirrorball_render::capture_cube;
use mirrorball_render::{mesh, Attach, Camera, Environment, Indexing, Material, Object, Settings};
use std::sync::Arc;

#[test]
fn capturing_an_empty_scene_gives_back_its_environment() {
    let ll = env_of(ProjectionKind::LatLong, 512, smooth);
    let scene = mirrorball_render::Scene {
        objects: vec![],
        environment: Some(Environment::new(ll.clone())),
        background: true,
    };
    let cube = capture_cube(
        &scene,
        Vec3::new(5.0, -2.0, 1.0),
        16,
        None,
        &Settings::default(),
    )
    .unwrap();
    let mut worst = 0.0f32;
    for l in 0..6 {
        for y in 0..16 {
            for x in 0..16 {
                let uv = DVec2::new((x as f64 + 0.5) / 16.0, (y as f64 + 0.5) / 16.0);
                let d = CubeMap.uv_to_dir(l, uv).unwrap();
                let want = ll.sample(d);
                let got = cube.layers()[l].get(x, y);
                worst = worst.max(max_diff(
                    [got[0], got[1], got[2]],
                    [want[0], want[1], want[2]],
                ));
            }
        }
    }
    assert!(worst < 2e-3, "{worst}");
    // And into any other projection.
    let oct = resample(
        &cube,
        ProjectionKind::Octahedral.default_projection(),
        32,
        &ResampleOptions::default(),
    );
    let d = glam::DVec3::new(0.3, 0.5, -0.8).normalize();
    assert!(
        max_diff(
            [oct.sample(d)[0], oct.sample(d)[1], oct.sample(d)[2]],
            [ll.sample(d)[0], ll.sample(d)[1], ll.sample(d)[2]]
        ) < 0.02
    );
}

#[test]
fn dynamic_reflection_shows_the_neighbour_but_not_itself() {
    // A mirror ball at the origin and a red box at +X. Captured at the ball's centre
    // without the ball, the +X face is red; the ball rendered in the capture shows red on
    // its right and the sky elsewhere.
    let sky = env_of(ProjectionKind::LatLong, 128, |_| [0.2, 0.4, 0.9]);
    let ball = Object {
        mesh: Arc::new(mesh::sphere(48)),
        model: Mat4::IDENTITY,
        material: Material::mirror(),
    };
    let boxed = Object {
        mesh: Arc::new(mesh::cube(1)),
        model: Mat4::from_translation(Vec3::new(4.0, 0.0, 0.0))
            * Mat4::from_scale(Vec3::splat(1.5)),
        material: Material::Diffuse {
            colour: [0.9, 0.05, 0.05],
            light: [0.0, 0.0, 0.0],
            ambient: 1.0,
        },
    };
    let scene = mirrorball_render::Scene {
        objects: vec![ball, boxed],
        environment: Some(Environment::new(sky)),
        background: true,
    };
    let cube = capture_cube(&scene, Vec3::ZERO, 32, Some(0), &Settings::default()).unwrap();
    let px = cube.layers()[0].get(16, 16); // +X face centre
    assert!(px[0] > 0.8 && px[2] < 0.1, "{px:?}");
    let nx = cube.layers()[1].get(16, 16);
    assert!(nx[2] > 0.8, "{nx:?}");
    // Render the ball alone in its capture.
    let mut lit = scene.clone();
    lit.objects.truncate(1);
    lit.environment = Some(Environment {
        attach: Attach::World,
        ..Environment::new(cube)
    });
    let cam = Camera::perspective(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 30.0, 64, 64);
    let f = draw(&lit, &cam, Indexing::PerPixel, 1, false);
    // Near the right limb the reflected ray turns by about 95° towards +X (the red box);
    // the centre reflects +Z, behind the camera (sky).
    let right = f.color.get(56, 32);
    let centre = f.color.get(32, 32);
    assert!(right[0] > 0.5 && right[2] < 0.3, "{right:?}");
    assert!(centre[2] > 0.8 && centre[0] < 0.3, "{centre:?}");
}

#[test]
fn omnimax_fisheye_looks_at_the_target_and_keeps_the_world() {
    use mirrorball_core::{Fisheye, Frame, Lens, Projection};
    use mirrorball_render::render_fisheye;
    let ll = env_of(ProjectionKind::LatLong, 256, smooth);
    let red = Object {
        mesh: Arc::new(mesh::cube(1)),
        model: Mat4::from_translation(Vec3::new(0.0, 0.0, -6.0)),
        material: Material::Diffuse {
            colour: [1.0, 0.0, 0.0],
            light: [0.0, 1.0, 0.0],
            ambient: 1.0,
        },
    };
    let scene = mirrorball_render::Scene {
        objects: vec![red],
        environment: Some(Environment::new(ll.clone())),
        background: true,
    };
    let img = render_fisheye(
        &scene,
        Vec3::ZERO,
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::Y,
        Lens::Equidistant,
        180.0,
        64,
        32,
        &Settings::default(),
    )
    .unwrap();
    let c = img.get(32, 32);
    assert!(
        c[0] > 0.9 && c[1] < 0.05,
        "the centre sees the red box: {c:?}"
    );
    assert_eq!(&img.get(0, 0)[..3], &[0.0, 0.0, 0.0], "outside the circle");
    // Away from the box, the fisheye shows the environment where the lens says.
    let fish = Fisheye::new(Frame::default(), Lens::Equidistant, 180.0).unwrap();
    let p = Projection::Fisheye(fish);
    for (x, y) in [(8, 32), (32, 6), (50, 50), (20, 44)] {
        let uv = glam::DVec2::new((x as f64 + 0.5) / 64.0, (y as f64 + 0.5) / 64.0);
        let d = p.uv_to_dir(0, uv).unwrap();
        let want = ll.sample(d);
        let got = img.get(x, y);
        assert!(
            max_diff([got[0], got[1], got[2]], [want[0], want[1], want[2]]) < 0.03,
            "{x},{y}: {got:?} vs {want:?}"
        );
    }
}

#[test]
fn camera_rotation_blurs_the_background_along_the_swept_path() {
    // Stripes in longitude; the camera pans 20° between frames. Each background pixel must
    // be the environment averaged along the arc its ray swept (Greene §9).
    let ll = env_of(ProjectionKind::LatLong, 1024, |d| {
        let lon = d.x.atan2(-d.z);
        let v = (0.5 + 0.5 * (40.0 * lon).sin()) as f32;
        [v, v, v]
    });
    let scene = mirrorball_render::Scene {
        objects: vec![],
        environment: Some(Environment::new(ll.clone())),
        background: true,
    };
    let cam = Camera::perspective(
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -1.0),
        60.0,
        32,
        32,
    );
    let prev = cam.panned(20f32.to_radians());
    let sharp = draw(&scene, &cam, Indexing::PerPixel, 1, false);
    let blur = mirrorball_render::render(
        &scene,
        &cam,
        &Settings {
            motion_from: Some(prev),
            ..Settings::default()
        },
    )
    .unwrap();
    let still = mirrorball_render::render(
        &scene,
        &cam,
        &Settings {
            motion_from: Some(cam),
            ..Settings::default()
        },
    )
    .unwrap();
    assert_eq!(still.color.data(), sharp.color.data(), "no motion, no blur");
    // Reference: 2000 samples along each swept arc, at a few pixels.
    for (x, y) in [(16, 16), (3, 20), (28, 5)] {
        let ndc = |v: u32, n: u32| 2.0 * (v as f32 + 0.5) / n as f32 - 1.0;
        let (xn, yn) = (ndc(x, 32), -ndc(y, 32));
        let d1 = cam.ray_ndc(xn, yn).1.as_dvec3();
        let d0 = prev.ray_ndc(xn, yn).1.as_dvec3();
        let a = d0.angle_between(d1);
        let mut acc = 0.0f64;
        for k in 0..2000 {
            let t = (k as f64 + 0.5) / 2000.0;
            let d = (d0 * ((1.0 - t) * a).sin() + d1 * (t * a).sin()) / a.sin();
            acc += ll.sample(d.normalize())[0] as f64;
        }
        let want = (acc / 2000.0) as f32;
        let got = blur.color.get(x, y)[0];
        assert!((got - want).abs() < 0.03, "{x},{y}: {got} vs {want}");
    }
    // And the stripes are gone: the row varies far less.
    let spread = |img: &mirrorball_core::Image| {
        let row: Vec<f32> = (0..32).map(|x| img.get(x, 16)[0]).collect();
        row.iter().cloned().fold(f32::MIN, f32::max) - row.iter().cloned().fold(f32::MAX, f32::min)
    };
    assert!(spread(&blur.color) < 0.3 * spread(&sharp.color));
}
