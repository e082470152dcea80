//! FFmpeg `v360`'s tetrahedron: the regular tetrahedron inscribed in the cube `[−1, 1]³`
//! unfolded into a rectangle (`libavfilter/vf_v360.c`, `tetrahedron_to_xyz` and
//! `xyz_to_tetrahedron`), so that pictures v360 writes read back and pictures written here
//! play in it.
//!
//! The net, in v360's axes (`x` right, `y` down, `z` forward; mirrorball's `(x, −y, −z)`),
//! puts texture coordinates `(u, v)` at the point `(X, Y, Z)` with
//! `X = 4u − 1` for `u < ½`, `3 − 4u` beyond, `Y = 1 − 2v`,
//! `Z = 2|1 − |1 − 2u + v|| − 1`. In mirrorball's axes that point is
//! `P(u, v) = (X, 2v − 1, 1 − 2|1 − |1 − 2u + v||)`: the top of the picture looks down, as
//! in v360. `P` is linear on each of four right triangles of the rectangle (split by
//! `u = ½`, `v = 2u` and `v = 2u − 1`), each of which it lays on one face `n·P = 1` of the
//! tetrahedron, with `n` one of `(1, −1, 1)` and `(−1, 1, 1)` (left half) or `(1, 1, −1)`
//! and `(−1, −1, −1)` (right half). The left and right edges meet (`u` wraps, as v360
//! reads it), and the top and bottom edges are each one edge of the tetrahedron folded at
//! its middle (`u` meets `1 − u`).
//!
//! Inverse: `m = max nᵢ·d` over the four faces, the point `d/m`; the left half when a
//! left face is the largest (`z + |x − y| ≥ −z + |x + y|`). Area: on a piece the map is
//! affine with `|P_u × P_v| = 8√3` along the face's normal, and central projection gives
//! `dω = (n̂·P)/|P|³ dA` with `n̂·P = 1/√3`, so the density is `8/|P|³`, i.e. `8m³` for a
//! unit direction. Texel solid angles are exact: the texel is cut into its pieces, each a
//! planar polygon on the tetrahedron whose central projection is summed by Van Oosterom &
//! Strackee's triangle formula.

use super::quadrature::{clip, polygon_solid_angle};
use super::{texel_range, WorldProjection};
use glam::{DVec2, DVec3};

/// v360's tetrahedron net (see the module). Size `s` is the picture's width, its height
/// half that, as v360 makes it from a 2:1 source.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Tetrahedron;

/// The point of the tetrahedron at texture coordinates `uv` (mirrorball's axes).
#[inline]
fn net_point(uv: DVec2) -> DVec3 {
    let (u, v) = (uv.x, uv.y);
    let x = if u < 0.5 {
        4.0 * u - 1.0
    } else {
        3.0 - 4.0 * u
    };
    let z = 1.0 - 2.0 * (1.0 - (1.0 - 2.0 * u + v).abs()).abs();
    DVec3::new(x, 2.0 * v - 1.0, z)
}

/// The largest `n·d` over the faces' normals, and whether it is a left-half face's.
#[inline]
fn support(d: DVec3) -> (f64, bool) {
    let left = d.z + (d.x - d.y).abs();
    let right = -d.z + (d.x + d.y).abs();
    if left >= right {
        (left, true)
    } else {
        (right, false)
    }
}

/// The four pieces of the rectangle, each on one face: the half-planes `n·uv ≤ c` that cut
/// it out (after `u ≤ ½` or `u ≥ ½`).
const PIECES: [[(DVec2, f64); 2]; 4] = [
    [(DVec2::new(1.0, 0.0), 0.5), (DVec2::new(-2.0, 1.0), 0.0)],
    [(DVec2::new(1.0, 0.0), 0.5), (DVec2::new(2.0, -1.0), 0.0)],
    [(DVec2::new(-1.0, 0.0), -0.5), (DVec2::new(2.0, -1.0), 1.0)],
    [(DVec2::new(-1.0, 0.0), -0.5), (DVec2::new(-2.0, 1.0), -1.0)],
];

