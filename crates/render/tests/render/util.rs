use glam::{DVec3, Mat4, Vec3};
use mirrorball_core::{EnvMap, Image, Projection, ProjectionKind};
use mirrorball_render::{
    render, Attach, Camera, Environment, Frame, Indexing, Material, Mesh, Object, Scene, Settings,
};
use std::sync::Arc;

/// A smooth analytic environment: colour = ½ + ½·d (so every axis flip shows).
pub fn smooth(d: DVec3) -> [f32; 3] {
    [
        (0.5 + 0.5 * d.x) as f32,
        (0.5 + 0.5 * d.y) as f32,
        (0.5 + 0.5 * d.z) as f32,
    ]
}

/// A busier analytic environment (bands in longitude and latitude) for visible artifacts.
pub fn busy(d: DVec3) -> [f32; 3] {
    let lon = d.x.atan2(-d.z);
    let lat = d.y.asin();
    let a = (0.5 + 0.5 * (6.0 * lon).sin()) as f32;
    let b = (0.5 + 0.5 * (8.0 * lat).cos()) as f32;
    [a, b, 0.5 * (d.y as f32 + 1.0)]
}

pub fn env_of(kind: ProjectionKind, size: u32, f: fn(DVec3) -> [f32; 3]) -> EnvMap {
    env_in(kind.default_projection(), size, f)
}

pub fn env_in(p: Projection, size: u32, f: fn(DVec3) -> [f32; 3]) -> EnvMap {
    EnvMap::from_fn(p, size, 3, move |d| {
        let c = f(d);
        [c[0], c[1], c[2], 1.0]
    })
}

pub fn scene_with(mesh: Mesh, model: Mat4, env: EnvMap, attach: Attach, background: bool) -> Scene {
    Scene {
        objects: vec![Object {
            mesh: Arc::new(mesh),
            model,
            material: Material::mirror(),
        }],
        environment: Some(Environment {
            attach,
            ..Environment::new(env)
        }),
        background,
    }
}

pub fn draw(scene: &Scene, cam: &Camera, mode: Indexing, ss: u32, aovs: bool) -> Frame {
    render(
        scene,
        cam,
        &Settings {
            indexing: mode,
            supersample: ss,
            aovs,
            motion_from: None,
            cull_hidden_faces: true,
        },
    )
    .expect("renders")
}

pub fn ortho_front(size: u32) -> Camera {
    Camera::orthographic(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, 1.0, size, size)
}

pub fn px(img: &Image, x: u32, y: u32) -> [f32; 3] {
    let p = img.get(x, y);
    [p[0], p[1], p[2]]
}

pub fn max_diff(a: [f32; 3], b: [f32; 3]) -> f32 {
    (0..3).map(|i| (a[i] - b[i]).abs()).fold(0.0, f32::max)
}
