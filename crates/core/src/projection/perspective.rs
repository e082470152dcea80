//! Views: a camera's picture of part of the sphere, aimed by yaw, pitch and roll. The
//! rectilinear (perspective, gnomonic) picture of an ordinary lens, and Sharpless, Postle &
//! German's Pannini (*Pannini: a new projection for rendering wide angle perspective
//! images*, 2010), of which the rectilinear is the case `d = 0`. FFmpeg's `v360` calls them
//! `flat` (also `rectilinear`, `gnomonic`) and `pannini`; its `perspective` is another
//! projection (the globe seen from a finite distance), not this one.
//!
//! In the camera's frame (`x` right, `y` up, `z` forward), a direction at view longitude
//! `φ = atan2(x, z)` and latitude `θ = atan2(y, √(x² + z²))` lands at
//! `X = S sin φ`, `Y = S tan θ`, `S = (d + 1)/(d + cos φ)`; with `h = √(x² + z²)` that is
//! `(X, Y) = (d + 1)(x, y)/(d·h + z)`, no trigonometry. The picture is
//! `[−X_max, X_max] × [−Y_max, Y_max]`, `a = X/X_max = 2u − 1`, `b = Y/Y_max = 1 − 2v`,
//! `X_max = X(hfov/2)`, `Y_max = tan(vfov/2)`. Inverse: with `k = X²/(d + 1)²`,
//! `cos φ = (−kd + √(1 + k(1 − d²)))/(k + 1)` (the root of
//! `(k + 1)c² + 2kdc + kd² − 1 = 0` that is 1 at `X = 0`), then `sin φ = X/S` and
//! `tan θ = Y/S`.
//!
//! Area: `∂X/∂φ = (d + 1)(1 + d cos φ)/(d + cos φ)²` and `∂Y/∂θ = S/cos²θ`, so
//! `dω = cos θ dθ dφ = cos³θ (d + cos φ)³/((d + 1)²(1 + d cos φ)) dX dY`. A texel spans
//! view longitudes `[φ₀, φ₁]` (X depends on φ alone) and, at each φ, `Y ∈ [Y₀, Y₁]`, so it
//! holds `∫ (Y₁/√(S² + Y₁²) − Y₀/√(S² + Y₀²)) dφ` (as `sin θ = Y/√(S² + Y²)`), by
//! Gauss–Legendre; for `d = 0` the closed form of a rectangle on a tangent plane, as for a
//! cube face.

use super::cube::cube_area;
use super::quadrature::gauss_legendre;
use super::{texel_range, DirRun, Frame, Range, WorldProjection};
use glam::{DMat3, DVec2, DVec3};

/// A rectilinear or Pannini view (see the module documentation).
///
/// ```
/// use mirrorball_core::{View, WorldProjection};
/// use glam::{DVec2, DVec3};
/// let v = View::perspective(90.0, 90.0, 0.0, 0.0, 0.0).unwrap();
/// // The right edge's middle is 45° to the right of straight ahead.
/// let d = v.uv_to_dir(0, DVec2::new(1.0, 0.5)).unwrap();
/// assert!((d - DVec3::new(1.0, 0.0, -1.0).normalize()).length() < 1e-12);
/// assert!(v.dir_to_uv(DVec3::Z).is_none());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    frame: Frame,
    /// Pannini's distance `d` (0: rectilinear).
    d: f64,
    pannini: bool,
    x_max: f64,
    y_max: f64,
    /// `cos(hfov/2)`: directions further round are not covered.
    cos_half_h: f64,
    /// `hfov, vfov, yaw, pitch, roll`, degrees, as given.
    angles: [f64; 5],
}

impl View {
    /// A rectilinear view with fields of view `0 < hfov, vfov < 180` degrees, aimed by
    /// `yaw` (degrees to the right), `pitch` (up) and `roll` (see [`View::frame_of`]).
    pub fn perspective(hfov: f64, vfov: f64, yaw: f64, pitch: f64, roll: f64) -> Option<View> {
        View::new(false, 0.0, [hfov, vfov, yaw, pitch, roll])
    }

    /// A Pannini view with distance `d ≥ 0`; `hfov` must stay below the widest the
    /// projection draws one to one (`2 acos(−d)` for `d ≤ 1`, `2 acos(−1/d)` beyond), and
    /// `0 < vfov < 180`.
    pub fn pannini(d: f64, hfov: f64, vfov: f64, yaw: f64, pitch: f64, roll: f64) -> Option<View> {
        View::new(true, d, [hfov, vfov, yaw, pitch, roll])
    }

