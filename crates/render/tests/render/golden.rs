//! Small golden images, one per indexing mode and projection, named after what they show.
//! Each is rendered at 48×48 in an analytic environment and compared with the PNG under
//! `tests/golden/`; `MIRRORBALL_BLESS=1 cargo test -p mirrorball-render` rewrites them.

use crate::util::*;
use glam::{Mat4, Vec3};
use mirrorball_core::{Image, ProjectionKind};
use mirrorball_render::{mesh, tone, Attach, Builtin, Camera, Indexing, Material, Ramp, Scene};
use std::path::PathBuf;

const N: u32 = 48;

fn golden_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

fn check(name: &str, scene: &Scene, cam: &Camera, mode: Indexing) {
    let f = draw(scene, cam, mode, 2, false);
    let img = tone::to_display(&f.color, 0.0, tone::Tone::Clamp).with_channels(3);
    let path = golden_dir().join(format!("{name}.png"));
    if std::env::var_os("MIRRORBALL_BLESS").is_some() {
        std::fs::create_dir_all(golden_dir()).unwrap();
        mirrorball_io::write_image(&path, &img, &Default::default()).unwrap();
        return;
    }
    let want = mirrorball_io::read(&path, &Default::default())
        .unwrap_or_else(|e| panic!("{name}: {e} (bless with MIRRORBALL_BLESS=1)"))
        .layers
        .remove(0);
    assert_eq!((want.width(), want.height()), (img.width(), img.height()));
    let bad = differing(&img, &want.with_channels(3));
    // 8-bit quantisation is ~0.002 in linear light near black; allow a few pixels to move
    // at silhouettes from floating-point differences between platforms.
    assert!(
        bad <= 3,
        "{name}: {bad} pixels differ from the golden image"
    );
}

/// Pixels whose colour differs by more than 0.02 (linear) in any channel.
fn differing(a: &Image, b: &Image) -> usize {
    a.data()
        .chunks_exact(3)
        .zip(b.data().chunks_exact(3))
        .filter(|(p, q)| (0..3).any(|i| (p[i] - q[i]).abs() > 0.02))
        .count()
}

fn persp(eye: Vec3) -> Camera {
    Camera::perspective(eye, Vec3::ZERO, 40.0, N, N)
}

fn sphere_map_scene(m: mirrorball_render::Mesh, model: Mat4) -> Scene {
    scene_with(
        m,
        model,
        env_of(ProjectionKind::Sphere, 128, busy),
        Attach::Eye,
        false,
    )
}

#[test]
fn coarse_sphere_in_a_sphere_map_each_mode() {
    let cam = persp(Vec3::new(0.0, 0.0, 3.5));
    let s = sphere_map_scene(mesh::sphere(12), Mat4::IDENTITY);
    for mode in Indexing::ALL {
        check(
            &format!("sphere12_spheremap_{}", mode.name()),
            &s,
            &cam,
            mode,
        );
    }
}

#[test]
fn grazing_quad_in_a_sphere_map_bends_with_texgen() {
    // Zimmons' figure 21: the door at a grazing angle.
    let cam = Camera::perspective(Vec3::new(0.0, 0.0, 2.2), Vec3::ZERO, 60.0, N, N);
    let s = sphere_map_scene(mesh::quad(1), Mat4::from_rotation_y(70f32.to_radians()));
    for mode in [Indexing::PerVertexTexgen, Indexing::PerPixel] {
        check(
            &format!("grazing_quad_spheremap_{}", mode.name()),
            &s,
            &cam,
            mode,
        );
    }
}

#[test]
fn teapot_in_a_cube_map_each_mode() {
    let cam = persp(Vec3::new(1.5, 1.5, 3.0));
    let s = scene_with(
        Builtin::Teapot.mesh(4),
        Mat4::IDENTITY,
        env_of(ProjectionKind::Cube, 64, busy),
        Attach::World,
        true,
    );
    for mode in Indexing::ALL {
        check(&format!("teapot4_cube_{}", mode.name()), &s, &cam, mode);
    }
}

#[test]
fn other_projections() {
    let cam = persp(Vec3::new(0.5, 1.0, 3.5));
    for (kind, obj, mode) in [
        (
            ProjectionKind::LatLong,
            Builtin::Sphere,
            Indexing::PerVertexTexgen,
        ),
        (ProjectionKind::LatLong, Builtin::Sphere, Indexing::PerPixel),
        (
            ProjectionKind::Paraboloid,
            Builtin::Torus,
            Indexing::PerPixel,
        ),
        (ProjectionKind::Octahedral, Builtin::Cube, Indexing::Cone),
        (
            ProjectionKind::Angular,
            Builtin::Torus,
            Indexing::PerVertexReflection,
        ),
    ] {
        let s = scene_with(
            obj.mesh(16),
            Mat4::IDENTITY,
            env_of(kind, 64, busy),
            Attach::World,
            true,
        );
        check(
            &format!("{}16_{}_{}", obj.name(), kind.name(), mode.name()),
            &s,
            &cam,
            mode,
        );
    }
}

#[test]
fn materials() {
    let cam = persp(Vec3::new(0.0, 0.8, 3.5));
    let env = env_of(ProjectionKind::LatLong, 64, busy);
    let mut s = scene_with(mesh::sphere(32), Mat4::IDENTITY, env, Attach::World, true);
    s.objects[0].material = Material::Fresnel {
        f0: 0.04,
        base: [0.6, 0.1, 0.1],
    };
    check("sphere32_fresnel", &s, &cam, Indexing::PerPixel);
    s.objects[0].material = Material::CheapChrome {
        ramp: Ramp::chrome(),
    };
    s.objects[0].mesh = std::sync::Arc::new(Builtin::Teapot.mesh(4));
    check("teapot4_cheap_chrome", &s, &cam, Indexing::PerPixel);
}

#[test]
fn orthographic_mirror_ball_world_and_eye() {
    let cam = Camera::orthographic(Vec3::new(2.0, 1.0, 4.0), Vec3::ZERO, 1.1, N, N);
    for attach in [Attach::World, Attach::Eye] {
        let s = scene_with(
            mesh::sphere(48),
            Mat4::IDENTITY,
            env_of(ProjectionKind::LatLong, 128, busy),
            attach,
            true,
        );
        check(
            &format!("ortho_ball_latlong_{attach:?}").to_lowercase(),
            &s,
            &cam,
            Indexing::PerPixel,
        );
    }
}
