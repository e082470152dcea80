//! Equal-area world maps with a curved outline: Hammer's (Hammer–Aitoff, an ellipse) and the
//! sinusoidal (Sanson–Flamsteed). Both show the whole sphere inside their outline, centred
//! straight ahead (−Z) with +X to the right and +Y up, the back meridian (+Z) split along
//! the left and right rims; texels outside the outline have no direction of their own (they
//! take the nearest rim point's, with density 0, as the disk maps do). FFmpeg's `v360` calls
//! them `hammer` and `sinusoidal`.
//!
//! Longitude and latitude are those of [`LatLong`](super::LatLong); `a = 2u − 1` grows to
//! the right, `b = 1 − 2v` upwards.

use super::azimuthal::clamp_to_disk;
use super::latlong::dir_from_lon_lat;
use super::{texel_range, Frame, Lens, RadialMap, WorldProjection};
use glam::{DVec2, DVec3};
use std::f64::consts::{FRAC_1_PI, FRAC_PI_2, PI, SQRT_2};

#[inline]
fn lon_lat(d: DVec3) -> (f64, f64, f64) {
    let h = (d.x * d.x + d.z * d.z).sqrt();
    (d.x.atan2(-d.z), d.y.atan2(h), h)
}

/// Hammer's equal-area projection (1892), on a 2:1 picture whose inscribed ellipse is the
/// whole sphere. In the usual units `x = 2√2 cos φ sin(λ/2)/z`, `y = √2 sin φ/z` with
/// `z = √(1 + cos φ cos(λ/2))` (Snyder, *Map Projections: A Working Manual*, 1987, p. 231),
/// and `(a, b) = (x/2√2, y/√2)` fills the unit disk `a² + b² ≤ 1`. Inverse, with
/// `Z = √(1 − a²/2 − b²/2)`: `λ = 2 atan2(√2 a Z, 2Z² − 1)`, `φ = asin(√2 b Z)`.
///
/// Equal-area: `4π` over the disk's area π/4 in `uv`, so the density is 16 inside and a
/// texel holds 16 times its area inside the disk — the sphere map's measure exactly, which
/// does the clipping (see [`RadialMap::rect_solid_angle`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hammer {
    /// The equal-area disk with the same measure (16 per unit of `uv` area).
    disk: RadialMap,
}

impl Default for Hammer {
    fn default() -> Self {
        Hammer {
            disk: RadialMap::new(Frame::default(), Lens::Equisolid, PI).expect("valid"),
        }
    }
}

impl WorldProjection for Hammer {
    fn layer_count(&self) -> usize {
        1
    }
    fn layer_extent(&self, size: u32) -> (u32, u32) {
        (size, (size / 2).max(1))
    }
    #[inline]
    fn dir_to_uv(&self, d: DVec3) -> Option<(usize, DVec2)> {
        let (lon, _, cp) = lon_lat(d);
        let (s2, c2) = (0.5 * lon).sin_cos();
        let z = (1.0 + cp * c2).sqrt();
        let (a, b) = (cp * s2 / z, d.y / z);
        Some((0, DVec2::new(0.5 * (a + 1.0), 0.5 * (1.0 - b))))
    }
    #[inline]
    fn uv_to_dir(&self, _layer: usize, uv: DVec2) -> Option<DVec3> {
        let (a, b) = (2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y);
        let r2 = a * a + b * b;
        if r2 > 1.0 + 1e-12 {
            return None;
        }
        let zz = 1.0 - 0.5 * r2.min(1.0);
        let z = zz.sqrt();
        let lon = 2.0 * (SQRT_2 * a * z).atan2(2.0 * zz - 1.0);
        let lat = (SQRT_2 * b * z).clamp(-1.0, 1.0).asin();
        Some(dir_from_lon_lat(lon, lat))
    }
    #[inline]
    fn density(&self, _layer: usize, uv: DVec2) -> f64 {
        let (a, b) = (2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y);
        if a * a + b * b > 1.0 {
            0.0
        } else {
            16.0
        }
    }
    #[inline]
    fn density_of_dir(&self, _dir: DVec3) -> f64 {
        16.0
    }
    fn texel_solid_angle(&self, _layer: usize, x: u32, y: u32, w: u32, h: u32) -> f64 {
        let (u0, u1) = texel_range(x, w);
        let (v0, v1) = texel_range(y, h);
        self.disk.rect_solid_angle(u0, u1, v0, v1)
    }
    fn nearest_covered(&self, _layer: usize, uv: DVec2) -> DVec2 {
        clamp_to_disk(uv)
    }
}

/// The sinusoidal projection: `a = λ cos φ/π`, `b = 2φ/π`, on a 2:1 picture; the outline is
/// `|a| ≤ cos(πb/2)`, in `uv` `|u − ½| ≤ ½ sin(πv)`. Inverse: `φ = πb/2`, `λ = πa/cos φ`.
///
/// Equal-area: `dω = cos φ dφ dλ` and at fixed φ `cos φ dλ = π da`, so `dω = π da · (π/2) db
/// = 2π² du dv` inside the outline. A texel holds `2π²` times its area inside it, which is
/// `∫ |[u₀, u₁] ∩ [½ − ½ sin πv, ½ + ½ sin πv]| dv` over its rows: between the heights
/// where an edge of the outline crosses `u₀` or `u₁` the length is one of `u₁ − u₀`,
/// `R − u₀`, `u₁ − L`, `R − L` or 0, each integrated in closed form
/// (`∫ sin πv dv = −cos πv/π`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sinusoidal;

