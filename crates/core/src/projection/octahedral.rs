//! Octahedral maps: the octahedron `|x| + |y| + |z| = 1` unfolded into a square (Praun &
//! Hoppe 2003; Cigolle et al. 2014), and Clarberg's equal-area variant (2008).
//!
//! Both use the same square: `(a, b) = (2u − 1, 2v − 1)`, the upper hemisphere (+Y) in the
//! inner diamond `|a| + |b| ≤ 1` with `a` along +X and `b` along +Z (so −Z, straight ahead,
//! is towards the top of the picture), the lower hemisphere folded out into the four corner
//! triangles. The square's border is mirrored about each side's midpoint, which is how
//! texels outside it wrap.

use super::quadrature::{clip, polygon_solid_angle};
use super::{texel_range, WorldProjection};
use glam::{DVec2, DVec3};
use std::f64::consts::{FRAC_PI_2, PI};

#[inline]
fn sgn(x: f64) -> f64 {
    if x >= 0.0 {
        1.0
    } else {
        -1.0
    }
}

#[inline]
fn uv_to_ab(uv: DVec2) -> DVec2 {
    uv * 2.0 - DVec2::ONE
}

#[inline]
fn ab_to_uv(ab: DVec2) -> DVec2 {
    (ab + DVec2::ONE) * 0.5
}

/// The point on the octahedron `|x|+|y|+|z| = 1` for square coordinates `(a, b)`.
#[inline]
fn octa_point(ab: DVec2) -> DVec3 {
    let y = 1.0 - ab.x.abs() - ab.y.abs();
    if y >= 0.0 {
        DVec3::new(ab.x, y, ab.y)
    } else {
        DVec3::new(
            (1.0 - ab.y.abs()) * sgn(ab.x),
            y,
            (1.0 - ab.x.abs()) * sgn(ab.y),
        )
    }
}

/// Mirror-wraps a texel index across the square's border.
#[inline]
fn wrap_octa(x: i64, y: i64, w: u32, h: u32) -> (u32, u32) {
    let (w, h) = (w as i64, h as i64);
    let (mut x, mut y) = (x, y);
    for _ in 0..2 {
        if x < 0 {
            x = -1 - x;
            y = h - 1 - y;
        } else if x >= w {
            x = 2 * w - 1 - x;
            y = h - 1 - y;
        }
        if y < 0 {
            y = -1 - y;
            x = w - 1 - x;
        } else if y >= h {
            y = 2 * h - 1 - y;
            x = w - 1 - x;
        }
    }
    (x.clamp(0, w - 1) as u32, y.clamp(0, h - 1) as u32)
}

/// The standard octahedral map: `(a, b) = (x, z)/(|x|+|y|+|z|)` for `y ≥ 0`, folded
/// `(a, b) → ((1 − |b|) sgn a, (1 − |a|) sgn b)` for `y < 0`.
///
/// Area: on an octant face the map from `(a, b)` to the octahedron point `P` is affine with
/// area factor √3, and central projection gives `dω = (n̂·P̂)/|P|² dA`, `n̂·P = 1/√3`, so
/// `dω = da db / |P|³`. Texel solid angles are exact: the texel is cut along the fold lines
/// into pieces that map to planar polygons on the octahedron, whose central projections are
/// spherical polygons (summed by Van Oosterom & Strackee's triangle formula).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Octahedral;

impl WorldProjection for Octahedral {
    fn layer_count(&self) -> usize {
        1
    }
    fn layer_extent(&self, size: u32) -> (u32, u32) {
        (size, size)
    }
    #[inline]
    fn dir_to_uv(&self, d: DVec3) -> Option<(usize, DVec2)> {
        let l1 = d.x.abs() + d.y.abs() + d.z.abs();
        if l1 <= 0.0 || !l1.is_finite() {
            return None;
        }
        let (a, b) = (d.x / l1, d.z / l1);
        let ab = if d.y >= 0.0 {
            DVec2::new(a, b)
        } else {
            DVec2::new((1.0 - b.abs()) * sgn(a), (1.0 - a.abs()) * sgn(b))
        };
        Some((0, ab_to_uv(ab)))
    }
    #[inline]
    fn uv_to_dir(&self, _layer: usize, uv: DVec2) -> Option<DVec3> {
        let ab = uv_to_ab(uv);
        if ab.x.abs() > 1.0 + 1e-12 || ab.y.abs() > 1.0 + 1e-12 {
            return None;
        }
        Some(octa_point(ab).normalize())
    }
    fn density(&self, _layer: usize, uv: DVec2) -> f64 {
        let p = octa_point(uv_to_ab(uv));
        4.0 / p.length().powi(3)
    }
    #[inline]
    fn density_of_dir(&self, d: DVec3) -> f64 {
        // The octahedron point is d/|d|₁, so |P| = 1/|d|₁.
        let l1 = d.x.abs() + d.y.abs() + d.z.abs();
        4.0 * l1 * l1 * l1
    }
    fn texel_solid_angle(&self, _layer: usize, x: u32, y: u32, w: u32, h: u32) -> f64 {
        let (u0, u1) = texel_range(x, w);
        let (v0, v1) = texel_range(y, h);
        let (a0, b0) = (2.0 * u0 - 1.0, 2.0 * v0 - 1.0);
        let (a1, b1) = (2.0 * u1 - 1.0, 2.0 * v1 - 1.0);
        let rect = [
            DVec2::new(a0, b0),
            DVec2::new(a1, b0),
            DVec2::new(a1, b1),
            DVec2::new(a0, b1),
        ];
        let mut total = 0.0;
        for sa in [-1.0, 1.0] {
            for sb in [-1.0, 1.0] {
                // Quadrant sa·a ≥ 0, sb·b ≥ 0.
                let q = clip(
                    &clip(&rect, DVec2::new(-sa, 0.0), 0.0),
                    DVec2::new(0.0, -sb),
                    0.0,
                );
                if q.len() < 3 {
                    continue;
                }
                let n = DVec2::new(sa, sb);
                for piece in [clip(&q, n, 1.0), clip(&q, -n, -1.0)] {
                    if piece.len() >= 3 {
                        let pts: Vec<DVec3> = piece.iter().map(|&p| octa_point(p)).collect();
                        total += polygon_solid_angle(&pts);
                    }
                }
            }
        }
        total
    }
    #[inline]
    fn wrap_texel(&self, layer: usize, x: i64, y: i64, w: u32, h: u32) -> (usize, u32, u32) {
        let (x, y) = wrap_octa(x, y, w, h);
        (layer, x, y)
    }
}

