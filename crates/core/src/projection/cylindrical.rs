//! Cylinders with a field of view: the central cylindrical projection (`tan φ` linear in
//! `v`), Lambert's cylindrical equal-area projection (`sin φ` linear in `v`) and the half
//! equirectangular (VR180) picture, the front hemisphere with both angles linear. FFmpeg's
//! `v360` calls them `cylindrical`, `cylindricalea` and `hequirect`.
//!
//! Longitude and latitude are those of [`LatLong`](super::LatLong): `λ = atan2(x, −z)` (0
//! straight ahead along −Z, growing to the right, towards +X), `φ = asin y`. With
//! `a = 2u − 1` (right) and `b = 1 − 2v` (up, row 0 at the top), `λ = a·H/2` for the
//! horizontal field of view `H`, and `g(φ) = b·k` where `g` is `tan`, `sin` or the identity
//! and `k = g(V/2)` for the vertical field of view `V`.
//!
//! Area: `dω = cos φ dφ dλ = d(sin φ) dλ`, so a texel holds exactly
//! `(H/w)·(sin φ_top − sin φ_bottom)`, and the density is `2H·d(sin φ)/db`.

use super::latlong::dir_from_lon_lat;
use super::{DirRun, Range, WorldProjection};
use glam::{DVec2, DVec3};
use std::f64::consts::TAU;

/// How latitude grows down the picture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CylinderRule {
    /// Central cylindrical: `tan φ = b·tan(V/2)` (the view from the cylinder's axis).
    Central,
    /// Lambert's equal-area cylinder: `sin φ = b·sin(V/2)`.
    EqualArea,
    /// Equidistant (equirectangular): `φ = b·V/2`.
    Equidistant,
}

/// A cylindrical projection with a horizontal and a vertical field of view (see the module
/// documentation for the formulas). Directions outside both fields of view are not covered.
///
/// ```
/// use mirrorball_core::{Cylinder, CylinderRule, WorldProjection};
/// use glam::{DVec2, DVec3};
/// let c = Cylinder::new(CylinderRule::Central, 360.0, 90.0).unwrap();
/// // The top row looks 45° up: tan φ = 1.
/// let d = c.uv_to_dir(0, DVec2::new(0.5, 0.0)).unwrap();
/// assert!((d - DVec3::new(0.0, 1.0, -1.0).normalize()).length() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylinder {
    rule: CylinderRule,
    /// Horizontal field of view `H`, radians.
    hfov: f64,
    /// Vertical field of view `V`, radians.
    vfov: f64,
    /// `g(V/2)`.
    k: f64,
}

impl Cylinder {
    /// The horizontal fields of view, in degrees: `(0°, 360°]`.
    pub const HFOV: Range = Range::above(0.0).to(360.0).unit("°");

    /// The vertical fields of view of `rule`, in degrees: `(0°, 180°)` for the central rule
    /// (which never reaches the poles), `(0°, 180°]` for the others.
    pub fn vfov_range(rule: CylinderRule) -> Range {
        let r = Range::above(0.0).unit("°");
        match rule {
            CylinderRule::Central => r.below(180.0),
            _ => r.to(180.0),
        }
    }

    /// A cylinder with fields of view in degrees, in [`Cylinder::HFOV`] and
    /// [`Cylinder::vfov_range`].
    pub fn new(rule: CylinderRule, hfov_deg: f64, vfov_deg: f64) -> Option<Cylinder> {
        if !(Cylinder::HFOV.contains(hfov_deg) && Cylinder::vfov_range(rule).contains(vfov_deg)) {
            return None;
        }
        let (hfov, vfov) = (hfov_deg.to_radians(), vfov_deg.to_radians());
        let half = 0.5 * vfov;
        let k = match rule {
            CylinderRule::Central => half.tan(),
            CylinderRule::EqualArea => half.sin(),
            CylinderRule::Equidistant => half,
        };
        Some(Cylinder {
            rule,
            hfov,
            vfov,
            k,
        })
    }

    /// The central cylindrical default: all the way round, 90° high.
    pub fn central() -> Cylinder {
        Cylinder::new(CylinderRule::Central, 360.0, 90.0).expect("valid")
    }

    /// Lambert's equal-area default: the whole sphere.
    pub fn equal_area() -> Cylinder {
        Cylinder::new(CylinderRule::EqualArea, 360.0, 180.0).expect("valid")
    }