/// `∫_{v0}^{v1} ½ sin(πv) dv`.
#[inline]
fn half_sin_integral(v0: f64, v1: f64) -> f64 {
    0.5 * FRAC_1_PI * ((PI * v0).cos() - (PI * v1).cos())
}

impl Sinusoidal {
    /// Area in `uv` of the rectangle `[u0, u1] × [v0, v1]` inside the outline.
    fn rect_area(u0: f64, u1: f64, v0: f64, v1: f64) -> f64 {
        // Heights where the outline's half-width ½ sin πv equals |u − ½| for an edge u:
        // v = asin(2|u − ½|)/π and 1 − that.
        let mut cuts = vec![v0, v1];
        for u in [u0, u1] {
            let c = (2.0 * (u - 0.5)).abs();
            if c < 1.0 {
                let t = c.asin() * FRAC_1_PI;
                for v in [t, 1.0 - t] {
                    if v > v0 && v < v1 {
                        cuts.push(v);
                    }
                }
            }
        }
        cuts.sort_by(f64::total_cmp);
        let mut area = 0.0;
        for pair in cuts.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            if b <= a {
                continue;
            }
            // Which edges bound the row in this band: decided at its middle.
            let hw = 0.5 * (PI * 0.5 * (a + b)).sin();
            let (left, right) = (0.5 - hw, 0.5 + hw);
            if right <= u0 || left >= u1 {
                continue;
            }
            // Strictly: where an edge only touches the outline (u = 0 or 1 at v = ½), the
            // outline is the bound.
            let (l_out, r_out) = (left < u0, right > u1);
            // ∫ (min(u1, R) − max(u0, L)) dv, R = ½ + S, L = ½ − S, S = ½ sin πv.
            let s = half_sin_integral(a, b);
            let len = b - a;
            let upper = if r_out { u1 * len } else { 0.5 * len + s };
            let lower = if l_out { u0 * len } else { 0.5 * len - s };
            area += upper - lower;
        }
        area.max(0.0)
    }
}

impl WorldProjection for Sinusoidal {
    fn layer_count(&self) -> usize {
        1
    }
    fn layer_extent(&self, size: u32) -> (u32, u32) {
        (size, (size / 2).max(1))
    }
    #[inline]
    fn dir_to_uv(&self, d: DVec3) -> Option<(usize, DVec2)> {
        let (lon, lat, cp) = lon_lat(d);
        let (a, b) = (lon * cp * FRAC_1_PI, lat / FRAC_PI_2);
        Some((0, DVec2::new(0.5 * (a + 1.0), 0.5 * (1.0 - b))))
    }
    #[inline]
    fn uv_to_dir(&self, _layer: usize, uv: DVec2) -> Option<DVec3> {
        let (a, b) = (2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y);
        if b.abs() > 1.0 + 1e-12 {
            return None;
        }
        let lat = FRAC_PI_2 * b.clamp(-1.0, 1.0);
        let cp = lat.cos();
        if a.abs() > cp + 1e-12 {
            return None;
        }
        let lon = if cp > 1e-300 {
            (PI * a / cp).clamp(-PI, PI)
        } else {
            0.0
        };
        Some(dir_from_lon_lat(lon, lat))
    }
    #[inline]
    fn density(&self, _layer: usize, uv: DVec2) -> f64 {
        let (a, b) = (2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y);
        if b.abs() > 1.0 || a.abs() > (FRAC_PI_2 * b).cos() {
            0.0
        } else {
            2.0 * PI * PI
        }
    }
    #[inline]
    fn density_of_dir(&self, _dir: DVec3) -> f64 {
        2.0 * PI * PI
    }
    fn texel_solid_angle(&self, _layer: usize, x: u32, y: u32, w: u32, h: u32) -> f64 {
        let (u0, u1) = texel_range(x, w);
        let (v0, v1) = texel_range(y, h);
        2.0 * PI * PI * Sinusoidal::rect_area(u0, u1, v0, v1)
    }
    fn nearest_covered(&self, _layer: usize, uv: DVec2) -> DVec2 {
        let v = uv.y.clamp(0.0, 1.0);
        let hw = 0.5 * (PI * v).sin() * (1.0 - 1e-9);
        DVec2::new(uv.x.clamp(0.5 - hw, 0.5 + hw), v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hammer_rim_is_the_back_meridian() {
        let d = Hammer::default()
            .uv_to_dir(0, DVec2::new(1.0, 0.5))
            .unwrap();
        assert!((d - DVec3::Z).length() < 1e-9, "{d}");
        assert!(Hammer::default()
            .uv_to_dir(0, DVec2::new(0.01, 0.01))
            .is_none());
    }

    #[test]
    fn sinusoidal_outline_area_is_two_over_pi() {
        // ∫₀¹ sin πv dv = 2/π, and any split into rectangles adds up to it.
        let whole = Sinusoidal::rect_area(0.0, 1.0, 0.0, 1.0);
        assert!((whole - 2.0 / PI).abs() < 1e-15, "{whole}");
        let parts: f64 = (0..5)
            .flat_map(|i| (0..3).map(move |j| (i, j)))
            .map(|(i, j)| {
                Sinusoidal::rect_area(
                    i as f64 / 5.0,
                    (i + 1) as f64 / 5.0,
                    j as f64 / 3.0,
                    (j + 1) as f64 / 3.0,
                )
            })
            .sum();
        assert!((parts - whole).abs() < 1e-15, "{parts}");
    }
}