    /// The vertical fields of view, in degrees: `(0°, 180°)`.
    pub const VFOV: Range = Range::above(0.0).below(180.0).unit("°");

    /// Pannini's distances: `[0, ∞)` (0 is the rectilinear view).
    pub const DISTANCE: Range = Range::from(0.0);

    /// The horizontal fields of view, in degrees, a view with Pannini distance `d` draws
    /// (`(0°, 180°)` for the rectilinear view, `d = 0`): below [`View::max_hfov_deg`].
    pub fn hfov_range(d: f64) -> Range {
        Range::above(0.0).below(View::max_hfov_deg(d)).unit("°")
    }

    /// The widest horizontal field of view, in degrees, Pannini's `d` draws one to one
    /// (`X` grows with φ while `1 + d cos φ > 0` and `d + cos φ > 0`).
    pub fn max_hfov_deg(d: f64) -> f64 {
        let c = if d > 1.0 { -1.0 / d } else { -d };
        2.0 * c.acos().to_degrees()
    }

    fn new(pannini: bool, d: f64, angles: [f64; 5]) -> Option<View> {
        let [hfov, vfov, yaw, pitch, roll] = angles;
        if !(d.is_finite() && View::DISTANCE.contains(d) && angles.iter().all(|a| a.is_finite())) {
            return None;
        }
        if !(View::hfov_range(d).contains(hfov) && View::VFOV.contains(vfov)) {
            return None;
        }
        let half = 0.5 * hfov.to_radians();
        let (sh, ch) = half.sin_cos();
        Some(View {
            frame: Frame::turned(View::frame_of(yaw, pitch, roll)),
            d,
            pannini,
            x_max: (d + 1.0) * sh / (d + ch),
            y_max: (0.5 * vfov.to_radians()).tan(),
            cos_half_h: ch,
            angles,
        })
    }

    /// The camera's orientation (columns: where its right, up and backward axes point) for
    /// `yaw`, `pitch`, `roll` in degrees, as FFmpeg's `v360` aims its output (rotation order
    /// `ypr`; `calculate_rotation_matrix` and `v360_slice` in libavfilter/vf_v360.c): the
    /// roll about the view axis first, then the pitch up, then the yaw to the right. In
    /// `v360`'s axes (`x` right, `y` down, `z` forward, i.e. mirrorball's `(x, −y, −z)`) its
    /// matrix is `Y(yaw)·P(pitch)·R(roll)`; carried over, that is
    /// `R_y(−yaw)·R_x(pitch)·R_z(−roll)` in mirrorball's right-handed, +Y-up world.
    pub fn frame_of(yaw: f64, pitch: f64, roll: f64) -> DMat3 {
        DMat3::from_rotation_y(-yaw.to_radians())
            * DMat3::from_rotation_x(pitch.to_radians())
            * DMat3::from_rotation_z(-roll.to_radians())
    }

    /// Where the view looks: its right, up and forward axes.
    pub fn frame(&self) -> &Frame {
        &self.frame
    }
    /// The picture plane's half extents `(X_max, Y_max)`: `a = X/X_max`, `b = Y/Y_max`.
    pub fn plane_extent(&self) -> (f64, f64) {
        (self.x_max, self.y_max)
    }
    /// `cos(hfov/2)`: a direction whose view-frame `z < √(x² + z²)·cos(hfov/2)` is not
    /// covered.
    pub fn cos_half_hfov(&self) -> f64 {
        self.cos_half_h
    }
    /// Whether this is a Pannini view (otherwise rectilinear).
    pub fn is_pannini(&self) -> bool {
        self.pannini
    }
    /// Pannini's distance `d` (0 for a rectilinear view).
    pub fn distance(&self) -> f64 {
        self.d
    }
    /// `[hfov, vfov, yaw, pitch, roll]` in degrees.
    pub fn angles_deg(&self) -> [f64; 5] {
        self.angles
    }

    /// `(X, Y)` on the picture plane of the camera-frame direction `l`, or `None` where the
    /// view does not reach.
    #[inline]
    fn plane_of_local(&self, l: DVec3) -> Option<DVec2> {
        let h = (l.x * l.x + l.z * l.z).sqrt();
        let den = self.d * h + l.z;
        if den <= 0.0 || l.z < h * self.cos_half_h - 1e-12 {
            return None;
        }
        Some(DVec2::new(l.x, l.y) * ((self.d + 1.0) / den))
    }