    /// The half equirectangular (VR180) picture: the front hemisphere, 180° × 180°.
    pub fn half_equirect() -> Cylinder {
        Cylinder::new(CylinderRule::Equidistant, 180.0, 180.0).expect("valid")
    }

    /// The rule.
    pub fn rule(&self) -> CylinderRule {
        self.rule
    }
    /// `g(V/2)` (tan, sin or the identity of half the vertical field of view): the
    /// picture height `b = g(φ)/g(V/2)`.
    pub fn height_scale(&self) -> f64 {
        self.k
    }
    /// Horizontal field of view, degrees.
    pub fn hfov_deg(&self) -> f64 {
        self.hfov.to_degrees()
    }
    /// Vertical field of view, degrees.
    pub fn vfov_deg(&self) -> f64 {
        self.vfov.to_degrees()
    }

    /// Whether the picture goes all the way round (its left and right edges meet).
    fn full_turn(&self) -> bool {
        self.hfov >= TAU * (1.0 - 1e-12)
    }

    /// Latitude at picture height `b ∈ [−1, 1]`.
    #[inline]
    fn lat_of_b(&self, b: f64) -> f64 {
        match self.rule {
            CylinderRule::Central => (b * self.k).atan(),
            CylinderRule::EqualArea => (b * self.k).clamp(-1.0, 1.0).asin(),
            CylinderRule::Equidistant => b * self.k,
        }
    }

    /// `sin φ` at picture height `b`.
    #[inline]
    fn sin_lat_of_b(&self, b: f64) -> f64 {
        match self.rule {
            CylinderRule::Central => {
                let t = b * self.k;
                t / (1.0 + t * t).sqrt()
            }
            CylinderRule::EqualArea => b * self.k,
            CylinderRule::Equidistant => (b * self.k).sin(),
        }
    }

    /// `d(sin φ)/db` at picture height `b`.
    #[inline]
    fn dsin_db(&self, b: f64) -> f64 {
        match self.rule {
            CylinderRule::Central => {
                let t = b * self.k;
                self.k / (1.0 + t * t).powf(1.5)
            }
            CylinderRule::EqualArea => self.k,
            CylinderRule::Equidistant => self.k * (b * self.k).cos(),
        }
    }

    /// Picture height `b` of unit direction `d` (given `h = √(x² + z²) = cos φ`), or `None`
    /// beyond the vertical field of view.
    #[inline]
    fn b_of_dir(&self, d: DVec3, h: f64) -> Option<f64> {
        let b = match self.rule {
            CylinderRule::Central => {
                if h <= 0.0 {
                    return None;
                }
                d.y / h / self.k
            }
            CylinderRule::EqualArea => d.y / self.k,
            CylinderRule::Equidistant => d.y.atan2(h) / self.k,
        };
        (b.abs() <= 1.0 + 1e-12).then_some(b.clamp(-1.0, 1.0))
    }
}

