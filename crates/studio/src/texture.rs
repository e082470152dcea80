//! An environment map's layers as the page's texture array: each layer padded by one texel
//! all round, the padding filled by the core's seam rule (`WorldProjection::wrap_texel`:
//! across a cube edge, around the longitude wrap, over a pole, past a disk's rim), so that
//! the shader's plain bilinear read of the padded layer reads the texels the core's
//! seamless bilinear lookup (`EnvMap::bilinear_at`) reads.
//!
//! The payload, little-endian: `b"MBTX"`, `u32` length of a JSON header, the header
//! (`describe_map`'s fields plus `pad`, `texelWidth`, `texelHeight`, `precision`),
//! zero bytes to a multiple of 4, then the texels: layer by layer, row 0 (the top of the
//! picture) first, RGBA, as `f32` or IEEE half floats.

use crate::state::describe_map;
use mirrorball_core::{Choice, EnvMap, WorldProjection};

/// How texels are sent.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precision {
    /// IEEE binary16 (RGBA16F).
    Half,
    /// `f32` (RGBA32F).
    Float,
}

impl Choice for Precision {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (Precision::Half, &["half", "f16"]),
        (Precision::Float, &["float", "f32"]),
    ];
}
mirrorball_core::choice_traits!(Precision);

/// The padding on each side, in texels.
pub const PAD: u32 = 1;

/// `map`'s layers padded, RGBA, as the payload described above.
pub fn encode(map: &EnvMap, precision: Precision) -> Vec<u8> {
    let (w, h) = (map.width(), map.height());
    let (pw, ph) = (w + 2 * PAD, h + 2 * PAD);
    let mut header = describe_map(map);
    header["pad"] = PAD.into();
    header["texelWidth"] = pw.into();
    header["texelHeight"] = ph.into();
    header["precision"] = precision.name().into();
    let mut json = header.to_string().into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let layers = map.layers();
    let texel_bytes = match precision {
        Precision::Half => 8,
        Precision::Float => 16,
    };
    let mut out =
        Vec::with_capacity(8 + json.len() + layers.len() * (pw * ph) as usize * texel_bytes);
    out.extend_from_slice(b"MBTX");
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(&json);
    let p = map.projection();
    for layer in 0..layers.len() {
        for y in -(PAD as i64)..(h + PAD) as i64 {
            for x in -(PAD as i64)..(w + PAD) as i64 {
                let (l, tx, ty) = if (0..w as i64).contains(&x) && (0..h as i64).contains(&y) {
                    (layer, x as u32, y as u32)
                } else {
                    p.wrap_texel(layer, x, y, w, h)
                };
                let t = layers[l].get(tx, ty);
                let rgba = [t[0], t[1], t[2], if t.len() > 3 { t[3] } else { 1.0 }];
                for c in rgba {
                    match precision {
                        Precision::Half => {
                            out.extend_from_slice(&half::f16::from_f32(c).to_bits().to_le_bytes())
                        }
                        Precision::Float => out.extend_from_slice(&c.to_le_bytes()),
                    }
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorball_core::glam::DVec3;
    use mirrorball_core::{Image, Projection, ProjectionKind};

    /// A map whose texel `(l, x, y)` holds `(l, x, y)`.
    fn indexed(kind: ProjectionKind, size: u32) -> EnvMap {
        let p = kind.default_projection();
        let (w, h) = p.layer_extent(size);
        let layers = (0..p.layer_count())
            .map(|l| {
                let mut img = Image::new(w, h, 3);
                for y in 0..h {
                    for x in 0..w {
                        img.set(x, y, &[l as f32, x as f32, y as f32]);
                    }
                }
                img
            })
            .collect();
        EnvMap::new(p, layers).unwrap()
    }

    /// The bilinear read of a padded layer, as `web/glsl/bilinear.glsl` does it.
    fn padded_bilinear(
        data: &[f32],
        pw: usize,
        ph: usize,
        layer: usize,
        u: f32,
        v: f32,
    ) -> [f32; 3] {
        let (w, h) = (pw - 2, ph - 2);
        let (x0, y0, fx, fy) = mirrorball_core::bilinear_corner(u, v, w as u32, h as u32);
        let at = |x: i32, y: i32| {
            let (x, y) = (
                (x + 1).clamp(0, pw as i32 - 1),
                (y + 1).clamp(0, ph as i32 - 1),
            );
            let i = ((layer * ph + y as usize) * pw + x as usize) * 4;
            [data[i], data[i + 1], data[i + 2]]
        };
        let (a, b, c, d) = (
            at(x0, y0),
            at(x0 + 1, y0),
            at(x0, y0 + 1),
            at(x0 + 1, y0 + 1),
        );
        std::array::from_fn(|k| {
            let top = a[k] + fx * (b[k] - a[k]);
            let bot = c[k] + fx * (d[k] - c[k]);
            top + fy * (bot - top)
        })
    }

    #[test]
    fn the_padded_read_is_the_cores_seamless_read() {
        // Texels that name themselves: a tap taken from the wrong texel shows.
        for kind in ProjectionKind::ALL {
            let map = indexed(kind, 8);
            let bytes = encode(&map, Precision::Float);
            let n = u32::from_le_bytes(bytes[4..8].try_into().unwrap()) as usize;
            let header: serde_json::Value = serde_json::from_slice(&bytes[8..8 + n]).unwrap();
            let (pw, ph) = (
                header["texelWidth"].as_u64().unwrap() as usize,
                header["texelHeight"].as_u64().unwrap() as usize,
            );
            let data: Vec<f32> = bytes[8 + n..]
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
                .collect();
            assert_eq!(data.len(), map.layers().len() * pw * ph * 4);
            let p: Projection = *map.projection();
            let mut seams = 0;
            let steps = 97;
            for i in 0..steps {
                for j in 0..2 * steps {
                    let (th, ph_) = (
                        std::f64::consts::PI * (i as f64 + 0.5) / steps as f64,
                        std::f64::consts::PI * (j as f64 + 0.5) / steps as f64,
                    );
                    let d = DVec3::new(th.sin() * ph_.cos(), th.cos(), th.sin() * ph_.sin());
                    let Some((l, uv)) = p.dir_to_uv(d) else {
                        continue;
                    };
                    let (u, v) = (uv.x as f32, uv.y as f32);
                    let mut want = [0.0f32; 3];
                    map.bilinear_at(
                        l,
                        mirrorball_core::glam::DVec2::new(u as f64, v as f64),
                        &mut want,
                    );
                    let got = padded_bilinear(&data, pw, ph, l, u, v);
                    let (x0, y0, _, _) =
                        mirrorball_core::bilinear_corner(u, v, map.width(), map.height());
                    if x0 < 0
                        || y0 < 0
                        || x0 + 1 >= map.width() as i32
                        || y0 + 1 >= map.height() as i32
                    {
                        seams += 1;
                    }
                    for k in 0..3 {
                        assert!(
                            (got[k] - want[k]).abs() < 1e-3,
                            "{kind:?} at {d:?} (layer {l}, {u}, {v}): {got:?} against {want:?}"
                        );
                    }
                }
            }
            assert!(seams > 50, "{kind:?}: only {seams} lookups crossed a seam");
        }
    }
}
