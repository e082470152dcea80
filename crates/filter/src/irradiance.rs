//! Diffuse irradiance: Lambert's cosine convolution over the hemisphere.
//!
//! Three ways, from exact to fast:
//!
//! * [`BruteForce`](crate::BruteForce) with [`Lobe::Lambert`](crate::Lobe): the sum over
//!   every texel, `Σ L_t max(n·d_t, 0) Ω_t / Σ max(n·d_t, 0) Ω_t` (the reference).
//! * The **moment hierarchy** used by [`Prefilterer`](crate::Prefilterer) for Lambert
//!   lobes. It computes the same sum, exactly up to a tolerance, in a few thousand
//!   operations per direction instead of one per texel. Each node of the cube's quadtree
//!   (a texel of a coarser mip level) stores its energy `E = Σ L_t Ω_t` and first moment
//!   `M = Σ L_t Ω_t d_t` (per colour channel, plus the same for `L = 1`). The cosine kernel
//!   is *linear* in `l` wherever it is not clamped, so a node lying wholly above the
//!   horizon of `n` contributes exactly `n·M` to the sum, whatever the radiance inside it;
//!   a node wholly below contributes nothing. Cube texels are bounded by great circles,
//!   so a node is wholly above the horizon exactly when its four corners are, a test that
//!   is linear in the face coordinates. Only the nodes the horizon cuts are opened, down to
//!   single texels where the node is bright enough to matter (its energy times the spread
//!   of `n·l` across it exceeds `tolerance` times the map's total energy); a dim cut node is
//!   taken as `E` times the mean of `max(c, 0)` for `c` spread evenly between its corners'
//!   cosines. With the default tolerance the result agrees with the brute-force sum to
//!   about 1e-4 relative at a few microseconds per direction.
//! * Spherical harmonics ([`crate::sh`]): nine numbers, evaluated anywhere in a few
//!   nanoseconds; exact only for environments of bands 0–2 (Ramamoorthi & Hanrahan 2001).

use crate::cube::FaceGeometry;
use crate::sh::{Sh9, Window};
use glam::{Vec3, Vec4};
use mirrorball_core::{Choice, CubeFace};
use mirrorball_core::{EnvMap, Image, Projection};
use rayon::prelude::*;

/// How a Lambert (irradiance) map is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IrradianceMethod {
    /// The moment hierarchy ([`Prefilterer`](crate::Prefilterer) with
    /// [`Lobe::Lambert`](crate::Lobe)): the brute-force sum to a tolerance.
    Exact,
    /// Nine spherical-harmonic coefficients ([`irradiance_map_sh`]).
    Sh,
}

impl Choice for IrradianceMethod {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (IrradianceMethod::Exact, &["exact", "convolve", "brute"]),
        (IrradianceMethod::Sh, &["sh", "sh9"]),
    ];
}
mirrorball_core::choice_traits!(IrradianceMethod);

/// The quadtree of a power-of-two cube with energy and first-moment sums per node.
pub(crate) struct MomentPyramid {
    size0: usize,
    geom: FaceGeometry,
    /// Level-0 radiance, RGB and 1, `6 × size0²`.
    base: Vec<Vec4>,
    /// `levels[k − 1]` holds level `k ≥ 1`: per node `[E|Ω, Mx|Ωx, My|Ωy, Mz|Ωz]`.
    levels: Vec<Vec<[Vec4; 4]>>,
    /// `1/Σ E` per channel (and `1/4π`).
    inv_total: Vec4,
}

impl MomentPyramid {
    /// From the six faces of a power-of-two cube (3 or 4 channels; alpha ignored).
    pub fn new(faces: &[Image]) -> MomentPyramid {
        let size0 = faces[0].width() as usize;
        assert!(
            size0.is_power_of_two(),
            "moment pyramids need power-of-two faces"
        );
        let geom = FaceGeometry::new(size0);
        let mut base = vec![Vec4::ZERO; 6 * size0 * size0];
        base.par_chunks_mut(size0 * size0)
            .enumerate()
            .for_each(|(f, out)| {
                let img = &faces[f];
                for (i, o) in out.iter_mut().enumerate() {
                    let t = img.get((i % size0) as u32, (i / size0) as u32);
                    *o = Vec4::new(t[0], t[1], t[2], 1.0);
                }
            });
        let mut levels: Vec<Vec<[Vec4; 4]>> = Vec::new();
        let mut size = size0 / 2;
        while size >= 1 {
            let prev = levels.last();
            let s2 = 2 * size;
            let mut nodes = vec![[Vec4::ZERO; 4]; 6 * size * size];
            nodes
                .par_chunks_mut(size)
                .enumerate()
                .for_each(|(row, out)| {
                    let (f, y) = (row / size, row % size);
                    for (x, o) in out.iter_mut().enumerate() {
                        let mut acc = [[0.0f64; 4]; 4];
                        for (cx, cy) in [
                            (2 * x, 2 * y),
                            (2 * x + 1, 2 * y),
                            (2 * x, 2 * y + 1),
                            (2 * x + 1, 2 * y + 1),
                        ] {
                            let child: [Vec4; 4] = match prev {
                                None => {
                                    let i = cy * s2 + cx;
                                    let g = geom.texels[i];
                                    let d = CubeFace::from_face(f, Vec3::new(g[0], g[1], g[2]));
                                    let e = base[f * s2 * s2 + i] * g[3];
                                    [e, e * d.x, e * d.y, e * d.z]
                                }
                                Some(p) => p[f * s2 * s2 + cy * s2 + cx],
                            };
                            for (a, c) in acc.iter_mut().zip(child) {
                                for k in 0..4 {
                                    a[k] += c[k] as f64;
                                }
                            }
                        }
                        *o = acc
                            .map(|a| Vec4::new(a[0] as f32, a[1] as f32, a[2] as f32, a[3] as f32));
                    }
                });
            levels.push(nodes);
            size /= 2;
        }
        let total = match levels.last() {
            Some(top) => top.iter().fold(Vec4::ZERO, |a, n| a + n[0]),
            None => (0..6).fold(Vec4::ZERO, |a, f| a + base[f] * geom.texels[0][3]),
        };
        let inv_total = Vec4::new(
            1.0 / total.x.max(1e-30),
            1.0 / total.y.max(1e-30),
            1.0 / total.z.max(1e-30),
            1.0 / total.w.max(1e-30),
        );
        MomentPyramid {
            size0,
            geom,
            base,
            levels,
            inv_total,
        }
    }

