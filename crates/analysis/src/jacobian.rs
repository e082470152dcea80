//! The local stretch of a projection: the Jacobian of `uv_to_dir` and its singular values.
//!
//! A texel `(x, y)` of a `w×h` layer is a unit square in *pixel* coordinates
//! `(X, Y) = (u·w, v·h)`. The projection's inverse `d(X, Y) = uv_to_dir(X/w, Y/h)` maps it
//! onto the sphere; near a point the map is linear, `dd ≈ J (dX, dY)` with the 3×2 Jacobian
//! `J = [∂d/∂X, ∂d/∂Y]`. Its singular values `σ₁ ≥ σ₂` are the largest and smallest angles
//! (in radians) one pixel step subtends in any direction, so
//!
//! * `σ₁σ₂ = |∂d/∂X × ∂d/∂Y|` is the solid angle per texel there (the projection's
//!   [`density`](mirrorball_core::WorldProjection::density) divided by `w·h`), and
//! * `σ₁/σ₂ ≥ 1` is the **anisotropy**: how much more of the world a texel sees along one
//!   direction than across it (1 for a conformal map such as a paraboloid half).
//!
//! Pixel coordinates, not `uv`, are the right measure: a 2:1 lat-long has square texels at the
//! equator, and there its anisotropy is 1.
//!
//! `J` is computed from the projection's own `uv_to_dir` (the code the converter uses) by
//! [`mirrorball_core::derivative`]'s finite differences (step `10⁻⁶` in `uv`, one-sided at
//! the rim of a disk map). Where the point lies on a crease (the fold lines of the
//! octahedral maps pass through texel centres), `J` is two-valued; the anisotropy reported
//! is the larger of the values just either side of it (a conservative choice).
//!
//! The singular values come from the 2×2 Gram matrix `G = JᵀJ`:
//! `σ²₁,₂ = (tr G ± √(tr² G − 4 det G))/2`.

use glam::{DVec2, DVec3};
use mirrorball_core::derivative::{uv_derivative, UV_STEP as DELTA};
use mirrorball_core::WorldProjection;

/// The Jacobian of a projection's inverse in pixel coordinates at one point: `[∂d/∂X, ∂d/∂Y]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Jacobian {
    /// `∂d/∂X`: change of direction per pixel step to the right.
    pub dx: DVec3,
    /// `∂d/∂Y`: change of direction per pixel step downwards.
    pub dy: DVec3,
}

impl Jacobian {
    /// The singular values `(σ₁, σ₂)`, `σ₁ ≥ σ₂ ≥ 0`: the largest and smallest angle per
    /// pixel step, in radians.
    pub fn singular_values(&self) -> (f64, f64) {
        let (a, b, c) = (
            self.dx.length_squared(),
            self.dx.dot(self.dy),
            self.dy.length_squared(),
        );
        let tr = a + c;
        // det G = |dx × dy|², computed directly for accuracy when σ₂ ≪ σ₁.
        let det = self.dx.cross(self.dy).length_squared();
        let disc = ((a - c) * (a - c) + 4.0 * b * b).sqrt();
        let l1 = 0.5 * (tr + disc);
        let s1 = l1.sqrt();
        let s2 = if l1 > 0.0 { (det / l1).sqrt() } else { 0.0 };
        (s1, s2)
    }

    /// `σ₁/σ₂` (infinite where the map degenerates).
    pub fn anisotropy(&self) -> f64 {
        let (s1, s2) = self.singular_values();
        if s2 > 0.0 {
            s1 / s2
        } else {
            f64::INFINITY
        }
    }

    /// `σ₁σ₂ = |∂d/∂X × ∂d/∂Y|`: solid angle per texel at this point.
    pub fn area(&self) -> f64 {
        self.dx.cross(self.dy).length()
    }
}

/// One partial derivative `∂d/∂s` along `e` (a unit step in `uv`), or `Err(())` on a crease.
fn derivative<P: WorldProjection + ?Sized>(
    p: &P,
    layer: usize,
    uv: DVec2,
    f0: DVec3,
    e: DVec2,
) -> Option<Result<DVec3, ()>> {
    let d = uv_derivative(p, layer, uv, f0, e)?;
    Some(if d.crease { Err(()) } else { Ok(d.value) })
}

/// The pixel-coordinate Jacobian of `p` at `uv` of `layer` for a `w×h` layer, or `None`
/// outside the covered domain or on a crease (see [`anisotropy`] for creases).
pub fn jacobian<P: WorldProjection + ?Sized>(
    p: &P,
    layer: usize,
    uv: DVec2,
    w: u32,
    h: u32,
) -> Option<Jacobian> {
    let f0 = p.uv_to_dir(layer, uv)?;
    let du = derivative(p, layer, uv, f0, DVec2::X)?.ok()?;
    let dv = derivative(p, layer, uv, f0, DVec2::Y)?.ok()?;
    Some(Jacobian {
        dx: du / w as f64,
        dy: dv / h as f64,
    })
}

/// The anisotropy `σ₁/σ₂` at `uv`, or `None` outside the covered domain. On a crease the
/// larger of the values just either side is returned.
pub fn anisotropy<P: WorldProjection + ?Sized>(
    p: &P,
    layer: usize,
    uv: DVec2,
    w: u32,
    h: u32,
) -> Option<f64> {
    anisotropy_at(p, layer, uv, p.uv_to_dir(layer, uv)?, w, h)
}

/// [`anisotropy`] when the direction at `uv`, `f0 = uv_to_dir(layer, uv)`, is known.
pub fn anisotropy_at<P: WorldProjection + ?Sized>(
    p: &P,
    layer: usize,
    uv: DVec2,
    f0: DVec3,
    w: u32,
    h: u32,
) -> Option<f64> {
    let du = derivative(p, layer, uv, f0, DVec2::X)?;
    let dv = derivative(p, layer, uv, f0, DVec2::Y)?;
    if let (Ok(du), Ok(dv)) = (du, dv) {
        return Some(
            Jacobian {
                dx: du / w as f64,
                dy: dv / h as f64,
            }
            .anisotropy(),
        );
    }
    // A crease: look just either side of it, across each axis that has one.
    let mut best: Option<f64> = None;
    for (bad, e) in [(du.is_err(), DVec2::X), (dv.is_err(), DVec2::Y)] {
        if !bad {
            continue;
        }
        for s in [-4.0, 4.0] {
            if let Some(j) = jacobian(p, layer, uv + e * (s * DELTA), w, h) {
                let a = j.anisotropy();
                best = Some(best.map_or(a, |b: f64| b.max(a)));
            }
        }
    }
    if best.is_none() {
        // Where two creases cross, step off both at once.
        for (sx, sy) in [(-4.0, -4.0), (4.0, -4.0), (-4.0, 4.0), (4.0, 4.0)] {
            if let Some(j) = jacobian(p, layer, uv + DVec2::new(sx, sy) * DELTA, w, h) {
                let a = j.anisotropy();
                best = Some(best.map_or(a, |b: f64| b.max(a)));
            }
        }
    }
    best
}
