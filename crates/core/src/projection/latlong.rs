//! Cylindrical projections: latitude-longitude (Blinn & Newell 1976) and Mercator (Miller &
//! Hoffman 1984, Greene 1986 §6).

use super::fastmath;
use super::{texel_range, DirRun, Lookup, Range, WorldProjection};
use glam::{DVec2, DVec3};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Longitude `λ ∈ [-π, π]` of `u`: `u = ½` faces −Z (straight ahead of the default camera),
/// and longitude grows to the right as seen from the centre of the sphere with +Y up, so
/// `u = ¾` faces +X and `u = ¼` faces −X; `u = 0` and `u = 1` both face +Z (the seam).
#[inline]
fn lon_of_u(u: f64) -> f64 {
    TAU * (u - 0.5)
}

/// The unit direction at longitude `lon` and latitude `lat` (radians), as [`LatLong`] reads
/// them.
#[inline]
pub(super) fn dir_from_lon_lat(lon: f64, lat: f64) -> DVec3 {
    let (sl, cl) = lon.sin_cos();
    let (sp, cp) = lat.sin_cos();
    DVec3::new(sl * cp, sp, -cl * cp)
}

#[inline]
fn u_of_dir(d: DVec3) -> f64 {
    fastmath::atan2(d.x, -d.z) / TAU + 0.5
}

/// Mirrors a texel index around the longitude wrap and over the poles.
#[inline]
fn wrap_cylinder(x: i64, y: i64, w: u32, h: u32) -> (u32, u32) {
    let (w, h) = (w as i64, h as i64);
    let (mut x, mut y) = (x, y);
    if y < 0 {
        y = -1 - y;
        x += w / 2;
    } else if y >= h {
        y = 2 * h - 1 - y;
        x += w / 2;
    }
    (x.rem_euclid(w) as u32, y.clamp(0, h - 1) as u32)
}

/// The latitude-longitude (equirectangular) projection: `u` is longitude, `v` latitude,
/// both linear; row 0 is the +Y pole (the sky). See the longitude convention at
/// `lon_of_u`: the middle of the picture looks along −Z, +X is to the right of it.
///
/// `d = (sin λ cos φ, sin φ, −cos λ cos φ)` with `λ = 2π(u − ½)`, `φ = π(½ − v)`;
/// `dω = cos φ dφ dλ = 2π² cos φ du dv`, so a texel row between latitudes φ₀ < φ₁ holds
/// `Δλ (sin φ₁ − sin φ₀)` per texel, exactly.
///
/// ```
/// use mirrorball_core::{LatLong, WorldProjection};
/// use glam::{DVec2, DVec3};
/// let d = LatLong.uv_to_dir(0, DVec2::new(0.75, 0.5)).unwrap();
/// assert!((d - DVec3::X).length() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LatLong;