    /// `Σ_t max(n·d_t, 0) [L_t Ω_t, Ω_t]` over the whole cube, to within `tol` (relative to
    /// the total energy, per cut node; see the module docs). `n` is a unit vector.
    pub fn cosine_sum(&self, n: Vec3, tol: f32) -> Vec4 {
        let top = self.levels.len();
        let mut acc = Vec4::ZERO;
        // Depth-first; at most 3 entries per level plus the six roots are pending at once.
        let mut stack: [(u8, u8, u16, u16); 128] = [(0, 0, 0, 0); 128];
        let mut sp = 0usize;
        let mut nl = [Vec3::ZERO; 6];
        for (f, nlf) in nl.iter_mut().enumerate() {
            *nlf = CubeFace::to_face(f, n);
            stack[sp] = (top as u8, f as u8, 0, 0);
            sp += 1;
        }
        while sp > 0 {
            sp -= 1;
            let (k, f, x, y) = stack[sp];
            let (k, f, x, y) = (k as usize, f as usize, x as usize, y as usize);
            let s = self.size0 >> k;
            let q = nl[f];
            let step = 2.0 / s as f32;
            let a0 = x as f32 * step - 1.0;
            let b0 = y as f32 * step - 1.0;
            let (a1, b1) = (a0 + step, b0 + step);
            let (ax0, ax1) = (q.x * a0, q.x * a1);
            let (by0, by1) = (q.y * b0, q.y * b1);
            let lo = q.z + ax0.min(ax1) + by0.min(by1);
            let hi = q.z + ax0.max(ax1) + by0.max(by1);
            if hi <= 0.0 {
                continue;
            }
            if k == 0 {
                let i = y * s + x;
                let g = self.geom.texels[i];
                let c = q.x * g[0] + q.y * g[1] + q.z * g[2];
                if c > 0.0 {
                    acc += self.base[f * s * s + i] * (c * g[3]);
                }
                continue;
            }
            let node = &self.levels[k - 1][(f * s + y) * s + x];
            if lo > 0.0 {
                acc += node[1] * n.x + node[2] * n.y + node[3] * n.z;
                continue;
            }
            // Cut by the horizon: the cosines at the four corners.
            let corner = |a: f32, b: f32, ab: f32| ab / (1.0 + a * a + b * b).sqrt();
            let c00 = corner(a0, b0, q.z + ax0 + by0);
            let c10 = corner(a1, b0, q.z + ax1 + by0);
            let c01 = corner(a0, b1, q.z + ax0 + by1);
            let c11 = corner(a1, b1, q.z + ax1 + by1);
            let clo = c00.min(c10).min(c01.min(c11));
            let chi = c00.max(c10).max(c01.max(c11));
            let spread = (chi - clo).max(1e-12);
            let weight = (node[0] * self.inv_total).max_element() * spread;
            if weight > tol && sp + 4 <= stack.len() {
                let (cx, cy) = (2 * x as u16, 2 * y as u16);
                let kk = (k - 1) as u8;
                stack[sp] = (kk, f as u8, cx, cy);
                stack[sp + 1] = (kk, f as u8, cx + 1, cy);
                stack[sp + 2] = (kk, f as u8, cx, cy + 1);
                stack[sp + 3] = (kk, f as u8, cx + 1, cy + 1);
                sp += 4;
            } else {
                // Mean of max(c, 0) for c uniform on [clo, chi].
                let m = if clo >= 0.0 {
                    0.5 * (clo + chi)
                } else {
                    let p = chi.max(0.0);
                    p * p / (2.0 * spread)
                };
                acc += node[0] * m;
            }
        }
        acc
    }

    /// `E(n)/π` (RGB) with the exact normalisation `Σ max(n·d_t, 0) Ω_t`.
    #[inline]
    pub fn irradiance_over_pi(&self, n: Vec3, tol: f32) -> Vec4 {
        let s = self.cosine_sum(n, tol);
        if s.w > 0.0 {
            s / s.w
        } else {
            Vec4::ZERO
        }
    }
}

/// An irradiance map (`E/π`) of `size` in projection `out` from nine spherical-harmonic
/// coefficients, with a window against ringing.
pub fn irradiance_map_sh(sh: &Sh9, window: Window, out: Projection, size: u32) -> EnvMap {
    let conv = sh.windowed(window).lambert();
    EnvMap::from_fn(out, size, 3, |d| {
        let v = conv.eval(d);
        [v[0] as f32, v[1] as f32, v[2] as f32, 1.0]
    })
}
