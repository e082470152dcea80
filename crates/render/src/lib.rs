//! # mirrorball-render
//!
//! A CPU renderer (rayon, no GPU) of environment-mapped objects, showing each way
//! environment mapping was done as it truly behaved: fixed-function per-vertex texture
//! generation with its chords and bow ties, per-vertex reflection vectors, per-pixel
//! reflection, and Greene's filtered reflection cones.
//!
//! The pipeline: [`Scene`] (meshes with model matrices and [`Material`]s, an
//! [`Environment`] in any world projection of `mirrorball-core`, attached to the world or
//! the eye) → [`render()`] with a [`Camera`] and [`Settings`] (indexing mode, `n×n`
//! supersampling, diagnostic channels) → [`Rendered`] of linear RGBA plus [`Aovs`] →
//! [`tone::to_display`] for PNGs.
//!
//! ```
//! use mirrorball_core::{EnvMap, ProjectionKind};
//! use mirrorball_render::{mesh, render, Camera, Environment, Indexing, Material, Object, Scene, Settings};
//! use glam::{Mat4, Vec3};
//! use std::sync::Arc;
//! let env = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 64, 3, |d| {
//!     [d.y as f32 * 0.5 + 0.5, 0.5, 0.5, 1.0]
//! });
//! let scene = Scene {
//!     objects: vec![Object { mesh: Arc::new(mesh::sphere(32)), model: Mat4::IDENTITY, material: Material::mirror() }],
//!     environment: Some(Environment::new(env)),
//!     background: true,
//! };
//! let cam = Camera::perspective(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 40.0, 32, 32);
//! let frame = render(&scene, &cam, &Settings { indexing: Indexing::PerPixel, ..Settings::default() }).unwrap();
//! assert_eq!(frame.color.width(), 32);
//! ```
#![warn(missing_docs)]

mod camera;
mod capture;
mod cpu;
mod fast;
mod load;
mod lookup;
mod maps;
pub mod mesh;
mod mirror;
mod raster;
mod render;
mod scene;
mod shading;
mod teapot;
#[cfg(test)]
mod test_envs;
pub mod tone;

pub use camera::{Camera, CameraLens, Rays};
pub use capture::{capture_cube, render_fisheye};
pub use cpu::set_portable;
pub use load::{load_mesh, load_mesh_bytes, MeshError, MAX_EXTENT};
pub use lookup::{EnvCache, SpecularLobe};
pub use maps::phong_sphere_map;
pub use mesh::{Builtin, Mesh};
pub use render::{
    render, render_into, render_with_progress, sphere_map_texcoords, texture_space_diagram, Aovs,
    RenderError, Rendered,
};
pub use scene::{
    environment_filter, Attach, Environment, Filter, Indexing, Material, MaterialKind, Object,
    Ramp, Scene, Settings, ENVIRONMENT_FILTERS,
};
