//! Brute-force references: the prefiltered value as a sum over every texel of the source.
//!
//! The environment is taken to be what its texels say: texel `t` radiates `L_t` uniformly
//! over the part of the sphere it covers, solid angle `Ω_t` (exact, from the projection).
//! The prefiltered value in direction `n` is then
//!
//! ```text
//! P(n) = Σ_t L_t ∫_t K(n·l) dω / Σ_t ∫_t K(n·l) dω,
//! ```
//!
//! with each texel's integral `∫_t K` taken as `K(n·d_t) Ω_t` at its centre `d_t`, except
//! where the kernel varies across the texel: there the texel is split into `q×q` sub-texels
//! weighted by the projection's area element (normalised to `Ω_t`), `q` chosen so that a
//! sub-texel spans at most a fifth of the kernel's local scale (its half-width near the
//! axis, the distance to the axis further out, where GGX and Phong fall off as powers of
//! it). Nothing is sampled at random and nothing is truncated: every texel contributes.
//! This is the yardstick for the fast prefilterers; it costs `O(texels)` per direction.

use crate::lobe::Lobe;
use glam::{DVec2, DVec3};
use mirrorball_core::{EnvMap, WorldProjection};
use rayon::prelude::*;

/// A source prepared for brute-force convolution.
pub struct BruteForce<'a> {
    env: &'a EnvMap,
    texels: Vec<Texel>,
}

struct Texel {
    d: DVec3,
    omega: f64,
    radius: f64,
    /// `cos(6·radius)`: beyond this angle from the axis the texel is small against its
    /// distance and is taken whole.
    cos_far: f64,
    l: [f64; 3],
    layer: u32,
    x: u32,
    y: u32,
}

impl<'a> BruteForce<'a> {
    /// Tabulates every covered texel of `env`: centre direction, exact solid angle, radiance.
    pub fn new(env: &'a EnvMap) -> BruteForce<'a> {
        let p = *env.projection();
        let (w, h) = (env.width(), env.height());
        let mut texels = Vec::new();
        for (layer, img) in env.layers().iter().enumerate() {
            let rows: Vec<Vec<Texel>> = (0..h)
                .into_par_iter()
                .map(|y| {
                    let mut dirs = vec![None; w as usize];
                    p.row_dirs(layer, y, w, h, &mut dirs);
                    let mut row = Vec::with_capacity(w as usize);
                    for x in 0..w {
                        let Some((d, _)) = dirs[x as usize] else {
                            continue;
                        };
                        let omega = p.texel_solid_angle(layer, x, y, w, h);
                        if omega <= 0.0 {
                            continue;
                        }
                        let v = img.get(x, y);
                        // Half the diagonal of a square of the same area.
                        let radius = 0.71 * omega.sqrt();
                        row.push(Texel {
                            d,
                            omega,
                            radius,
                            cos_far: (6.0 * radius).min(std::f64::consts::PI).cos(),
                            l: [v[0] as f64, v[1] as f64, v[2] as f64],
                            layer: layer as u32,
                            x,
                            y,
                        });
                    }
                    row
                })
                .collect();
            texels.extend(rows.into_iter().flatten());
        }
        BruteForce { env, texels }
    }

    /// Number of texels summed per direction.
    pub fn texel_count(&self) -> usize {
        self.texels.len()
    }

    /// The prefiltered value (RGB) of `lobe` about unit axis `n`.
    pub fn eval(&self, lobe: &Lobe, n: DVec3) -> [f64; 3] {
        let scale = lobe.angular_scale();
        let smooth = matches!(lobe, Lobe::Lambert);
        let p = *self.env.projection();
        let (w, h) = (self.env.width(), self.env.height());
        let mut num = [0.0f64; 3];
        let mut den = 0.0f64;
        for t in &self.texels {
            let c = n.dot(t.d).clamp(-1.0, 1.0);
            // Whole texel when the kernel is smooth across it: the texel is small against
            // the lobe (radius ≤ scale/5) or against its distance (θ ≥ 6·radius).
            let whole = smooth || t.radius <= 0.2 * scale || c <= t.cos_far;
            let k = if whole {
                lobe.kernel(c) * t.omega
            } else {
                let theta = c.acos();
                if theta - t.radius >= std::f64::consts::FRAC_PI_2 {
                    0.0
                } else {
                    let local = scale.max(theta - t.radius);
                    let q = ((t.radius / (0.2 * local)).ceil() as u32).clamp(1, 16);
                    sub_integral(&p, lobe, n, t, q, w, h)
                }
            };
            if k == 0.0 {
                continue;
            }
            for (a, l) in num.iter_mut().zip(t.l) {
                *a += k * l;
            }
            den += k;
        }
        if den > 0.0 {
            num.map(|v| v / den)
        } else {
            [0.0; 3]
        }
    }

    /// [`eval`](BruteForce::eval) at many directions, in parallel.
    pub fn eval_many(&self, lobe: &Lobe, dirs: &[DVec3]) -> Vec<[f64; 3]> {
        dirs.par_iter().map(|&n| self.eval(lobe, n)).collect()
    }
}

/// `∫_t K(n·l) dω` over texel `t` by a `q×q` midpoint rule in `uv`, weighted by the area
/// element and normalised to the texel's exact solid angle.
fn sub_integral(
    p: &mirrorball_core::Projection,
    lobe: &Lobe,
    n: DVec3,
    t: &Texel,
    q: u32,
    w: u32,
    h: u32,
) -> f64 {
    let layer = t.layer as usize;
    let (mut kw, mut ws) = (0.0, 0.0);
    for j in 0..q {
        for i in 0..q {
            let uv = DVec2::new(
                (t.x as f64 + (i as f64 + 0.5) / q as f64) / w as f64,
                (t.y as f64 + (j as f64 + 0.5) / q as f64) / h as f64,
            );
            let dens = p.density(layer, uv);
            if dens <= 0.0 {
                continue;
            }
            let Some(d) = p.uv_to_dir(layer, uv) else {
                continue;
            };
            kw += dens * lobe.kernel(n.dot(d));
            ws += dens;
        }
    }
    if ws > 0.0 {
        kw / ws * t.omega
    } else {
        lobe.kernel(n.dot(t.d)) * t.omega
    }
}
