//! HDR robustness: clamping or softly compressing extreme texels before prefiltering, with
//! an account of the energy removed.
//!
//! A sun stored at 10⁵ times the sky's radiance is physically right, but a renderer whose
//! shaders or caches hold half floats (max 65504), or a prefilter with few samples, may
//! prefer it tamed. Both operators act on luminance (the mean of R, G and B) and scale the
//! three channels together, so hues survive:
//!
//! * [`Compression::Clamp`]: `Y' = min(Y, max)`;
//! * [`Compression::Soft`]: identity up to `knee`, then
//!   `Y' = knee + (max − knee)(1 − exp(−(Y − knee)/(max − knee)))`, which has slope 1 at the
//!   knee (no visible kink) and approaches `max`.
//!
//! The [`EnergyReport`] gives the energy `Σ L Ω` (exact texel solid angles) before and
//! after, per channel, and the fraction of luminance energy removed.

use mirrorball_core::EnvMap;

/// How to tame extreme texels.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Compression {
    /// Leave them.
    #[default]
    None,
    /// Hard clamp of luminance at `max`.
    Clamp {
        /// Largest luminance kept.
        max: f32,
    },
    /// Soft compression above `knee`, towards `max`.
    Soft {
        /// Luminance below which nothing changes.
        knee: f32,
        /// The asymptote.
        max: f32,
    },
}

impl Compression {
    /// Parses `none`, `clamp:MAX`, `soft:KNEE:MAX` (or `soft:MAX`, knee = MAX/4).
    pub fn parse(s: &str) -> Option<Compression> {
        let parts: Vec<&str> = s.trim().split(':').collect();
        let num = |t: &str| {
            t.trim()
                .parse::<f32>()
                .ok()
                .filter(|v| v.is_finite() && *v > 0.0)
        };
        Some(match parts.as_slice() {
            ["none"] | ["off"] => Compression::None,
            ["clamp", m] => Compression::Clamp { max: num(m)? },
            ["soft", m] => {
                let max = num(m)?;
                Compression::Soft {
                    knee: 0.25 * max,
                    max,
                }
            }
            ["soft", k, m] => {
                let (knee, max) = (num(k)?, num(m)?);
                if knee >= max {
                    return None;
                }
                Compression::Soft { knee, max }
            }
            _ => return None,
        })
    }

    /// The new luminance for luminance `y`.
    #[inline]
    pub fn apply(&self, y: f32) -> f32 {
        match *self {
            Compression::None => y,
            Compression::Clamp { max } => y.min(max),
            Compression::Soft { knee, max } => {
                if y <= knee {
                    y
                } else {
                    let r = max - knee;
                    knee + r * (1.0 - (-(y - knee) / r).exp())
                }
            }
        }
    }
}

/// What a [`compress`] call changed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EnergyReport {
    /// `Σ L Ω` per channel before.
    pub before: [f64; 3],
    /// `Σ L Ω` per channel after.
    pub after: [f64; 3],
    /// Fraction of the luminance energy removed.
    pub fraction_removed: f64,
    /// Texels changed.
    pub texels: u64,
    /// Largest luminance before and after.
    pub max_before: f32,
    /// Largest luminance after.
    pub max_after: f32,
}

/// Applies `c` to every texel of `env` and reports the energy removed.
pub fn compress(env: &mut EnvMap, c: Compression) -> EnergyReport {
    let proj = *env.projection();
    let (w, h) = (env.width(), env.height());
    let omega = crate::mip::texel_solid_angles(&proj, w, h);
    let ch = env.channels();
    let mut r = EnergyReport::default();
    for (layer, img) in env.layers_mut().iter_mut().enumerate() {
        let om = &omega[layer.min(omega.len() - 1)];
        for (p, &o) in img.data_mut().chunks_exact_mut(ch).zip(om.iter()) {
            let y = (p[0] + p[1] + p[2]) / 3.0;
            for (b, v) in r.before.iter_mut().zip(&p[..3]) {
                *b += *v as f64 * o;
            }
            r.max_before = r.max_before.max(y);
            let y2 = c.apply(y);
            if y2 < y && y > 0.0 {
                let s = y2 / y;
                for v in &mut p[..3] {
                    *v *= s;
                }
                r.texels += 1;
            }
            for (a, v) in r.after.iter_mut().zip(&p[..3]) {
                *a += *v as f64 * o;
            }
            r.max_after = r.max_after.max(y2.min(y));
        }
    }
    let (b, a) = (r.before.iter().sum::<f64>(), r.after.iter().sum::<f64>());
    r.fraction_removed = if b > 0.0 { (b - a) / b } else { 0.0 };
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn soft_is_smooth_and_bounded() {
        let c = Compression::Soft {
            knee: 10.0,
            max: 100.0,
        };
        assert_eq!(c.apply(5.0), 5.0);
        let e = 1e-3;
        let slope = (c.apply(10.0 + e) - c.apply(10.0)) / e;
        assert!((slope - 1.0).abs() < 1e-2);
        assert!(c.apply(1e9) <= 100.0);
        assert!(c.apply(50.0) < 50.0 && c.apply(50.0) > 10.0);
        assert_eq!(
            Compression::parse("soft:100"),
            Some(Compression::Soft {
                knee: 25.0,
                max: 100.0
            })
        );
        assert!(Compression::parse("soft:100:10").is_none());
    }
}