/// Clarberg's equal-area octahedral map ("Fast Equal-Area Mapping of the (Hemi)Sphere using
/// SIMD", JGT 2008), on the same square and axes as [`Octahedral`].
///
/// Decode: `r = 1 − |1 − |a| − |b||`, `φ = ((|b| − |a|)/r + 1)·π/4`, height
/// `y = sgn(1 − |a| − |b|)(1 − r²)`, horizontal radius `r√(2 − r²)` at azimuth φ from +X
/// towards +Z (signs of `a`, `b`). Encode: `r = √(1 − |y|)` (computed as
/// `√((x² + z²)/(1 + |y|))` to keep precision near the poles), `|b| = 2rφ/π`,
/// `|a| = r − |b|`, folded for `y < 0`. Every texel holds exactly `4π/(w·h)` sr.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EqualAreaOctahedral;

impl WorldProjection for EqualAreaOctahedral {
    fn layer_count(&self) -> usize {
        1
    }
    fn layer_extent(&self, size: u32) -> (u32, u32) {
        (size, size)
    }
    #[inline]
    fn dir_to_uv(&self, d: DVec3) -> Option<(usize, DVec2)> {
        let hz2 = d.x * d.x + d.z * d.z;
        let len2 = hz2 + d.y * d.y;
        if len2.is_nan() || len2 <= 0.0 || !len2.is_finite() {
            return None;
        }
        let r = (hz2 / (len2 + d.y.abs() * len2.sqrt())).sqrt();
        let phi = d.z.abs().atan2(d.x.abs());
        let bb = r * phi / FRAC_PI_2;
        let aa = r - bb;
        let (aa, bb) = if d.y >= 0.0 {
            (aa, bb)
        } else {
            (1.0 - bb, 1.0 - aa)
        };
        Some((0, ab_to_uv(DVec2::new(aa * sgn(d.x), bb * sgn(d.z)))))
    }
    #[inline]
    fn uv_to_dir(&self, _layer: usize, uv: DVec2) -> Option<DVec3> {
        let ab = uv_to_ab(uv);
        let (aa, bb) = (ab.x.abs(), ab.y.abs());
        if aa > 1.0 + 1e-12 || bb > 1.0 + 1e-12 {
            return None;
        }
        let dd = 1.0 - (aa + bb);
        let r = 1.0 - dd.abs();
        let phi = if r == 0.0 {
            PI / 4.0
        } else {
            ((bb - aa) / r + 1.0) * PI / 4.0
        };
        let y = sgn(dd) * (1.0 - r * r);
        let s = r * (2.0 - r * r).max(0.0).sqrt();
        let (sp, cp) = phi.sin_cos();
        Some(DVec3::new(sgn(ab.x) * cp * s, y, sgn(ab.y) * sp * s))
    }
    fn density(&self, _layer: usize, uv: DVec2) -> f64 {
        let ab = uv_to_ab(uv);
        if ab.x.abs() > 1.0 || ab.y.abs() > 1.0 {
            return 0.0;
        }
        4.0 * PI
    }
    #[inline]
    fn density_of_dir(&self, _d: DVec3) -> f64 {
        4.0 * PI
    }
    fn texel_solid_angle(&self, _layer: usize, _x: u32, _y: u32, w: u32, h: u32) -> f64 {
        4.0 * PI / (w as f64 * h as f64)
    }
    #[inline]
    fn wrap_texel(&self, layer: usize, x: i64, y: i64, w: u32, h: u32) -> (usize, u32, u32) {
        let (x, y) = wrap_octa(x, y, w, h);
        (layer, x, y)
    }
}
