//! The equi-angular cube map (EAC), as Google publishes it for YouTube and FFmpeg's `v360`
//! (`eac`) reads and writes it.
//!
//! **Formula.** The six faces are the OpenGL cube's (layer order +X −X +Y −Y +Z −Z, each
//! face's `(s, t)` axes as the major-axis table gives them: [`CubeFace`]), but the stored
//! coordinate is the *angle* across the face instead of the tangent-plane intersection. With
//! `p = 2u − 1`, `q = 2v − 1` in `[-1, 1]`, the gnomonic face coordinates are
//!
//! ```text
//! a = tan(π/4 · p),   b = tan(π/4 · q)        (p = 4/π · atan a, q = 4/π · atan b)
//! ```
//!
//! and the direction is `normalize(face.point(a, b))`, exactly the cube's. Equal steps in
//! `p` are equal angles seen from the centre along the face's mid-line; this is v360's
//! `xyz_to_eac`/`eac_to_xyz` (`uf = 2/π · atan(uf) + ½`, `uf = tan(π/2 · uf)` on
//! `uf ∈ [−½, ½]`) and Google's "Bringing pixels front and center in VR video" (2017).
//! The face arrangement in one picture (v360's 3×2 with its bottom row turned, and its
//! padding) is a layout: [`crate::Layout::eac`].
//!
//! **Density.** The cube's area element in `(a, b)` is `dω = da db/(1 + a² + b²)^{3/2}`, and
//! `da/du = 2 · π/4 · sec²(π/4 · p) = π/2 · (1 + a²)`, likewise for `b`, so
//!
//! ```text
//! dω/du dv = (π/2)² (1 + a²)(1 + b²) / (1 + a² + b²)^{3/2}.
//! ```
//!
//! **Texel solid angle.** The warp acts on each axis separately and is monotone, so a texel
//! `[u₀, u₁] × [v₀, v₁]` is the gnomonic rectangle between the warped corners
//! `a_k = tan(π/4 (2u_k − 1))`, `b_k` likewise, whose solid angle is the cube's closed form
//! `F(a₁, b₁) − F(a₀, b₁) − F(a₁, b₀) + F(a₀, b₀)`, `F(a, b) = atan(ab/√(1 + a² + b²))`.
//! The six faces cover the sphere once: `covered_solid_angle` is 4π.

use super::cube::{cube_area, CubeFace};
use super::{texel_range, WorldProjection};
use glam::{DVec2, DVec3};
use std::f64::consts::FRAC_PI_4;

/// The equi-angular cube map: OpenGL's six faces, each stored equi-angularly (see the module
/// documentation for the formulas).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Eac;

impl Eac {
    /// Gnomonic face coordinate `a = tan(π/4 · p)` of the equi-angular one `p ∈ [-1, 1]`.
    #[inline]
    pub fn unwarp(p: f64) -> f64 {
        (FRAC_PI_4 * p).tan()
    }

    /// Equi-angular face coordinate `p = 4/π · atan a` of the gnomonic one `a ∈ [-1, 1]`.
    #[inline]
    pub fn warp(a: f64) -> f64 {
        a.atan() / FRAC_PI_4
    }

    /// Solid angle per unit `uv` at gnomonic face coordinates `(a, b)`: the cube's
    /// `4/(1 + a² + b²)^{3/2}` times `da/du · db/dv = (π/2)²(1 + a²)(1 + b²)/4`.
    #[inline]
    fn density_at(a: f64, b: f64) -> f64 {
        let (a2, b2) = (a * a, b * b);
        let g = 1.0 + a2 + b2;
        let half_pi = 2.0 * FRAC_PI_4;
        half_pi * half_pi * (1.0 + a2) * (1.0 + b2) / (g * g.sqrt())
    }
}