impl WorldProjection for Tetrahedron {
    fn layer_count(&self) -> usize {
        1
    }
    fn layer_extent(&self, size: u32) -> (u32, u32) {
        (size, (size / 2).max(1))
    }
    #[inline]
    fn dir_to_uv(&self, d: DVec3) -> Option<(usize, DVec2)> {
        let (m, left) = support(d);
        if m.is_nan() || m <= 0.0 || !m.is_finite() {
            return None;
        }
        let p = d / m;
        let u = if left {
            0.25 * (p.x + 1.0)
        } else {
            0.25 * (3.0 - p.x)
        };
        Some((0, DVec2::new(u, 0.5 * (1.0 + p.y))))
    }
    #[inline]
    fn uv_to_dir(&self, _layer: usize, uv: DVec2) -> Option<DVec3> {
        let inside = |t: f64| (-1e-12..=1.0 + 1e-12).contains(&t);
        if !inside(uv.x) || !inside(uv.y) {
            return None;
        }
        Some(net_point(uv).normalize())
    }
    fn density(&self, _layer: usize, uv: DVec2) -> f64 {
        if !(0.0..=1.0).contains(&uv.x) || !(0.0..=1.0).contains(&uv.y) {
            return 0.0;
        }
        8.0 / net_point(uv).length().powi(3)
    }
    #[inline]
    fn density_of_dir(&self, d: DVec3) -> f64 {
        let (m, _) = support(d);
        8.0 * m * m * m
    }
    fn texel_solid_angle(&self, _layer: usize, x: u32, y: u32, w: u32, h: u32) -> f64 {
        let (u0, u1) = texel_range(x, w);
        let (v0, v1) = texel_range(y, h);
        let rect = [
            DVec2::new(u0, v0),
            DVec2::new(u1, v0),
            DVec2::new(u1, v1),
            DVec2::new(u0, v1),
        ];
        let mut total = 0.0;
        for [(n0, c0), (n1, c1)] in PIECES {
            let piece = clip(&clip(&rect, n0, c0), n1, c1);
            if piece.len() >= 3 {
                let pts: Vec<DVec3> = piece.iter().map(|&p| net_point(p)).collect();
                total += polygon_solid_angle(&pts);
            }
        }
        total
    }
    #[inline]
    fn wrap_texel(&self, layer: usize, x: i64, y: i64, w: u32, h: u32) -> (usize, u32, u32) {
        let (w, h) = (w as i64, h as i64);
        // Over the top or bottom edge: the same edge of the tetrahedron at `1 − u`.
        let (x, y) = if y < 0 {
            (w - 1 - x, -1 - y)
        } else if y >= h {
            (w - 1 - x, 2 * h - 1 - y)
        } else {
            (x, y)
        };
        (layer, x.rem_euclid(w) as u32, y.clamp(0, h - 1) as u32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// v360's own formulas in its axes (`vf_v360.c`), as the reference the module's
    /// mirrorball-axes forms must equal.
    fn v360_to_xyz(u: f64, v: f64) -> DVec3 {
        let x = if u < 0.5 {
            u * 4.0 - 1.0
        } else {
            3.0 - u * 4.0
        };
        let y = 1.0 - v * 2.0;
        let z = 2.0 * (1.0 - (1.0 - u * 2.0 + v).abs()).abs() - 1.0;
        DVec3::new(x, y, z).normalize()
    }

    fn v360_from_xyz(vec: DVec3) -> DVec2 {
        let d = 0.5 * vec.length_squared();
        let d0 = (vec.x * 0.5 + vec.y * 0.5 + vec.z * -0.5) / d;
        let d1 = (vec.x * -0.5 + vec.y * -0.5 + vec.z * -0.5) / d;
        let d2 = (vec.x * 0.5 + vec.y * -0.5 + vec.z * 0.5) / d;
        let d3 = (vec.x * -0.5 + vec.y * 0.5 + vec.z * 0.5) / d;
        let d = d0.max(d1.max(d2.max(d3)));
        let (x, y, z) = (vec.x / d, vec.y / d, -vec.z / d);
        let vf = 0.5 - y * 0.5;
        let uf = if (x + y >= 0.0 && y + z >= 0.0 && -z - x <= 0.0)
            || (x + y <= 0.0 && -y + z >= 0.0 && z - x >= 0.0)
        {
            0.25 * x + 0.25
        } else {
            0.75 - 0.25 * x
        };
        DVec2::new(uf, vf)
    }

    /// mirrorball's axes from v360's, and back: `(x, −y, −z)`.
    fn flip(d: DVec3) -> DVec3 {
        DVec3::new(d.x, -d.y, -d.z)
    }

    #[test]
    fn both_directions_are_v360s_and_invert_each_other() {
        let t = Tetrahedron;
        let n = 97;
        for j in 0..n {
            for i in 0..2 * n {
                let uv = DVec2::new(
                    (i as f64 + 0.5) / (2 * n) as f64,
                    (j as f64 + 0.5) / n as f64,
                );
                let d = t.uv_to_dir(0, uv).unwrap();
                let want = flip(v360_to_xyz(uv.x, uv.y));
                assert!((d - want).length() < 1e-12, "{uv:?}: {d:?} vs {want:?}");
                let (_, back) = t.dir_to_uv(d).unwrap();
                assert!((back - uv).length() < 1e-12, "{uv:?} came back as {back:?}");
                let theirs = v360_from_xyz(flip(d));
                assert!(
                    (theirs - uv).length() < 1e-12,
                    "v360 reads {uv:?} as {theirs:?}"
                );
            }
        }
        // Directions v360 reads, off the grid: the same coordinates.
        for k in 0..2000 {
            let a = k as f64 * 2.399_963;
            let z = 1.0 - 2.0 * (k as f64 + 0.5) / 2000.0;
            let r = (1.0 - z * z).sqrt();
            let d = DVec3::new(r * a.cos(), z, r * a.sin());
            let (_, uv) = t.dir_to_uv(d).unwrap();
            let theirs = v360_from_xyz(flip(d));
            let du = (uv.x - theirs.x).abs();
            assert!(
                du.min(1.0 - du) < 1e-12 && (uv.y - theirs.y).abs() < 1e-12,
                "{d:?}"
            );
        }
    }

    #[test]
    fn the_top_of_the_picture_looks_down_as_in_v360() {
        let d = Tetrahedron.uv_to_dir(0, DVec2::new(0.25, 0.02)).unwrap();
        assert!(d.y < -0.5, "{d:?}");
    }

    #[test]
    fn density_is_the_derivative_and_texels_sum_to_the_sphere() {
        let t = Tetrahedron;
        // |∂d/∂u × ∂d/∂v| by central differences, inside the pieces.
        for &(u, v) in &[(0.3, 0.2), (0.1, 0.6), (0.7, 0.8), (0.9, 0.2), (0.45, 0.5)] {
            let e = 1e-6;
            let uv = DVec2::new(u, v);
            let du = (t.uv_to_dir(0, uv + DVec2::X * e).unwrap()
                - t.uv_to_dir(0, uv - DVec2::X * e).unwrap())
                / (2.0 * e);
            let dv = (t.uv_to_dir(0, uv + DVec2::Y * e).unwrap()
                - t.uv_to_dir(0, uv - DVec2::Y * e).unwrap())
                / (2.0 * e);
            let want = du.cross(dv).length();
            let got = t.density(0, uv);
            assert!(
                (got - want).abs() < 1e-6 * want,
                "({u}, {v}): {got} vs {want}"
            );
            let d = t.uv_to_dir(0, uv).unwrap();
            assert!((t.density_of_dir(d) - got).abs() < 1e-9 * got);
        }
        for (w, h) in [(8, 4), (33, 17), (64, 32)] {
            let mut sum = 0.0;
            for y in 0..h {
                for x in 0..w {
                    let s = t.texel_solid_angle(0, x, y, w, h);
                    assert!(s > 0.0);
                    sum += s;
                }
            }
            assert!((sum - 4.0 * PI).abs() < 1e-9, "{w}x{h}: {sum}");
        }
        // A texel's solid angle against its density integrated by a fine midpoint rule.
        let (w, h, x, y) = (16, 8, 7, 3);
        let n = 400;
        let mut s = 0.0;
        for j in 0..n {
            for i in 0..n {
                let u = (x as f64 + (i as f64 + 0.5) / n as f64) / w as f64;
                let v = (y as f64 + (j as f64 + 0.5) / n as f64) / h as f64;
                s += t.density(0, DVec2::new(u, v));
            }
        }
        s /= (n * n * w * h) as f64;
        let exact = t.texel_solid_angle(0, x, y, w, h);
        assert!((s - exact).abs() < 1e-5 * exact, "{s} vs {exact}");
    }

    #[test]
    fn wrapped_texels_are_the_neighbours_on_the_tetrahedron() {
        let t = Tetrahedron;
        let (w, h) = (64u32, 32u32);
        let centre = |x: i64, y: i64| {
            let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
            net_point(uv).normalize()
        };
        for x in 0..w as i64 {
            for (y, inner) in [(-1i64, 0i64), (h as i64, h as i64 - 1)] {
                let (_, wx, wy) = t.wrap_texel(0, x, y, w, h);
                // The wrapped texel lies next to the edge texel it continues from.
                let a = centre(wx as i64, wy as i64);
                let b = centre(x, inner);
                assert!(a.angle_between(b) < 0.2, "({x}, {y}) -> ({wx}, {wy})");
            }
        }
        assert_eq!(t.wrap_texel(0, -1, 5, w, h), (0, w - 1, 5));
        assert_eq!(t.wrap_texel(0, w as i64, 5, w, h), (0, 0, 5));
    }
}