impl WorldProjection for LatLong {
    fn layer_count(&self) -> usize {
        1
    }
    fn layer_extent(&self, size: u32) -> (u32, u32) {
        (size, (size / 2).max(1))
    }
    #[inline]
    fn dir_to_uv(&self, d: DVec3) -> Option<(usize, DVec2)> {
        // asin(y) as atan2(y, √(x² + z²)): accurate near the poles too.
        let lat = fastmath::atan2(d.y, (d.x * d.x + d.z * d.z).sqrt());
        Some((0, DVec2::new(u_of_dir(d), 0.5 - lat / PI)))
    }
    #[inline]
    fn uv_to_dir(&self, _layer: usize, uv: DVec2) -> Option<DVec3> {
        Some(dir_from_lon_lat(lon_of_u(uv.x), PI * (0.5 - uv.y)))
    }
    #[inline]
    fn density(&self, _layer: usize, uv: DVec2) -> f64 {
        let lat = PI * (0.5 - uv.y);
        if lat.abs() > FRAC_PI_2 {
            return 0.0;
        }
        2.0 * PI * PI * lat.cos()
    }
    #[inline]
    fn density_of_dir(&self, d: DVec3) -> f64 {
        2.0 * PI * PI * (d.x * d.x + d.z * d.z).sqrt()
    }
    fn lookup_batch(&self, xs: &[f32], ys: &[f32], zs: &[f32], out: &mut [Lookup]) {
        use std::f32::consts::{PI as PI32, TAU as TAU32};
        let k = (2.0 * PI * PI) as f32;
        let n = out.len().min(xs.len()).min(ys.len()).min(zs.len());
        let (xs, ys, zs) = (&xs[..n], &ys[..n], &zs[..n]);
        for (i, o) in out[..n].iter_mut().enumerate() {
            let (x, y, z) = (xs[i], ys[i], zs[i]);
            let hz = (x * x + z * z).sqrt();
            let u = fastmath::atan2_f32(x, -z) * (1.0 / TAU32) + 0.5;
            let v = 0.5 - fastmath::atan2_f32(y, hz) * (1.0 / PI32);
            *o = Lookup {
                layer: 0,
                u,
                v,
                density: k * hz,
            };
        }
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
        // Latitude is fixed along a row; longitude advances by a fixed step, so its sine and
        // cosine follow by the angle-addition recurrence (drift < 1e-12 over 65536 steps).
        let (sp, cp) = (PI * (0.5 - (y as f64 + 0.5) / h as f64)).sin_cos();
        let dens = 2.0 * PI * PI * cp;
        let step = TAU / w as f64;
        let (sd, cd) = step.sin_cos();
        let (mut s, mut c) = lon_of_u((x0 as f64 + 0.5) / w as f64).sin_cos();
        for o in out.iter_mut() {
            *o = Some((DVec3::new(s * cp, sp, -c * cp), dens));
            (s, c) = (s * cd + c * sd, c * cd - s * sd);
        }
    }
    fn span_dirs_f32(&self, _layer: usize, y: u32, w: u32, h: u32, x0: u32, out: DirRun) {
        // As span_dirs, written out in f32.
        let (sp, cp) = (PI * (0.5 - (y as f64 + 0.5) / h as f64)).sin_cos();
        let dens = (2.0 * PI * PI * cp) as f32;
        let (sd, cd) = (TAU / w as f64).sin_cos();
        let (mut s, mut c) = lon_of_u((x0 as f64 + 0.5) / w as f64).sin_cos();
        for (x, y, z, d) in out.texels() {
            (*x, *y, *z, *d) = ((s * cp) as f32, sp as f32, (-c * cp) as f32, dens);
            (s, c) = (s * cd + c * sd, c * cd - s * sd);
        }
    }
    fn texel_solid_angle(&self, _layer: usize, x: u32, y: u32, w: u32, h: u32) -> f64 {
        let _ = x;
        let (v0, v1) = texel_range(y, h);
        let (lat_top, lat_bot) = (PI * (0.5 - v0), PI * (0.5 - v1));
        TAU / w as f64 * (lat_top.sin() - lat_bot.sin())
    }
    #[inline]
    fn wrap_texel(&self, layer: usize, x: i64, y: i64, w: u32, h: u32) -> (usize, u32, u32) {
        let (x, y) = wrap_cylinder(x, y, w, h);
        (layer, x, y)
    }
}

/// The Mercator projection with a latitude limit: `u` is longitude as in [`LatLong`], and
/// `v` is linear in the Mercator ordinate `y = ln tan(π/4 + φ/2) = atanh(sin φ)` between
/// `+Y_max` (row 0) and `−Y_max`, `Y_max = atanh(sin φ_max)`. Directions beyond `±φ_max`
/// are not covered.
///
/// Inverse: `φ = atan(sinh y)` (the Gudermannian). Area: `dφ = cos φ dy`, so
/// `dω = cos²φ dy dλ` and a texel between ordinates `y₀ < y₁` holds
/// `Δλ (tanh y₁ − tanh y₀)` exactly (since `sin φ = tanh y`).
///
/// The default limit, 85.0511°, gives `Y_max = π`: a square image, as web maps use.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mercator {
    max_lat: f64,
    y_max: f64,
}

impl Default for Mercator {
    fn default() -> Self {
        Mercator::with_ordinate_limit(PI)
    }
}

impl Mercator {
    /// The latitude limits, in degrees: `(0°, 90°)` (the poles lie at infinity).
    pub const MAX_LAT: Range = Range::above(0.0).below(90.0).unit("°");

