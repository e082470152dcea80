//! Reflection lobes: the zonal kernels that prefiltered environment maps are convolved with.
//!
//! Every lobe here is *zonal*: its weight for light arriving from direction `l` depends only
//! on `c = n·l`, the cosine of the angle between `l` and the lobe's axis `n` (the surface
//! normal for Lambert, the reflection vector for Phong and GGX). A prefiltered map stores,
//! for each axis `n`,
//!
//! ```text
//!            ∫ L(l) K(n·l) dω
//! P(n) = ─────────────────────── ,
//!              ∫ K(n·l) dω
//! ```
//!
//! the kernel-weighted mean radiance. For Lambert `∫ max(n·l, 0) dω = π`, so `P = E/π`: the
//! irradiance divided by π, i.e. the radiance a white Lambertian surface reflects (Greene's
//! "diffuse illumination map", Miller & Hoffman's diffuse map). A constant environment gives
//! a constant map for every lobe (the furnace test).
//!
//! * Lambert: `K = max(c, 0)`.
//! * Phong (Miller & Hoffman 1984; Greene 1986 §7): `K = max(c, 0)^s` around the reflection
//!   vector, exponent `s`.
//! * GGX (Walter et al. 2007) in the split-sum form engines use (Karis 2013): with the view
//!   vector taken equal to the normal and to the reflection vector (`n = v = r`), the
//!   importance-sampled estimator `Σ L(l) (n·l) / Σ (n·l)` with `l` drawn from
//!   `D(h)(n·h)/(4 v·h) = D(h)/4` converges to the ratio above with
//!   `K = D(h) max(c, 0)`, `h = (n + l)/|n + l|`, `n·h = √((1 + c)/2)`, and
//!   `D(h) = α² / (π ((n·h)²(α² − 1) + 1)²)`, `α = roughness²` (perceptual roughness, as in
//!   Burley 2012, Karis 2013 and Filament).

use glam::DVec3;
use mirrorball_core::quadrature::gauss_legendre;
use std::f64::consts::PI;

/// A reflection lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Lobe {
    /// Lambert's cosine law over the hemisphere: the prefiltered value is `E/π`.
    Lambert,
    /// Phong lobe `max(r·l, 0)^exponent` (exponent ≥ 0; `f64::INFINITY` is a mirror).
    Phong {
        /// The Phong exponent `s`.
        exponent: f64,
    },
    /// GGX (Trowbridge–Reitz) in the split-sum approximation (`n = v = r`).
    Ggx {
        /// Perceptual roughness in `[0, 1]`; `α = roughness²`; 0 is a mirror.
        roughness: f64,
    },
}

/// The smallest GGX `α` treated as a lobe; below it the lobe is a mirror.
pub(crate) const MIN_ALPHA: f64 = 1e-5;

impl Lobe {
    /// Whether the lobe is a perfect mirror (roughness 0 or infinite exponent): the
    /// prefiltered map is then the environment itself.
    pub fn is_mirror(&self) -> bool {
        match *self {
            Lobe::Lambert => false,
            Lobe::Phong { exponent } => !exponent.is_finite(),
            Lobe::Ggx { roughness } => roughness * roughness < MIN_ALPHA,
        }
    }

    /// The GGX `α` (roughness squared), if this is GGX.
    pub fn alpha(&self) -> Option<f64> {
        match *self {
            Lobe::Ggx { roughness } => Some((roughness * roughness).max(MIN_ALPHA)),
            _ => None,
        }
    }

    /// The kernel `K(c)` at `c = n·l` (not normalised).
    #[inline]
    pub fn kernel(&self, c: f64) -> f64 {
        if c <= 0.0 {
            return 0.0;
        }
        match *self {
            Lobe::Lambert => c,
            Lobe::Phong { exponent } => c.min(1.0).powf(exponent),
            Lobe::Ggx { roughness } => {
                let a2 = {
                    let a = (roughness * roughness).max(MIN_ALPHA);
                    a * a
                };
                // (n·h)² = (1 + c)/2
                let nh2 = 0.5 * (1.0 + c.min(1.0));
                let q = nh2 * (a2 - 1.0) + 1.0;
                a2 / (PI * q * q) * c
            }
        }
    }

