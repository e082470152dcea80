use glam::{Mat4, Vec3};
use mirrorball_core::{EnvMap, Image};
use mirrorball_render::{
    render, Attach, Camera, Environment, Indexing, Material, Mesh, Object, Rendered, Scene,
    Settings,
};
use std::sync::Arc;

#[path = "../../src/test_envs.rs"]
mod test_envs;
pub use test_envs::*;

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

pub fn draw(scene: &Scene, cam: &Camera, mode: Indexing, ss: u32, aovs: bool) -> Rendered {
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