    /// The camera-frame direction (not normalised) at picture-plane point `(X, Y)`, and
    /// `S`, `cos φ`.
    #[inline]
    fn local_of_plane(&self, p: DVec2) -> (DVec3, f64, f64) {
        let d = self.d;
        let d1 = d + 1.0;
        let k = p.x * p.x / (d1 * d1);
        let c = (-k * d + (1.0 + k * (1.0 - d * d)).max(0.0).sqrt()) / (k + 1.0);
        let s = d1 / (d + c);
        // (sin φ, tan θ, cos φ) = (X/S, Y/S, cos φ): a direction times 1/cos θ.
        (DVec3::new(p.x / s, p.y / s, c), s, c)
    }

    /// The density (`dω/du dv`) where the picture plane's point is `l` (`local_of_plane`'s
    /// direction over cos θ) and its `cos φ` is `c`.
    #[inline]
    fn density_at(&self, l: DVec3, c: f64) -> f64 {
        // l = (sin φ, tan θ, cos φ): cos θ = 1/√(1 + tan²θ).
        let cos_t = 1.0 / (1.0 + l.y * l.y).sqrt();
        let d = self.d;
        let jac = cos_t.powi(3) * (d + c).powi(3) / ((d + 1.0).powi(2) * (1.0 + d * c));
        4.0 * self.x_max * self.y_max * jac
    }

    /// View longitude φ at picture-plane abscissa `X`.
    #[inline]
    fn phi_of_x(&self, x: f64) -> f64 {
        let (l, _, _) = self.local_of_plane(DVec2::new(x, 0.0));
        l.x.atan2(l.z)
    }

    /// Solid angle of the picture-plane rectangle `[x0, x1] × [y0, y1]`.
    fn plane_rect_solid_angle(&self, x0: f64, x1: f64, y0: f64, y1: f64) -> f64 {
        if self.d == 0.0 {
            return (cube_area(x1, y1) - cube_area(x0, y1) - cube_area(x1, y0) + cube_area(x0, y0))
                .abs();
        }
        let (p0, p1) = (self.phi_of_x(x0), self.phi_of_x(x1));
        let d = self.d;
        let f = |phi: f64| {
            let s = (d + 1.0) / (d + phi.cos());
            y1 / (s * s + y1 * y1).sqrt() - y0 / (s * s + y0 * y0).sqrt()
        };
        // A few panels: the integrand is smooth, and one panel per texel already gives
        // 1e-15; wide spans (the whole picture) get more.
        let panels = ((p1 - p0).abs() / 0.05).ceil().clamp(1.0, 256.0) as usize;
        let step = (p1 - p0) / panels as f64;
        (0..panels)
            .map(|i| {
                let a = p0 + step * i as f64;
                gauss_legendre(a, a + step, f)
            })
            .sum::<f64>()
            .abs()
    }
}