impl WorldProjection for Eac {
    fn layer_count(&self) -> usize {
        6
    }
    fn layer_extent(&self, size: u32) -> (u32, u32) {
        (size, size)
    }
    #[inline]
    fn dir_to_uv(&self, d: DVec3) -> Option<(usize, DVec2)> {
        let (face, sc, tc, ma) = CubeFace::select(d);
        if ma <= 0.0 || !ma.is_finite() {
            return None;
        }
        let (p, q) = (Eac::warp(sc / ma), Eac::warp(tc / ma));
        Some((face as usize, DVec2::new(0.5 * (p + 1.0), 0.5 * (q + 1.0))))
    }
    #[inline]
    fn uv_to_dir(&self, layer: usize, uv: DVec2) -> Option<DVec3> {
        let face = CubeFace::from_index(layer)?;
        let (a, b) = (Eac::unwarp(2.0 * uv.x - 1.0), Eac::unwarp(2.0 * uv.y - 1.0));
        Some(face.point(a, b).normalize())
    }
    #[inline]
    fn density(&self, _layer: usize, uv: DVec2) -> f64 {
        let (a, b) = (Eac::unwarp(2.0 * uv.x - 1.0), Eac::unwarp(2.0 * uv.y - 1.0));
        Eac::density_at(a, b)
    }
    /// The default's directions and densities, texel for texel the same bits (tested),
    /// with the row's gnomonic coordinate worked out once: one `tan` a texel, not four.
    fn span_dirs(
        &self,
        layer: usize,
        y: u32,
        w: u32,
        h: u32,
        x0: u32,
        out: &mut [Option<(DVec3, f64)>],
    ) {
        let Some(face) = CubeFace::from_index(layer) else {
            out.fill(None);
            return;
        };
        let v = (y as f64 + 0.5) / h as f64;
        let b = Eac::unwarp(2.0 * v - 1.0);
        for (i, o) in out.iter_mut().enumerate() {
            let u = ((x0 as usize + i) as f64 + 0.5) / w as f64;
            let a = Eac::unwarp(2.0 * u - 1.0);
            *o = Some((face.point(a, b).normalize(), Eac::density_at(a, b)));
        }
    }
    fn texel_solid_angle(&self, _layer: usize, x: u32, y: u32, w: u32, h: u32) -> f64 {
        let (u0, u1) = texel_range(x, w);
        let (v0, v1) = texel_range(y, h);
        let c = |t: f64| Eac::unwarp(2.0 * t - 1.0);
        let (a0, a1, b0, b1) = (c(u0), c(u1), c(v0), c(v1));
        cube_area(a1, b1) - cube_area(a0, b1) - cube_area(a1, b0) + cube_area(a0, b0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::projection::CubeMap;
    use std::f64::consts::PI;

    /// Deterministic directions spread over the sphere (a Fibonacci lattice, jittered).
    fn directions(n: usize) -> impl Iterator<Item = DVec3> {
        let golden = PI * (3.0 - 5f64.sqrt());
        (0..n).map(move |i| {
            let y = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - y * y).sqrt();
            let phi = golden * i as f64 + 0.1;
            DVec3::new(r * phi.cos(), y, r * phi.sin())
        })
    }

    /// The hoisted rows are the default's, bit for bit (texel centres and the finer grids
    /// the resampler integrates on).
    #[test]
    fn span_dirs_are_the_defaults() {
        for (w, h, x0, n) in [(7, 7, 0, 7), (64, 64, 5, 40), (3 * 8, 3 * 8, 9, 6)] {
            for layer in 0..6 {
                for y in [0, 1, h / 2, h - 1] {
                    let mut fast = vec![None; n];
                    Eac.span_dirs(layer, y, w, h, x0, &mut fast);
                    let slow: Vec<_> = (0..n)
                        .map(|i| {
                            let uv = DVec2::new(
                                ((x0 as usize + i) as f64 + 0.5) / w as f64,
                                (y as f64 + 0.5) / h as f64,
                            );
                            Some((Eac.uv_to_dir(layer, uv).unwrap(), Eac.density(layer, uv)))
                        })
                        .collect();
                    assert_eq!(fast, slow, "layer {layer} row {y} of {w}x{h}");
                }
            }
        }
    }

    #[test]
    fn round_trip_of_1e5_directions() {
        let mut worst = 0.0f64;
        for d in directions(100_000) {
            let (l, uv) = Eac.dir_to_uv(d).unwrap();
            assert!((0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y));
            let back = Eac.uv_to_dir(l, uv).unwrap();
            worst = worst.max((back - d).length());
        }
        assert!(worst <= 1e-12, "worst round trip {worst:e}");
    }

    #[test]
    fn same_faces_as_the_cube_with_angles_inside() {
        // The face is the cube's; the stored coordinate is 4/π·atan of the cube's.
        for d in directions(2000) {
            let (le, e) = Eac.dir_to_uv(d).unwrap();
            let (lc, c) = CubeMap.dir_to_uv(d).unwrap();
            assert_eq!(le, lc);
            let want = (c * 2.0 - 1.0)
                .to_array()
                .map(|a| 0.5 * (a.atan() / FRAC_PI_4 + 1.0));
            assert!((e.x - want[0]).abs() < 1e-14 && (e.y - want[1]).abs() < 1e-14);
        }
        // The face's mid-lines are sampled at equal angles: texel centres along v = ½ of a
        // 90-texel face are one degree apart.
        let (w, x) = (90u32, 17u32);
        let at = |x: u32| {
            let uv = DVec2::new((x as f64 + 0.5) / w as f64, 0.5);
            Eac.uv_to_dir(4, uv).unwrap()
        };
        let step = at(x).angle_between(at(x + 1));
        assert!((step - 1f64.to_radians()).abs() < 1e-13, "{step}");
    }

    #[test]
    fn texel_solid_angles_sum_to_4pi() {
        for n in [1u32, 3, 16, 33] {
            let total: f64 = (0..6)
                .flat_map(|l| (0..n).flat_map(move |y| (0..n).map(move |x| (l, x, y))))
                .map(|(l, x, y)| Eac.texel_solid_angle(l, x, y, n, n))
                .sum();
            assert!((total - 4.0 * PI).abs() < 1e-12, "{n}: {total}");
        }
        assert_eq!(Eac.covered_solid_angle(), 4.0 * PI);
    }

    #[test]
    fn density_is_the_jacobian_and_integrates_to_the_texel() {
        let h = 1e-6;
        for (l, uv) in [
            (0, (0.5, 0.5)),
            (3, (0.1, 0.8)),
            (5, (0.97, 0.03)),
            (2, (0.3, 0.6)),
        ] {
            let uv = DVec2::new(uv.0, uv.1);
            let d = |du: f64, dv: f64| Eac.uv_to_dir(l, uv + DVec2::new(du, dv)).unwrap();
            let du = (d(h, 0.0) - d(-h, 0.0)) / (2.0 * h);
            let dv = (d(0.0, h) - d(0.0, -h)) / (2.0 * h);
            let fd = du.cross(dv).length();
            let exact = Eac.density(l, uv);
            assert!(
                (fd - exact).abs() < 1e-6 * exact,
                "{l} {uv}: {fd} vs {exact}"
            );
        }
        // A small texel's solid angle is the density times its area, to second order.
        let n = 4096;
        let (x, y) = (700, 3100);
        let uv = DVec2::new((x as f64 + 0.5) / n as f64, (y as f64 + 0.5) / n as f64);
        let area = Eac.density(1, uv) / (n as f64 * n as f64);
        let sa = Eac.texel_solid_angle(1, x, y, n, n);
        assert!((sa - area).abs() < 1e-6 * sa, "{sa} vs {area}");
    }

    #[test]
    fn equi_angular_texels_are_more_even_than_the_cube() {
        // The point of EAC: the largest-to-smallest texel ratio of a face is about 1.41
        // (the cube's is about 5.2, at 64² texels).
        let ratio = |p: &dyn WorldProjection| {
            let n = 64;
            let sa: Vec<f64> = (0..n)
                .flat_map(|y| (0..n).map(move |x| (x, y)))
                .map(|(x, y)| p.texel_solid_angle(4, x, y, n, n))
                .collect();
            let max = sa.iter().cloned().fold(0.0, f64::max);
            let min = sa.iter().cloned().fold(f64::INFINITY, f64::min);
            max / min
        };
        let (e, c) = (ratio(&Eac), ratio(&CubeMap));
        assert!(e < 1.45 && c > 5.0, "eac {e}, cube {c}");
    }
}
