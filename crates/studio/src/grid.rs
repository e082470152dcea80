//! A dense grid of directions with the core's texture coordinates for them: what the
//! browser test compares each projection's shader (`web/glsl/NAME.glsl`) against; and the
//! other way, the core's directions of texture coordinates the page read ([`directions`]).
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

/// The most texture coordinates one request of [`directions`] carries (two viewports'
/// worth at 4096×2160).
pub const MAX_LOOKUPS: usize = 2 * 4096 * 2160;

/// The core's `uv_to_dir` in `p` of each `(u, v, layer)` of `body` (little-endian `f32`
/// triples, as the simulator's record pass writes them: the layer a float, rounded), as
/// `f32` triples; NaN where there is none (a negative or non-finite layer or coordinate,
/// a layer the map does not have, a point off a disk). The simulator's heat map measures
/// its angles between these, so that the page holds no inverse of any projection.
pub fn directions(p: &Projection, body: &[u8]) -> Result<Vec<u8>, crate::Error> {
    if !body.len().is_multiple_of(12) || body.len() / 12 > MAX_LOOKUPS {
        return Err(crate::Error::request(format!(
            "the body must be (u, v, layer) f32 triples, at most {MAX_LOOKUPS}: {} bytes",
            body.len()
        )));
    }
    let mut out = Vec::with_capacity(body.len());
    for t in body.chunks_exact(12) {
        let f = |k: usize| f32::from_le_bytes([t[k], t[k + 1], t[k + 2], t[k + 3]]) as f64;
        let (u, v, layer) = (f(0), f(4), f(8).round());
        let d = (u.is_finite() && v.is_finite() && layer >= 0.0 && layer < p.layer_count() as f64)
            .then(|| p.uv_to_dir(layer as usize, DVec2::new(u, v)))
            .flatten()
            .map_or([f32::NAN; 3], |d| d.as_vec3().to_array());
        for x in d {
            out.extend_from_slice(&x.to_le_bytes());
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorball_core::ProjectionKind;

    fn triples(v: &[f32]) -> Vec<u8> {
        v.iter().flat_map(|x| x.to_le_bytes()).collect()
    }

    fn floats(b: &[u8]) -> Vec<f32> {
        b.chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    }

    #[test]
    fn directions_are_the_cores_and_nan_where_there_is_none() {
        let cube = ProjectionKind::Cube.default_projection();
        // Each face's centre is its major axis (OpenGL's face order +X −X +Y −Y +Z −Z); a
        // layer given as 2.0000001 is layer 2.
        let mut body = Vec::new();
        for l in 0..6 {
            body.extend([0.5, 0.5, l as f32]);
        }
        body.extend([0.5, 0.5, 2.000_000_2]);
        let got = floats(&directions(&cube, &triples(&body)).unwrap());
        let axes = [
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
            [0.0, 1.0, 0.0],
        ];
        for (k, a) in axes.iter().enumerate() {
            for c in 0..3 {
                assert!((got[3 * k + c] - a[c]).abs() < 1e-6, "{k}: {got:?}");
            }
        }
        // A layer the cube has not, a negative one, non-finite coordinates; a point off the
        // sphere map's disk.
        let none = [
            0.5,
            0.5,
            6.0,
            0.5,
            0.5,
            -1.0,
            f32::NAN,
            0.5,
            0.0,
            0.5,
            f32::INFINITY,
            0.0,
        ];
        let got = floats(&directions(&cube, &triples(&none)).unwrap());
        assert!(got.iter().all(|x| x.is_nan()), "{got:?}");
        let sphere = ProjectionKind::Sphere.default_projection();
        let got = floats(&directions(&sphere, &triples(&[0.999, 0.999, 0.0])).unwrap());
        assert!(got.iter().all(|x| x.is_nan()), "{got:?}");
        // A body that is not whole triples.
        let e = directions(&cube, &[0u8; 13]).unwrap_err();
        assert!(e.message.contains("13 bytes") && e.status() == 400, "{e}");
    }
}
