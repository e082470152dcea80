//! An environment map's layers as the page's texture array: each layer padded by one texel
//! all round, the padding filled by the core's seam rule (`WorldProjection::wrap_texel`:
//! across a cube edge, around the longitude wrap, over a pole, past a disk's rim), so that
//! the shader's plain bilinear read of the padded layer reads the texels the core's
//! seamless bilinear lookup (`EnvMap::bilinear_at`) reads.
//!
//! A map's mip chain (the filter crate's `MipChain::build` with the box filter: the pyramid
//! `mirrorball render`'s trilinear and EWA lookups read, mode 4's) travels the same way,
//! every level padded alike and packed into one atlas per layer: level 0 at the top left,
//! the further levels stacked top to bottom in a column to its right. Each level's padded
//! read is then the core's seamless `bilinear_at` of that level.
//!
//! The payload, little-endian: `b"MBTX"`, `u32` length of a JSON header, the header
//! (`describe_map`'s fields plus `pad`, `texelWidth`, `texelHeight` (the atlas),
//! `precision` and `levels`: per level `[x, y, width, height]`, the padded block's top-left
//! texel in the atlas and the level's size without the padding), spaces to a multiple of 4,
//! then the texels: layer by layer, row 0 (the top of the picture) first, RGBA, as `f32` or
//! IEEE half floats; atlas texels no level covers are zero.

use crate::state::describe_map;
use mirrorball_core::{Choice, EnvMap, Projection, WorldProjection};
use mirrorball_filter::{MipChain, MipFilter};

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

/// How a map was made to fit the page's GPU: its size before, and the largest texture
/// edge the page said the GPU takes (`GL_MAX_TEXTURE_SIZE`). Sent as the header's
/// `fitted` (`{"from": [w, h], "limit": N}`), for the page to say.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fitted {
    pub from: (u32, u32),
    pub limit: u32,
}

/// `map`'s layers padded, RGBA, as the payload described above (one level).
pub fn encode(map: &EnvMap, precision: Precision, fitted: Option<Fitted>) -> Vec<u8> {
    encode_levels(std::slice::from_ref(map), precision, fitted)
}

/// `map` and its mip chain (`MipChain::build`, box filter: what `mirrorball render`'s
/// footprint samplers read) as the payload described above.
pub fn encode_mips(map: &EnvMap, precision: Precision, fitted: Option<Fitted>) -> Vec<u8> {
    encode_levels(
        MipChain::build(map, MipFilter::Box).levels(),
        precision,
        fitted,
    )
}

/// The atlas's width and height for a `w`×`h` level 0, alone or with its chain (`mips`:
/// each level half the one before, rounded down, at least 1, down to 1×1, as
/// `MipChain::build` makes them).
pub fn atlas_extent((w, h): (u32, u32), mips: bool) -> (u32, u32) {
    let mut sizes = vec![(w, h)];
    while let Some(&(a, b)) = sizes.last().filter(|_| mips) {
        if a == 1 && b == 1 {
            break;
        }
        sizes.push(((a / 2).max(1), (b / 2).max(1)));
    }
    let (_, aw, ah) = atlas(&sizes);
    (aw, ah)
}