impl WorldProjection for Cylinder {
    fn layer_count(&self) -> usize {
        1
    }
    /// `size` wide, and high enough that the texel at the centre is square:
    /// `h = w·2k/H` (`dφ/db = k` at the equator for all three rules).
    fn layer_extent(&self, size: u32) -> (u32, u32) {
        let h = (size as f64 * 2.0 * self.k / self.hfov).round().max(1.0);
        (size, h as u32)
    }
    #[inline]
    fn dir_to_uv(&self, d: DVec3) -> Option<(usize, DVec2)> {
        let h = (d.x * d.x + d.z * d.z).sqrt();
        let lon = d.x.atan2(-d.z);
        let a = 2.0 * lon / self.hfov;
        if a.abs() > 1.0 + 1e-12 {
            return None;
        }
        let b = self.b_of_dir(d, h)?;
        Some((
            0,
            DVec2::new(0.5 * (a.clamp(-1.0, 1.0) + 1.0), 0.5 * (1.0 - b)),
        ))
    }
    #[inline]
    fn uv_to_dir(&self, _layer: usize, uv: DVec2) -> Option<DVec3> {
        let (a, b) = (2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y);
        if a.abs() > 1.0 + 1e-12 || b.abs() > 1.0 + 1e-12 {
            return None;
        }
        Some(dir_from_lon_lat(
            0.5 * a * self.hfov,
            self.lat_of_b(b.clamp(-1.0, 1.0)),
        ))
    }
    #[inline]
    fn density(&self, _layer: usize, uv: DVec2) -> f64 {
        let (a, b) = (2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y);
        if a.abs() > 1.0 || b.abs() > 1.0 {
            return 0.0;
        }
        2.0 * self.hfov * self.dsin_db(b)
    }
    fn texel_solid_angle(&self, _layer: usize, _x: u32, y: u32, w: u32, h: u32) -> f64 {
        let b_top = 1.0 - 2.0 * y as f64 / h as f64;
        let b_bot = 1.0 - 2.0 * (y as f64 + 1.0) / h as f64;
        self.hfov / w as f64 * (self.sin_lat_of_b(b_top) - self.sin_lat_of_b(b_bot))
    }
    fn covered_solid_angle(&self) -> f64 {
        2.0 * self.hfov * self.sin_lat_of_b(1.0)
    }
    fn span_dirs(
        &self,
        _layer: usize,
        y: u32,
        w: u32,
        h: u32,
        x0: u32,
        out: &mut [Option<(DVec3, f64)>],
    ) {
        // Latitude and density are fixed along a row.
        let b = 1.0 - 2.0 * (y as f64 + 0.5) / h as f64;
        let (sp, cp) = self.lat_of_b(b).sin_cos();
        let dens = 2.0 * self.hfov * self.dsin_db(b);
        for (i, o) in out.iter_mut().enumerate() {
            let a = 2.0 * (x0 as f64 + i as f64 + 0.5) / w as f64 - 1.0;
            let (sl, cl) = (0.5 * a * self.hfov).sin_cos();
            *o = Some((DVec3::new(sl * cp, sp, -cl * cp), dens));
        }
    }
    fn span_dirs_f32(&self, _layer: usize, y: u32, w: u32, h: u32, x0: u32, out: DirRun) {
        let b = 1.0 - 2.0 * (y as f64 + 0.5) / h as f64;
        let (sp, cp) = self.lat_of_b(b).sin_cos();
        let dens = (2.0 * self.hfov * self.dsin_db(b)) as f32;
        for (i, (x, y, z, d)) in out.texels().enumerate() {
            let a = 2.0 * (x0 as f64 + i as f64 + 0.5) / w as f64 - 1.0;
            let (sl, cl) = (0.5 * a * self.hfov).sin_cos();
            (*x, *y, *z, *d) = ((sl * cp) as f32, sp as f32, (-cl * cp) as f32, dens);
        }
    }
    fn wrap_texel(&self, layer: usize, x: i64, y: i64, w: u32, h: u32) -> (usize, u32, u32) {
        let (w_, h_) = (w as i64, h as i64);
        let x = if self.full_turn() {
            x.rem_euclid(w_)
        } else {
            x.clamp(0, w_ - 1)
        };
        (layer, x as u32, y.clamp(0, h_ - 1) as u32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn refuses_fields_of_view_it_cannot_draw() {
        assert!(Cylinder::new(CylinderRule::Central, 360.0, 180.0).is_none());
        assert!(Cylinder::new(CylinderRule::EqualArea, 361.0, 90.0).is_none());
        assert!(Cylinder::new(CylinderRule::Equidistant, 90.0, 0.0).is_none());
        assert!(Cylinder::new(CylinderRule::EqualArea, 360.0, 180.0).is_some());
    }

    #[test]
    fn equal_area_texels_are_equal() {
        let c = Cylinder::equal_area();
        let (w, h) = c.layer_extent(64);
        assert_eq!((w, h), (64, 20)); // 64/π
        let first = c.texel_solid_angle(0, 0, 0, w, h);
        for y in 0..h {
            assert!((c.texel_solid_angle(0, 3, y, w, h) / first - 1.0).abs() < 1e-12);
        }
        assert!((first * (w * h) as f64 - 4.0 * PI).abs() < 1e-12);
    }

    #[test]
    fn half_equirect_is_the_front_hemisphere() {
        let c = Cylinder::half_equirect();
        assert_eq!(c.layer_extent(100), (100, 100));
        assert!(c.dir_to_uv(DVec3::Z).is_none());
        let (_, uv) = c.dir_to_uv(DVec3::X).unwrap();
        assert!((uv - DVec2::new(1.0, 0.5)).length() < 1e-12);
        assert!((c.covered_solid_angle() - 2.0 * PI).abs() < 1e-12);
    }
}
