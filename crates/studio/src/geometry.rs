//! An object's mesh for the page, in world space as the CPU renderer flattens it
//! (`mirrorball-render`'s `render/prepare.rs`, `flatten`: positions through the model
//! matrix, normals through its inverse transpose, normalised, +Y where that fails), so
//! that the GPU starts from the CPU's own vertex data.
//!
//! The payload, little-endian: `u32` vertex count `n`, `u32` triangle count `t`, then
//! `3n` `f32` positions, `3n` `f32` normals, `3t` `u32` indices.

use mirrorball_core::glam::{Mat3, Vec3};
use mirrorball_render::Object;

/// `o`'s mesh in world space, as the payload above.
pub fn encode(o: &Object) -> Vec<u8> {
    let m = &o.mesh;
    let nm = Mat3::from_mat4(o.model).inverse().transpose();
    let mut out = Vec::with_capacity(8 + m.positions.len() * 24 + m.triangles.len() * 12);
    out.extend_from_slice(&(m.positions.len() as u32).to_le_bytes());
    out.extend_from_slice(&(m.triangles.len() as u32).to_le_bytes());
    for q in &m.positions {
        for c in o.model.transform_point3(*q).to_array() {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    for n in &m.normals {
        for c in (nm * *n).try_normalize().unwrap_or(Vec3::Y).to_array() {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    for t in &m.triangles {
        for i in t {
            out.extend_from_slice(&i.to_le_bytes());
        }
    }
    out
}