    /// The kernel at `l` for axis `n` (both unit vectors).
    #[inline]
    pub fn kernel_dir(&self, n: DVec3, l: DVec3) -> f64 {
        self.kernel(n.dot(l))
    }

    /// `∫ K(n·l) dω` over the sphere, by 2-D-free quadrature in `c` (Gauss–Legendre on
    /// `[0, 1]`, split near `c = 1` where sharp lobes live): `2π ∫₀¹ K(c) dc`.
    pub fn integral(&self) -> f64 {
        match *self {
            Lobe::Lambert => PI,
            Lobe::Phong { exponent } => 2.0 * PI / (exponent + 1.0),
            Lobe::Ggx { .. } => {
                // Split [0, 1] geometrically towards 1, where the lobe is concentrated.
                let w = self.angular_scale();
                let mut edges = vec![1.0];
                let mut t = (0.05 * w * w).min(0.5);
                while t < 1.0 {
                    edges.push(1.0 - t);
                    t *= 2.0;
                }
                edges.push(0.0);
                let mut s = 0.0;
                for win in edges.windows(2) {
                    let (hi, lo) = (win[0], win[1]);
                    s += gauss_legendre(lo, hi, |c| self.kernel(c));
                }
                2.0 * PI * s
            }
        }
    }

    /// A rough angular radius (radians) of the lobe's core: the angle at which the kernel
    /// falls to half its peak (GGX: `2 atan(0.644 α)`; Phong: `acos(2^(−1/s))`; Lambert:
    /// π/3). Used to choose quadrature resolutions.
    pub fn angular_scale(&self) -> f64 {
        match *self {
            Lobe::Lambert => PI / 3.0,
            Lobe::Phong { exponent } => {
                if exponent <= 0.0 {
                    PI / 2.0
                } else if !exponent.is_finite() {
                    0.0
                } else {
                    (0.5f64.powf(1.0 / exponent)).acos().max(1e-6)
                }
            }
            Lobe::Ggx { .. } => {
                let a = self.alpha().unwrap_or(MIN_ALPHA);
                // D(h)/D(0) = 1/2 where tan θ_h = α √(√2 − 1) (small α), and θ_l = 2 θ_h.
                (2.0 * (0.6436 * a).atan()).min(PI / 2.0)
            }
        }
    }
}

/// Perceptual roughness ↔ Phong exponent, by matching the GGX/Beckmann lobe to a Phong lobe
/// (Walter et al. 2007 eq. 33 for Beckmann; Karis 2013 uses the same): `s = 2/α² − 2`.
pub fn phong_exponent_from_roughness(roughness: f64) -> f64 {
    let a = (roughness * roughness).max(MIN_ALPHA);
    (2.0 / (a * a) - 2.0).max(0.0)
}

/// The inverse of [`phong_exponent_from_roughness`]: `roughness = (2/(s + 2))^{1/4}`.
pub fn roughness_from_phong_exponent(exponent: f64) -> f64 {
    if !exponent.is_finite() {
        return 0.0;
    }
    (2.0 / (exponent.max(0.0) + 2.0)).powf(0.25)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrals() {
        assert!((Lobe::Lambert.integral() - PI).abs() < 1e-12);
        // ∫ D(h)(n·h) dω_h = 1 ⇒ ∫ D(h) (n·l) dω_l = ∫ D (n·l) 4 (n·h) dω_h; check against
        // brute-force quadrature in c.
        for r in [0.1, 0.3, 0.7, 1.0] {
            let lobe = Lobe::Ggx { roughness: r };
            let n = 200_000;
            let mut s = 0.0;
            for i in 0..n {
                let c = (i as f64 + 0.5) / n as f64;
                s += lobe.kernel(c);
            }
            let brute = 2.0 * PI * s / n as f64;
            let q = lobe.integral();
            assert!((q - brute).abs() / q < 2e-3, "r={r} {q} {brute}");
        }
        // α = 1: D = 1/π, so ∫ K = 2π/π ∫ c dc = 1.
        assert!((Lobe::Ggx { roughness: 1.0 }.integral() - 1.0).abs() < 1e-9);
    }

    #[test]
    fn phong_roughness_round_trip() {
        for r in [0.1, 0.5, 0.9] {
            let s = phong_exponent_from_roughness(r);
            assert!((roughness_from_phong_exponent(s) - r).abs() < 1e-9);
        }
    }
}
