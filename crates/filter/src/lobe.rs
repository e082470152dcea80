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
use mirrorball_core::Choice;
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

/// The kind of a [`Lobe`], without its parameter (what a prefiltered chain's levels share:
/// [`crate::chain_lobes`] gives each level its parameter). Named by its [`Choice`] table
/// (`lambert`, `phong`, `ggx` and their aliases), as the CLI's `--lobe` and a material's
/// `lobe` spell it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LobeKind {
    /// Lambert (every level the same lobe).
    Lambert,
    /// Phong, exponent `2/α² − 2` from each level's roughness unless given.
    Phong,
    /// GGX, one roughness per level.
    Ggx,
}

impl Choice for LobeKind {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (LobeKind::Lambert, &["lambert", "diffuse", "irradiance"]),
        (LobeKind::Phong, &["phong"]),
        (LobeKind::Ggx, &["ggx", "specular", "trowbridge-reitz"]),
    ];
}
mirrorball_core::choice_traits!(LobeKind);

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

    /// Whether the parameter is in range: a Phong exponent ≥ 0 (infinite: a mirror), a GGX
    /// roughness in `[0, 1]`.
    pub fn is_valid(&self) -> bool {
        match *self {
            Lobe::Lambert => true,
            Lobe::Phong { exponent } => exponent >= 0.0 && !exponent.is_nan(),
            Lobe::Ggx { roughness } => (0.0..=1.0).contains(&roughness),
        }
    }

    /// The lobe's kind, without its parameter.
    pub fn kind(&self) -> LobeKind {
        match self {
            Lobe::Lambert => LobeKind::Lambert,
            Lobe::Phong { .. } => LobeKind::Phong,
            Lobe::Ggx { .. } => LobeKind::Ggx,
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
                ggx::d(0.5 * (1.0 + c.min(1.0)), a2) * c
            }
        }
    }

    /// One importance sample of the lobe in the frame of its axis (`+z`), from `u1` in
    /// `[0, 1)` (the cumulative distribution in θ) and the azimuth `phi`:
    /// `(l, weight, pdf)`, the estimator of `∫LK/∫K` being `Σ weight·L(l) / Σ weight`, and
    /// `pdf` the density of `l` per steradian (for the filtered-importance-sampling level).
    /// Not for mirrors.
    ///
    /// * Lambert: cosine-weighted, `cos θ = √u₁`, `p = cos θ/π`, weight 1.
    /// * Phong: `p = (s + 1)/(2π) cos^s θ`, so `cos θ = u₁^{1/(s+1)}`, weight 1.
    /// * GGX: the half vector from `D(h)(n·h)` ([`ggx::cos_h`]), `l` its reflection of
    ///   `v = n`; `p(l) = D(h)(n·h)/(4 v·h) = D(h)/4`, weight `n·l` (0 below the horizon).
    #[inline]
    pub fn sample(&self, u1: f64, phi: f64) -> (DVec3, f64, f64) {
        match *self {
            Lobe::Lambert => {
                let c = u1.sqrt();
                (polar(c, phi), 1.0, c / PI)
            }
            Lobe::Phong { exponent } => {
                let c = u1.powf(1.0 / (exponent + 1.0));
                (
                    polar(c, phi),
                    1.0,
                    (exponent + 1.0) / (2.0 * PI) * c.powf(exponent),
                )
            }
            Lobe::Ggx { .. } => {
                let a = self.alpha().expect("ggx");
                let a2 = a * a;
                let ch = ggx::cos_h(u1, a2);
                let h = polar(ch, phi);
                let l = DVec3::new(2.0 * ch * h.x, 2.0 * ch * h.y, 2.0 * ch * ch - 1.0);
                (l, l.z.max(0.0), ggx::d(ch * ch, a2) / 4.0)
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

/// The unit vector at polar angle `acos c` and azimuth `phi` about `+z`.
#[inline]
pub(crate) fn polar(c: f64, phi: f64) -> DVec3 {
    let s = (1.0 - c * c).max(0.0).sqrt();
    DVec3::new(s * phi.cos(), s * phi.sin(), c)
}

/// The GGX (Trowbridge–Reitz) microfacet distribution of Walter et al. 2007, in terms of
/// `α²` (`α = roughness²`).
pub mod ggx {
    use std::f64::consts::PI;

    /// `D(h) = α² / (π ((n·h)²(α² − 1) + 1)²)` at `nh2 = (n·h)²` (Walter et al. eq. 33).
    #[inline]
    pub fn d(nh2: f64, a2: f64) -> f64 {
        let q = nh2 * (a2 - 1.0) + 1.0;
        a2 / (PI * q * q)
    }

    /// Sampling `D(h)(n·h)` by inverting its cumulative distribution in θ_h:
    /// `cos²θ_h = (1 − u)/(1 + (α² − 1)u)` for `u` in `[0, 1]` (Walter et al. eq. 35–36).
    #[inline]
    pub fn cos_h(u: f64, a2: f64) -> f64 {
        ((1.0 - u) / (1.0 + (a2 - 1.0) * u)).max(0.0).sqrt()
    }

    /// The split-sum kernel `K(c) = D(h)·c` with `(n·h)² = (1 + c)/2`, in `f32` for the
    /// bright-texel sum: [`super::Lobe::kernel`]'s GGX arm evaluated as
    /// `α²·(1/π)·c / q²`, `q = ½(1 + c)(α² − 1) + 1` (tested against it: relative error
    /// `~2ε/q`, since `q` cancels towards `α²` at `c = 1`).
    #[inline(always)]
    pub(crate) fn kernel_f32(c: f32, a2: f32) -> f32 {
        let q = 0.5 * (1.0 + c) * (a2 - 1.0) + 1.0;
        a2 * std::f32::consts::FRAC_1_PI * c / (q * q)
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
    fn lobe_kinds_are_named_by_one_table() {
        let names: Vec<&str> = LobeKind::all().map(LobeKind::name).collect();
        assert_eq!(names, ["lambert", "phong", "ggx"]);
        for (kind, aliases) in LobeKind::NAMES {
            for name in *aliases {
                assert_eq!(name.parse::<LobeKind>(), Ok(*kind));
            }
        }
        assert_eq!("Trowbridge_Reitz".parse::<LobeKind>(), Ok(LobeKind::Ggx));
        let lobes = [
            Lobe::Lambert,
            Lobe::Phong { exponent: 8.0 },
            Lobe::Ggx { roughness: 0.5 },
        ];
        for (lobe, name) in lobes.iter().zip(names) {
            assert_eq!(lobe.kind().to_string(), name);
        }
        let e = "beckmann".parse::<LobeKind>().unwrap_err();
        assert_eq!(e.list(), "lambert, phong, ggx");
    }

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
    fn f32_ggx_kernel_agrees_with_the_f64_one() {
        for r in [0.05, 0.2, 0.5, 1.0] {
            let lobe = Lobe::Ggx { roughness: r };
            let a = lobe.alpha().unwrap();
            for i in 1..=1000 {
                let c = (i as f64 / 1000.0) as f32;
                let k = lobe.kernel(c as f64);
                let k32 = ggx::kernel_f32(c, (a * a) as f32) as f64;
                // q = ½(1 + c)(α² − 1) + 1 cancels towards α² at c = 1: the f32 error in q
                // is a few ulps of 1, relative 2ε/q in K.
                let q = 0.5 * (1.0 + c as f64) * (a * a - 1.0) + 1.0;
                let tol = 1e-6 + 4.0 * f32::EPSILON as f64 / q;
                assert!((k32 - k).abs() <= tol * k, "r={r} c={c}: {k32} vs {k}");
            }
        }
    }

    #[test]
    fn samples_follow_their_pdf() {
        // Lambert and Phong: the pdf is the kernel normalised, p = K/∫K, weight 1.
        for lobe in [Lobe::Lambert, Lobe::Phong { exponent: 8.0 }] {
            let n = 4096;
            for i in 0..n {
                let (l, w, pdf) = lobe.sample((i as f64 + 0.5) / n as f64, 0.3);
                assert_eq!(w, 1.0);
                assert!((l.length() - 1.0).abs() < 1e-12);
                assert!((pdf - lobe.kernel(l.z) / lobe.integral()).abs() < 1e-9 * pdf.max(1.0));
            }
        }
        // GGX: p(l) = D(h)/4 and the weight is n·l.
        let lobe = Lobe::Ggx { roughness: 0.5 };
        let a2 = lobe.alpha().unwrap().powi(2);
        let (l, w, pdf) = lobe.sample(0.25, 1.0);
        let h = (l + DVec3::Z).normalize();
        assert!((pdf - ggx::d(h.z * h.z, a2) / 4.0).abs() < 1e-12);
        assert!((w - l.z).abs() < 1e-15);
    }

    #[test]
    fn phong_roughness_round_trip() {
        for r in [0.1, 0.5, 0.9] {
            let s = phong_exponent_from_roughness(r);
            assert!((roughness_from_phong_exponent(s) - r).abs() < 1e-9);
        }
    }
}
