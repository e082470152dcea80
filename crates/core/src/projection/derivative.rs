//! The derivatives of a projection's inverse, `∂d/∂u` and `∂d/∂v` of
//! [`WorldProjection::uv_to_dir`], by finite differences: the one home of the Jacobian that
//! the filter crate's footprints and the analysis crate's anisotropy are built on.
//!
//! Central differences in `f64` with a step of [`UV_STEP`] = `10⁻⁶` in `uv`: truncation error
//! `~δ²`, rounding `~ε/δ`, about `10⁻¹⁰` relative (the optimum of the two, `ε^{1/3} ≈ 6·10⁻⁶`,
//! is near). Two complications are handled:
//!
//! * **Domain edges** (the rim of a disk map): where a central stencil leaves the covered
//!   domain, the second-order one-sided difference `(∓3f₀ ± 4f₁ ∓ f₂)/2δ` is used instead.
//! * **Creases** (the fold lines of the octahedral maps pass through texel centres): where
//!   the forward and backward differences disagree by more than `10⁻³` relative *and* the
//!   disagreement does not shrink when the step is halved (as it would on a smooth but
//!   strongly curved map, near a singular rim), the point lies on a crease and the
//!   derivative is two-valued: [`UvDerivative::crease`] says so, and the value is the
//!   central difference (the mean of the two sides).

use super::WorldProjection;
use glam::{DVec2, DVec3};

/// The step in `uv` of the finite differences.
pub const UV_STEP: f64 = 1e-6;

/// One partial derivative of `uv_to_dir`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvDerivative {
    /// `∂d/∂s` along the step's direction (on a crease: the mean of the two sides).
    pub value: DVec3,
    /// Whether `uv` lies on a crease, where the derivative jumps.
    pub crease: bool,
}

/// `∂d/∂s` of `p`'s `uv_to_dir` at `uv` of `layer` along `e` (a unit vector in `uv`), given
/// `f0 = uv_to_dir(layer, uv)`; `None` where neither side (or the one-sided stencil) is
/// covered.
pub fn uv_derivative<P: WorldProjection + ?Sized>(
    p: &P,
    layer: usize,
    uv: DVec2,
    f0: DVec3,
    e: DVec2,
) -> Option<UvDerivative> {
    const D: f64 = UV_STEP;
    let smooth = |value| {
        Some(UvDerivative {
            value,
            crease: false,
        })
    };
    match (
        p.uv_to_dir(layer, uv + e * D),
        p.uv_to_dir(layer, uv - e * D),
    ) {
        (Some(fp), Some(fm)) => {
            let central = (fp - fm) / (2.0 * D);
            let fwd = (fp - f0) / D;
            let bwd = (f0 - fm) / D;
            let scale = fwd.length().max(bwd.length());
            let gap = (fwd - bwd).length();
            if scale > 0.0 && gap > 1e-3 * scale {
                // Smooth but strongly curved (near a singular rim), or a crease? On a smooth
                // curve the gap shrinks with the step; across a crease it does not.
                let h = 0.5 * D;
                let crease = match (
                    p.uv_to_dir(layer, uv + e * h),
                    p.uv_to_dir(layer, uv - e * h),
                ) {
                    (Some(fp2), Some(fm2)) => {
                        ((fp2 - f0) / h - (f0 - fm2) / h).length() > 0.75 * gap
                    }
                    _ => true,
                };
                return Some(UvDerivative {
                    value: central,
                    crease,
                });
            }
            smooth(central)
        }
        (Some(fp), None) => {
            let f2 = p.uv_to_dir(layer, uv + e * (2.0 * D))?;
            smooth((-3.0 * f0 + 4.0 * fp - f2) / (2.0 * D))
        }
        (None, Some(fm)) => {
            let f2 = p.uv_to_dir(layer, uv - e * (2.0 * D))?;
            smooth((3.0 * f0 - 4.0 * fm + f2) / (2.0 * D))
        }
        (None, None) => None,
    }
}

/// `(∂d/∂u, ∂d/∂v)` at `(layer, uv)` ([`uv_derivative`] along both axes; on a crease, the
/// mean of the two sides), or `None` where `uv` or both sides of it are not covered.
pub fn uv_derivatives<P: WorldProjection + ?Sized>(
    p: &P,
    layer: usize,
    uv: DVec2,
) -> Option<(DVec3, DVec3)> {
    let f0 = p.uv_to_dir(layer, uv)?;
    let du = uv_derivative(p, layer, uv, f0, DVec2::X)?;
    let dv = uv_derivative(p, layer, uv, f0, DVec2::Y)?;
    Some((du.value, dv.value))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{LatLong, Octahedral, SphereMap};

    #[test]
    fn lat_long_derivatives_match_the_closed_form() {
        // d = (sin λ cos φ, sin φ, −cos λ cos φ), λ = 2π(u − ½), φ = π(½ − v).
        let p = LatLong;
        let uv = DVec2::new(0.3, 0.4);
        let (du, dv) = uv_derivatives(&p, 0, uv).unwrap();
        let pi = std::f64::consts::PI;
        let (l, f) = (2.0 * pi * (uv.x - 0.5), pi * (0.5 - uv.y));
        let du_exact = 2.0 * pi * DVec3::new(l.cos() * f.cos(), 0.0, l.sin() * f.cos());
        let dv_exact = -pi * DVec3::new(-l.sin() * f.sin(), f.cos(), l.cos() * f.sin());
        assert!((du - du_exact).length() < 1e-8 * du_exact.length());
        assert!((dv - dv_exact).length() < 1e-8 * dv_exact.length());
    }

    #[test]
    fn octahedral_folds_are_creases_and_the_rim_is_one_sided() {
        let o = Octahedral;
        let uv = DVec2::new(0.5, 0.3); // on the fold a = 0
        let f0 = o.uv_to_dir(0, uv).unwrap();
        assert!(uv_derivative(&o, 0, uv, f0, DVec2::X).unwrap().crease);
        assert!(!uv_derivative(&o, 0, uv, f0, DVec2::Y).unwrap().crease);
        // A sphere map's rim: only the inside is covered.
        let s = SphereMap::default();
        let uv = DVec2::new(0.5, 0.5 + 0.5 * (1.0 - 1e-5));
        assert!(uv_derivatives(&s, 0, uv).is_some());
    }
}