    /// A Mercator map covering latitudes up to `max_lat_deg` degrees, in
    /// [`Mercator::MAX_LAT`].
    pub fn new(max_lat_deg: f64) -> Option<Mercator> {
        if !Mercator::MAX_LAT.contains(max_lat_deg) {
            return None;
        }
        let max_lat = max_lat_deg.to_radians();
        Some(Mercator {
            max_lat,
            y_max: max_lat.sin().atanh(),
        })
    }

    /// The Mercator map whose picture has this width and height (the aspect ratio fixes the
    /// latitude limit: `Y_max = π h / w`), or `None` for a zero size.
    pub fn from_extent(w: u32, h: u32) -> Option<Mercator> {
        (w > 0 && h > 0).then(|| Mercator::with_ordinate_limit(PI * h as f64 / w as f64))
    }

    fn with_ordinate_limit(y_max: f64) -> Mercator {
        Mercator {
            max_lat: y_max.sinh().atan(),
            y_max,
        }
    }

    /// The ordinate limit `Y_max = atanh(sin φ_max)`: `v = ½(1 − atanh(sin φ)/Y_max)`.
    pub fn ordinate_limit(&self) -> f64 {
        self.y_max
    }
    /// The latitude limit in degrees.
    pub fn max_latitude_deg(&self) -> f64 {
        self.max_lat.to_degrees()
    }

    #[inline]
    fn y_of_v(&self, v: f64) -> f64 {
        self.y_max * (1.0 - 2.0 * v)
    }
}

impl WorldProjection for Mercator {
    fn layer_count(&self) -> usize {
        1
    }
    fn layer_extent(&self, size: u32) -> (u32, u32) {
        let h = (size as f64 * self.y_max / PI).round().max(1.0);
        (size, h as u32)
    }
    #[inline]
    fn dir_to_uv(&self, d: DVec3) -> Option<(usize, DVec2)> {
        let s = d.y.clamp(-1.0, 1.0);
        if s.abs() > self.max_lat.sin() {
            return None;
        }
        let y = s.atanh();
        Some((0, DVec2::new(u_of_dir(d), 0.5 * (1.0 - y / self.y_max))))
    }
    #[inline]
    fn uv_to_dir(&self, _layer: usize, uv: DVec2) -> Option<DVec3> {
        let y = self.y_of_v(uv.y);
        if y.abs() > self.y_max * (1.0 + 1e-12) {
            return None;
        }
        Some(dir_from_lon_lat(lon_of_u(uv.x), y.sinh().atan()))
    }
    #[inline]
    fn density(&self, _layer: usize, uv: DVec2) -> f64 {
        let y = self.y_of_v(uv.y);
        if y.abs() > self.y_max {
            return 0.0;
        }
        let c = 1.0 / y.cosh(); // cos φ
        TAU * 2.0 * self.y_max * c * c
    }
    fn texel_solid_angle(&self, _layer: usize, _x: u32, y: u32, w: u32, h: u32) -> f64 {
        let (v0, v1) = texel_range(y, h);
        let (y0, y1) = (self.y_of_v(v0), self.y_of_v(v1));
        TAU / w as f64 * (y0.tanh() - y1.tanh())
    }
    fn covered_solid_angle(&self) -> f64 {
        4.0 * PI * self.max_lat.sin()
    }
    #[inline]
    fn density_of_dir(&self, d: DVec3) -> f64 {
        if d.y.abs() > self.max_lat.sin() {
            return 0.0;
        }
        4.0 * PI * self.y_max * (d.x * d.x + d.z * d.z)
    }
    fn nearest_covered(&self, _layer: usize, uv: DVec2) -> DVec2 {
        DVec2::new(uv.x, uv.y.clamp(0.0, 1.0))
    }
    #[inline]
    fn wrap_texel(&self, layer: usize, x: i64, y: i64, w: u32, h: u32) -> (usize, u32, u32) {
        let (w_, h_) = (w as i64, h as i64);
        (layer, x.rem_euclid(w_) as u32, y.clamp(0, h_ - 1) as u32)
    }
}
