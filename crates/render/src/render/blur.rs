//! Greene's camera-rotation motion blur (§9): a background pixel averages the environment
//! along the arc its ray sweeps between the previous frame's camera and this one.

use super::prepare::Prepared;
use glam::DVec3;
use mirrorball_core::WorldProjection;

impl Prepared<'_> {
    /// The average of the environment along the great-circle arc from `d0` to `d1`.
    pub(super) fn sweep(&self, d0: DVec3, d1: DVec3) -> [f32; 3] {
        let Some(env) = self.scene.environment.as_ref() else {
            return [0.0; 3];
        };
        let angle = d0.angle_between(d1);
        let m = &env.map;
        let texel = (m.projection().density_of_dir(d1) / (m.width() as f64 * m.height() as f64))
            .sqrt()
            .max(1e-9);
        let n = ((angle / texel).ceil() as usize).clamp(1, 64);
        let mut acc = [0.0f32; 3];
        for k in 0..n {
            let t = (k as f64 + 0.5) / n as f64;
            let d = slerp(d0, d1, angle, t);
            let c = self.read_dir(d).0;
            for (a, v) in acc.iter_mut().zip(c) {
                *a += v;
            }
        }
        acc.map(|a| a / n as f32)
    }
}

/// Spherical interpolation from unit `a` to unit `b`, `angle` apart, at `t`.
fn slerp(a: DVec3, b: DVec3, angle: f64, t: f64) -> DVec3 {
    if angle < 1e-9 {
        return a;
    }
    let s = angle.sin();
    if s.abs() < 1e-9 {
        return (a * (1.0 - t) + b * t).normalize_or_zero();
    }
    (a * ((1.0 - t) * angle).sin() / s + b * (t * angle).sin() / s).normalize_or_zero()
}
