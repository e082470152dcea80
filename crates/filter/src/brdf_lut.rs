//! The split-sum BRDF table (Karis 2013, "Real Shading in Unreal Engine 4").
//!
//! The split-sum approximation writes the specular image-based lighting integral as the
//! prefiltered radiance (see [`crate::specular`]) times
//!
//! ```text
//! ∫ f(v, l) (n·l) dl = F₀ A(n·v, r) + B(n·v, r)      (Schlick's Fresnel),
//! A = ∫ (1 − F_c) G_vis,   B = ∫ F_c G_vis,   F_c = (1 − v·h)⁵,
//! ```
//!
//! estimated by importance sampling GGX half vectors (the lattice of
//! [`crate::specular`]): with `l` the reflection of `v` about `h`,
//! `G_vis = G(v, l) (v·h) / ((n·h)(n·v))` for each sample with `n·l > 0`. The visibility
//! term is selectable: UE4's Schlick–Smith with `k = α/2` for image lighting, or the
//! height-correlated Smith form Filament uses, `V = ½ / (n·l √((n·v)²(1 − α²) + α²) + n·v
//! √((n·l)²(1 − α²) + α²))`, `G = 4 (n·l)(n·v) V`.
//!
//! Layout: a `size×size` table, column `x` ↔ `n·v = (x + ½)/size`, row `y` ↔ roughness
//! `(y + ½)/size` (row 0 = smoothest, first in memory, as OpenGL and Vulkan read `t = 0`),
//! `α = roughness²`.

use crate::specular::lattice;
use mirrorball_core::Image;
use rayon::prelude::*;

/// The geometric (shadowing–masking) term.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Visibility {
    /// Schlick–Smith with `k = α/2` (UE4's choice for image-based lighting).
    #[default]
    SchlickUe4,
    /// Height-correlated Smith GGX (Heitz 2014; Filament).
    HeightCorrelated,
}

/// A split-sum table.
#[derive(Clone, Debug, PartialEq)]
pub struct BrdfLut {
    /// Edge in entries.
    pub size: u32,
    /// `(A, B)` row-major.
    pub data: Vec<[f32; 2]>,
}

/// `(A, B)` at one `n·v` and roughness, with `samples` importance samples.
pub fn integrate(n_dot_v: f64, roughness: f64, samples: u32, vis: Visibility) -> [f64; 2] {
    let nv = n_dot_v.clamp(1e-4, 1.0);
    let a = (roughness * roughness).max(1e-4);
    let a2 = a * a;
    // View vector in the frame n = z.
    let v = [(1.0 - nv * nv).sqrt(), 0.0, nv];
    let (mut sa, mut sb) = (0.0, 0.0);
    let n = samples.max(1);
    for i in 0..n {
        let (u1, u2) = lattice(i, n);
        let phi = 2.0 * std::f64::consts::PI * u2;
        let ch = crate::lobe::ggx::cos_h(u1, a2);
        let sh = (1.0 - ch * ch).max(0.0).sqrt();
        let h = [sh * phi.cos(), sh * phi.sin(), ch];
        let vh = v[0] * h[0] + v[1] * h[1] + v[2] * h[2];
        let l = [
            2.0 * vh * h[0] - v[0],
            2.0 * vh * h[1] - v[1],
            2.0 * vh * h[2] - v[2],
        ];
        let nl = l[2];
        if nl <= 0.0 || vh <= 0.0 {
            continue;
        }
        let g = match vis {
            Visibility::SchlickUe4 => {
                let k = a / 2.0;
                (nv / (nv * (1.0 - k) + k)) * (nl / (nl * (1.0 - k) + k))
            }
            Visibility::HeightCorrelated => {
                let vv = 0.5
                    / (nl * (nv * nv * (1.0 - a2) + a2).sqrt()
                        + nv * (nl * nl * (1.0 - a2) + a2).sqrt());
                4.0 * nl * nv * vv
            }
        };
        let g_vis = g * vh / (ch * nv);
        let fc = (1.0 - vh).powi(5);
        sa += (1.0 - fc) * g_vis;
        sb += fc * g_vis;
    }
    [sa / n as f64, sb / n as f64]
}

impl BrdfLut {
    /// Computes a `size×size` table with `samples` samples per entry.
    pub fn new(size: u32, samples: u32, vis: Visibility) -> BrdfLut {
        let s = size.max(1);
        let data = (0..s * s)
            .into_par_iter()
            .map(|i| {
                let (x, y) = (i % s, i / s);
                let nv = (x as f64 + 0.5) / s as f64;
                let r = (y as f64 + 0.5) / s as f64;
                let v = integrate(nv, r, samples, vis);
                [v[0] as f32, v[1] as f32]
            })
            .collect();
        BrdfLut { size: s, data }
    }

    /// Bilinear lookup at `n·v` and roughness (clamped to the table's centres).
    pub fn get(&self, n_dot_v: f64, roughness: f64) -> [f32; 2] {
        let s = self.size as f64;
        let x = (n_dot_v * s - 0.5).clamp(0.0, s - 1.0);
        let y = (roughness * s - 0.5).clamp(0.0, s - 1.0);
        let (x0, y0) = (x.floor() as usize, y.floor() as usize);
        let (x1, y1) = (
            (x0 + 1).min(self.size as usize - 1),
            (y0 + 1).min(self.size as usize - 1),
        );
        let (fx, fy) = ((x - x0 as f64) as f32, (y - y0 as f64) as f32);
        let at = |x: usize, y: usize| self.data[y * self.size as usize + x];
        let lerp =
            |a: [f32; 2], b: [f32; 2], t: f32| [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
        lerp(
            lerp(at(x0, y0), at(x1, y0), fx),
            lerp(at(x0, y1), at(x1, y1), fx),
            fy,
        )
    }

    /// As an RGB image: R = A, G = B, B = 0.
    pub fn to_image(&self) -> Image {
        let mut img = Image::new(self.size, self.size, 3);
        for (px, v) in img.data_mut().chunks_exact_mut(3).zip(&self.data) {
            px[0] = v[0];
            px[1] = v[1];
        }
        img
    }
}