/// The largest size (`layer_extent`'s parameter) of `p` at most `size` whose atlas, alone
/// or with its chain, is at most `limit` texels wide and high; `None` when not even size
/// 1's is.
pub fn fitting_size(p: &Projection, size: u32, limit: u32, mips: bool) -> Option<u32> {
    let fits = |s: u32| {
        let (aw, ah) = atlas_extent(p.layer_extent(s), mips);
        aw <= limit && ah <= limit
    };
    if !fits(1) {
        return None;
    }
    // The atlas grows with the size: the largest that fits, by bisection.
    let (mut lo, mut hi) = (1, size.max(1));
    while lo < hi {
        let mid = lo + (hi - lo).div_ceil(2);
        if fits(mid) {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    Some(lo)
}

/// Where each level's padded block lies in the atlas: `[x, y, width, height]` (top-left
/// texel of the block; the level's size without padding), and the atlas's size.
pub fn atlas(levels: &[(u32, u32)]) -> (Vec<[u32; 4]>, u32, u32) {
    let (w0, h0) = levels[0];
    let mut rects = vec![[0, 0, w0, h0]];
    let (mut width, mut height) = (w0 + 2 * PAD, h0 + 2 * PAD);
    let mut y = 0;
    for &(w, h) in &levels[1..] {
        rects.push([w0 + 2 * PAD, y, w, h]);
        width = width.max(w0 + 2 * PAD + w + 2 * PAD);
        y += h + 2 * PAD;
        height = height.max(y);
    }
    (rects, width, height)
}

/// `levels` (level 0 first, one projection) padded into one atlas per layer.
fn encode_levels(levels: &[EnvMap], precision: Precision, fitted: Option<Fitted>) -> Vec<u8> {
    let map = &levels[0];
    let sizes: Vec<(u32, u32)> = levels.iter().map(|l| (l.width(), l.height())).collect();
    let (rects, aw, ah) = atlas(&sizes);
    let mut header = describe_map(map);
    header["pad"] = PAD.into();
    header["texelWidth"] = aw.into();
    header["texelHeight"] = ah.into();
    header["precision"] = precision.name().into();
    header["levels"] = rects.iter().map(|r| r.to_vec()).collect::<Vec<_>>().into();
    if let Some(f) = fitted {
        header["fitted"] = serde_json::json!({"from": [f.from.0, f.from.1], "limit": f.limit});
    }
    let mut json = header.to_string().into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let layer_count = map.layers().len();
    let texel_bytes = match precision {
        Precision::Half => 8,
        Precision::Float => 16,
    };
    let body = 8 + json.len();
    let mut out = vec![0u8; body + layer_count * (aw * ah) as usize * texel_bytes];
    out[..4].copy_from_slice(b"MBTX");
    out[4..8].copy_from_slice(&(json.len() as u32).to_le_bytes());
    out[8..body].copy_from_slice(&json);
    for (level, rect) in levels.iter().zip(&rects) {
        let (w, h) = (level.width(), level.height());
        let p = level.projection();
        let layers = level.layers();
        for layer in 0..layer_count {
            for y in -(PAD as i64)..(h + PAD) as i64 {
                for x in -(PAD as i64)..(w + PAD) as i64 {
                    let (l, tx, ty) = if (0..w as i64).contains(&x) && (0..h as i64).contains(&y) {
                        (layer, x as u32, y as u32)
                    } else {
                        p.wrap_texel(layer, x, y, w, h)
                    };
                    let t = layers[l].get(tx, ty);
                    let rgba = [t[0], t[1], t[2], if t.len() > 3 { t[3] } else { 1.0 }];
                    let ax = (rect[0] as i64 + x + PAD as i64) as usize;
                    let ay = (rect[1] as i64 + y + PAD as i64) as usize;
                    let mut at =
                        body + ((layer * ah as usize + ay) * aw as usize + ax) * texel_bytes;
                    for c in rgba {
                        match precision {
                            Precision::Half => out[at..at + 2]
                                .copy_from_slice(&half::f16::from_f32(c).to_bits().to_le_bytes()),
                            Precision::Float => out[at..at + 4].copy_from_slice(&c.to_le_bytes()),
                        }
                        at += texel_bytes / 4;
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

    /// The bilinear read of the padded level at `rect` (`[x, y, w, h]`, `levels` in the
    /// header) of an `aw`-wide, `ah`-high atlas, as `web/glsl/bilinear.glsl` does it.
    fn padded_bilinear(
        data: &[f32],
        (aw, ah): (usize, usize),
        rect: [usize; 4],
        layer: usize,
        (u, v): (f32, f32),
    ) -> [f32; 3] {
        let [ox, oy, w, h] = rect;
        let (x0, y0, fx, fy) = mirrorball_core::bilinear_corner(u, v, w as u32, h as u32);
        let at = |x: i32, y: i32| {
            let (x, y) = (
                ox + (x + 1).clamp(0, w as i32 + 1) as usize,
                oy + (y + 1).clamp(0, h as i32 + 1) as usize,
            );
            let i = ((layer * ah + y) * aw + x) * 4;
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

    /// The payload's header, atlas size, level rectangles and texels (`f32`).
    fn decode(bytes: &[u8]) -> ((usize, usize), Vec<[usize; 4]>, Vec<f32>) {
        let n = u32::from_le_bytes(bytes[4..8].try_into().unwrap()) as usize;
        let header: serde_json::Value = serde_json::from_slice(&bytes[8..8 + n]).unwrap();
        let size = (
            header["texelWidth"].as_u64().unwrap() as usize,
            header["texelHeight"].as_u64().unwrap() as usize,
        );
        let rects = header["levels"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| std::array::from_fn(|k| r[k].as_u64().unwrap() as usize))
            .collect();
        let data = bytes[8 + n..]
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        (size, rects, data)
    }

    /// Directions over the sphere, `steps` × `2 steps` of them.
    fn directions(steps: usize) -> impl Iterator<Item = DVec3> {
        (0..steps).flat_map(move |i| {
            (0..2 * steps).map(move |j| {
                let (th, ph) = (
                    std::f64::consts::PI * (i as f64 + 0.5) / steps as f64,
                    std::f64::consts::PI * (j as f64 + 0.5) / steps as f64,
                );
                DVec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin())
            })
        })
    }

    #[test]
    fn every_levels_padded_read_is_the_cores_read_of_that_level() {
        for kind in ProjectionKind::ALL {
            let map = indexed(kind, 16);
            let (size, rects, data) = decode(&encode_mips(&map, Precision::Float, None));
            let chain = MipChain::build(&map, MipFilter::Box);
            assert_eq!(rects.len(), chain.len(), "{kind:?}");
            assert_eq!(data.len(), map.layers().len() * size.0 * size.1 * 4);
            // The blocks do not overlap.
            for (i, a) in rects.iter().enumerate() {
                for b in &rects[i + 1..] {
                    let apart = a[0] + a[2] + 2 <= b[0]
                        || b[0] + b[2] + 2 <= a[0]
                        || a[1] + a[3] + 2 <= b[1]
                        || b[1] + b[3] + 2 <= a[1];
                    assert!(apart, "{kind:?}: {a:?} and {b:?} overlap");
                }
            }
            for (l, level) in chain.levels().iter().enumerate() {
                assert_eq!(
                    [rects[l][2], rects[l][3]],
                    [level.width() as usize, level.height() as usize]
                );
                let p: Projection = *level.projection();
                for d in directions(31) {
                    let Some((layer, uv)) = p.dir_to_uv(d) else {
                        continue;
                    };
                    let mut want = [0.0f32; 3];
                    level.bilinear_at(layer, uv, &mut want);
                    let got =
                        padded_bilinear(&data, size, rects[l], layer, (uv.x as f32, uv.y as f32));
                    for k in 0..3 {
                        assert!(
                            (got[k] - want[k]).abs() < 1e-3 * want[k].abs().max(1.0),
                            "{kind:?} level {l} at {d:?}: {got:?} against {want:?}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn the_padded_read_is_the_cores_seamless_read() {
        // Texels that name themselves: a tap taken from the wrong texel shows.
        for kind in ProjectionKind::ALL {
            let map = indexed(kind, 8);
            let (size, rects, data) = decode(&encode(&map, Precision::Float, None));
            assert_eq!(rects.len(), 1);
            assert_eq!(data.len(), map.layers().len() * size.0 * size.1 * 4);
            let p: Projection = *map.projection();
            let mut seams = 0;
            for d in directions(97) {
                {
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
                    let got = padded_bilinear(&data, size, rects[0], l, (u, v));
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
