//! A dense grid of directions with the core's texture coordinates for them: what the
//! browser test compares each projection's shader (`web/glsl/NAME.glsl`) against.
//!
//! The directions are the core's `uv_to_dir` of a grid of `(n + 1)²` texture coordinates in
//! every layer, edges included (`u`, `v` = 0 and 1: the lat-long seam and poles, the cube's
//! edges and corners, the disks' rims), and of points on and just inside each disk's rim.
//! Each is sent as the `f32` the shader reads, with the core's `dir_to_uv` of that `f32`
//! direction and, where a seam makes two answers right, the texture coordinates it was made
//! from.
//!
//! The payload, little-endian: `u32` count, the map's frame (nine `f32`, column-major, as
//! the page's `uFrame`; zeros for maps without one), its `uParams` (four `f32`,
//! `state::params_of`), then per direction nine `f32`: the direction,
//! the core's `(u, v, layer)` (layer −1 where the map does not cover it), and the
//! generating `(u, v, layer)`.

use mirrorball_core::glam::DVec2;
use mirrorball_core::{Projection, WorldProjection};

/// The most grid lines a side.
pub const MAX_N: u32 = 512;

/// The grid for `p` with `n` cells a side.
pub fn encode(p: &Projection, n: u32) -> Vec<u8> {
    let mut points: Vec<(usize, DVec2)> = Vec::new();
    for layer in 0..p.layer_count() {
        for j in 0..=n {
            for i in 0..=n {
                points.push((layer, DVec2::new(i as f64 / n as f64, j as f64 / n as f64)));
            }
        }
        if matches!(
            p,
            Projection::Sphere(_)
                | Projection::Paraboloid(_)
                | Projection::Angular(_)
                | Projection::Fisheye(_)
                | Projection::Hammer(_)
        ) {
            for k in 0..4 * n {
                let a = std::f64::consts::TAU * k as f64 / (4 * n) as f64;
                for r in [1.0, 1.0 - 1e-6, 1.0 - 1e-3] {
                    let uv = DVec2::new(0.5 + 0.5 * r * a.cos(), 0.5 - 0.5 * r * a.sin());
                    points.push((layer, uv));
                }
            }
        }
    }
    let mut out = Vec::with_capacity(56 + points.len() * 36);
    out.extend_from_slice(&0u32.to_le_bytes());
    let frame = crate::state::frame_of(p).map_or([0.0; 9], |m| m.to_cols_array());
    for v in frame.into_iter().chain(crate::state::params_of(p)) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    let mut count = 0u32;
    for (layer, uv) in points {
        let Some(d) = p.uv_to_dir(layer, uv) else {
            continue;
        };
        let d32 = d.as_vec3();
        let reference = p.dir_to_uv(d32.as_dvec3());
        let (ru, rv, rl) = match reference {
            Some((l, t)) => (t.x as f32, t.y as f32, l as f32),
            None => (0.0, 0.0, -1.0),
        };
        for v in [
            d32.x,
            d32.y,
            d32.z,
            ru,
            rv,
            rl,
            uv.x as f32,
            uv.y as f32,
            layer as f32,
        ] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        count += 1;
    }
    out[..4].copy_from_slice(&count.to_le_bytes());
    out
}