impl WorldProjection for View {
    fn layer_count(&self) -> usize {
        1
    }
    /// `size` wide, `size·Y_max/X_max` high: square texels at the centre (`dX/dφ = dY/dθ =
    /// 1` there).
    fn layer_extent(&self, size: u32) -> (u32, u32) {
        let h = (size as f64 * self.y_max / self.x_max).round().max(1.0);
        (size, h as u32)
    }
    #[inline]
    fn dir_to_uv(&self, dir: DVec3) -> Option<(usize, DVec2)> {
        let p = self.plane_of_local(self.frame.to_local(dir))?;
        let (a, b) = (p.x / self.x_max, p.y / self.y_max);
        if a.abs() > 1.0 + 1e-12 || b.abs() > 1.0 + 1e-12 {
            return None;
        }
        let (a, b) = (a.clamp(-1.0, 1.0), b.clamp(-1.0, 1.0));
        Some((0, DVec2::new(0.5 * (a + 1.0), 0.5 * (1.0 - b))))
    }
    #[inline]
    fn uv_to_dir(&self, _layer: usize, uv: DVec2) -> Option<DVec3> {
        let (a, b) = (2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y);
        if a.abs() > 1.0 + 1e-12 || b.abs() > 1.0 + 1e-12 {
            return None;
        }
        let (l, _, _) = self.local_of_plane(DVec2::new(a * self.x_max, b * self.y_max));
        let f = &self.frame;
        Some((f.right * l.x + f.up * l.y + f.forward * l.z).normalize())
    }
    #[inline]
    fn density(&self, _layer: usize, uv: DVec2) -> f64 {
        let (a, b) = (2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y);
        if a.abs() > 1.0 || b.abs() > 1.0 {
            return 0.0;
        }
        let (l, _, c) = self.local_of_plane(DVec2::new(a * self.x_max, b * self.y_max));
        self.density_at(l, c)
    }
    /// A rectilinear view's directions and densities in closed form (Pannini's through
    /// `span_dirs`): the plane point `(X, Y, 1)` in the view's frame is the direction's
    /// multiple, `|(X, Y, 1)|² = 1 + X² + Y²`, and the density `4·X_max·Y_max/(1 + X² +
    /// Y²)^{3/2}`; `U·Y + F` once a row.
    fn span_dirs_f32(&self, layer: usize, y: u32, w: u32, h: u32, x0: u32, out: DirRun) {
        if self.d != 0.0 {
            return super::span_dirs_f32_of(self, layer, y, (w, h), x0, out);
        }
        let b = 1.0 - 2.0 * ((y as f64 + 0.5) / h as f64);
        let f = &self.frame;
        let yy = b * self.y_max;
        let row = f.up * yy + f.forward;
        let scale = 4.0 * self.x_max * self.y_max;
        for (i, (x, y, z, d)) in out.texels().enumerate() {
            let u = ((x0 as usize + i) as f64 + 0.5) / w as f64;
            let a = 2.0 * u - 1.0;
            if a.abs() > 1.0 + 1e-12 || b.abs() > 1.0 + 1e-12 {
                (*x, *y, *z, *d) = (0.0, 0.0, 1.0, -1.0);
                continue;
            }
            let xx = a * self.x_max;
            let inv = 1.0 / (1.0 + xx * xx + yy * yy).sqrt();
            let dir = (f.right * xx + row) * inv;
            let density = if a.abs() > 1.0 || b.abs() > 1.0 {
                0.0
            } else {
                scale * inv * inv * inv
            };
            (*x, *y, *z, *d) = (dir.x as f32, dir.y as f32, dir.z as f32, density as f32);
        }
    }
    /// `uv_to_dir` and `density` of each texel centre of the run, the same bits, with the
    /// picture-plane point worked out once a texel (the planner's loop over a view).
    fn span_dirs(
        &self,
        _layer: usize,
        y: u32,
        w: u32,
        h: u32,
        x0: u32,
        out: &mut [Option<(DVec3, f64)>],
    ) {
        let b = 1.0 - 2.0 * ((y as f64 + 0.5) / h as f64);
        if b.abs() > 1.0 + 1e-12 {
            out.fill(None);
            return;
        }
        let f = &self.frame;
        for (i, o) in out.iter_mut().enumerate() {
            let u = ((x0 as usize + i) as f64 + 0.5) / w as f64;
            let a = 2.0 * u - 1.0;
            if a.abs() > 1.0 + 1e-12 {
                *o = None;
                continue;
            }
            let (l, _, c) = self.local_of_plane(DVec2::new(a * self.x_max, b * self.y_max));
            let dir = (f.right * l.x + f.up * l.y + f.forward * l.z).normalize();
            let density = if a.abs() > 1.0 || b.abs() > 1.0 {
                0.0
            } else {
                self.density_at(l, c)
            };
            *o = Some((dir, density));
        }
    }
    fn texel_solid_angle(&self, _layer: usize, x: u32, y: u32, w: u32, h: u32) -> f64 {
        let (u0, u1) = texel_range(x, w);
        let (v0, v1) = texel_range(y, h);
        self.plane_rect_solid_angle(
            (2.0 * u0 - 1.0) * self.x_max,
            (2.0 * u1 - 1.0) * self.x_max,
            (1.0 - 2.0 * v1) * self.y_max,
            (1.0 - 2.0 * v0) * self.y_max,
        )
    }
    fn covered_solid_angle(&self) -> f64 {
        self.plane_rect_solid_angle(-self.x_max, self.x_max, -self.y_max, self.y_max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn span_dirs_f32_are_uv_to_dir_and_density() {
        // A rectilinear view in closed form, a Pannini one through span_dirs: within f32's
        // rounding of the f64 methods.
        for view in [
            View::perspective(90.0, 90.0, 0.0, 0.0, 0.0).unwrap(),
            View::perspective(120.0, 70.0, 10.0, -20.0, 5.0).unwrap(),
            View::pannini(0.7, 150.0, 80.0, 30.0, 10.0, -5.0).unwrap(),
        ] {
            let (w, h) = (41, 29);
            for y in 0..h {
                let n = w as usize - 3;
                let (mut xs, mut ys, mut zs, mut ds) =
                    (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
                let run = DirRun {
                    x: &mut xs,
                    y: &mut ys,
                    z: &mut zs,
                    density: &mut ds,
                };
                view.span_dirs_f32(0, y, w, h, 3, run);
                for i in 0..n {
                    let x = 3 + i as u32;
                    let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                    let want = view.uv_to_dir(0, uv).unwrap();
                    let got = DVec3::new(xs[i] as f64, ys[i] as f64, zs[i] as f64);
                    assert!((got - want).length() < 2e-7, "({x}, {y}): {got} vs {want}");
                    let dens = view.density(0, uv);
                    assert!(
                        (ds[i] as f64 - dens).abs() < 2e-7 * dens,
                        "({x}, {y}): {} vs {dens}",
                        ds[i]
                    );
                }
            }
        }
    }

    #[test]
    fn span_dirs_are_uv_to_dir_and_density_bit_for_bit() {
        let views = [
            View::perspective(90.0, 90.0, 0.0, 0.0, 0.0).unwrap(),
            View::perspective(100.0, 70.0, 10.0, -20.0, 5.0).unwrap(),
            View::pannini(0.7, 150.0, 80.0, 30.0, 10.0, -5.0).unwrap(),
        ];
        for view in views {
            let (w, h) = (37, 23);
            for y in 0..h {
                let mut run = vec![None; 40];
                view.span_dirs(0, y, w, h, 5, &mut run);
                for (i, got) in run.iter().enumerate() {
                    let x = 5 + i as u32;
                    let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                    let want = view.uv_to_dir(0, uv).map(|d| (d, view.density(0, uv)));
                    // Past the right edge (x ≥ w) there is no direction, as uv_to_dir says.
                    assert_eq!(*got, want, "({x}, {y})");
                    assert_eq!(got.is_some(), x < w, "({x}, {y})");
                }
            }
        }
    }

    #[test]
    fn pannini_with_d_zero_is_rectilinear() {
        let p = View::pannini(0.0, 100.0, 70.0, 10.0, -20.0, 5.0).unwrap();
        let r = View::perspective(100.0, 70.0, 10.0, -20.0, 5.0).unwrap();
        for uv in [
            DVec2::new(0.1, 0.2),
            DVec2::new(0.7, 0.9),
            DVec2::splat(0.5),
        ] {
            let (a, b) = (p.uv_to_dir(0, uv).unwrap(), r.uv_to_dir(0, uv).unwrap());
            assert!((a - b).length() < 1e-12);
            assert!((p.density(0, uv) / r.density(0, uv) - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn aims_as_v360_does() {
        // yaw turns right, pitch up.
        let v = View::perspective(90.0, 90.0, 90.0, 0.0, 0.0).unwrap();
        let c = v.uv_to_dir(0, DVec2::splat(0.5)).unwrap();
        assert!((c - DVec3::X).length() < 1e-12, "{c}");
        let v = View::perspective(90.0, 90.0, 0.0, 30.0, 0.0).unwrap();
        let c = v.uv_to_dir(0, DVec2::splat(0.5)).unwrap();
        assert!((c.y - 0.5).abs() < 1e-12, "{c}");
    }

    #[test]
    fn refuses_what_it_cannot_draw() {
        assert!(View::perspective(180.0, 90.0, 0.0, 0.0, 0.0).is_none());
        assert!(View::perspective(90.0, 0.0, 0.0, 0.0, 0.0).is_none());
        assert!(View::pannini(1.0, 360.0, 90.0, 0.0, 0.0, 0.0).is_none());
        assert!(View::pannini(1.0, 300.0, 90.0, 0.0, 0.0, 0.0).is_some());
        assert!(View::pannini(-1.0, 90.0, 90.0, 0.0, 0.0, 0.0).is_none());
        assert!((View::max_hfov_deg(0.0) - 180.0).abs() < 1e-12);
        assert!((View::max_hfov_deg(2.0) - 240.0).abs() < 1e-9);
    }

    #[test]
    fn the_whole_picture_is_the_sum_of_its_texels() {
        let v = View::pannini(1.5, 200.0, 100.0, 0.0, 0.0, 0.0).unwrap();
        let (w, h) = (9, 5);
        let s: f64 = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| v.texel_solid_angle(0, x, y, w, h))
            .sum();
        assert!((s / v.covered_solid_angle() - 1.0).abs() < 1e-12);
        // Rectilinear, 90°×90°: one cube face.
        let r = View::perspective(90.0, 90.0, 0.0, 0.0, 0.0).unwrap();
        assert!((r.covered_solid_angle() - 4.0 * PI / 6.0).abs() < 1e-12);
    }
}
