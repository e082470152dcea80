//! Spherical harmonics, bands 0–2 (nine coefficients per colour channel): projection with
//! exact texel solid angles, Lambert convolution (Ramamoorthi & Hanrahan 2001), and windows
//! against ringing.
//!
//! # Basis
//!
//! Real, orthonormal on the sphere (`∫ Y_i Y_j dω = δ_ij`), index `i = l(l + 1) + m`, written
//! in the world axes of `ARCHITECTURE.md` (+Y up) exactly as Sloan's "Stupid SH Tricks" and
//! most engines write them:
//!
//! | i | (l, m) | Y |
//! | --- | --- | --- |
//! | 0 | (0, 0) | `½√(1/π)` |
//! | 1 | (1, −1) | `√(3/4π) y` |
//! | 2 | (1, 0) | `√(3/4π) z` |
//! | 3 | (1, 1) | `√(3/4π) x` |
//! | 4 | (2, −2) | `½√(15/π) xy` |
//! | 5 | (2, −1) | `½√(15/π) yz` |
//! | 6 | (2, 0) | `¼√(5/π) (3z² − 1)` |
//! | 7 | (2, 1) | `½√(15/π) xz` |
//! | 8 | (2, 2) | `¼√(15/π) (x² − y²)` |
//!
//! # Projection
//!
//! `L_i = ∫ L(ω) Y_i(ω) dω ≈ Σ_t L_t Y_i(d_t) Ω_t` with `Ω_t` the projection's exact texel
//! solid angle and `d_t` the texel's centre (cube maps: exact solid angles from a table of
//! `atan(ab/√(1 + a² + b²))` at texel corners). [`project`] sums in `f32` along rows and in
//! `f64` across them, in parallel; [`project_reference`] is the plain `f64` loop.
//!
//! # Irradiance
//!
//! Lambert's clamped cosine has the zonal coefficients `Â₀ = π`, `Â₁ = 2π/3`, `Â₂ = π/4`
//! (Ramamoorthi & Hanrahan 2001, eq. 8), so `E(n) = Σ Â_l L_lm Y_lm(n)`; [`Sh9::lambert`]
//! folds `Â_l/π` in, giving `E/π` as the prefiltered maps store it.
//!
//! # Ringing
//!
//! Truncating at band 2 makes a very bright, small source (a sun) ring: the irradiance
//! dips below zero on the far side. A window `σ_l` attenuates band `l` (Sloan 2008, "Stupid
//! SH Tricks" §"Windowing"): Hann `σ_l = (1 + cos(π l/w))/2`, Lanczos
//! `σ_l = sinc(l/w)`, or [`Window::NonNegative`], the weakest Hann window that makes the
//! irradiance non-negative everywhere (found by bisection on `1/w`; `w = 1` keeps band 0
//! only, which is always non-negative).

use crate::cube::FaceGeometry;
use glam::{DVec2, DVec3, Vec3};
use mirrorball_core::par::fold_in_order;
use mirrorball_core::CubeFace;
use mirrorball_core::{EnvMap, ProjectionKind, WorldProjection};
use rayon::prelude::*;
use std::f64::consts::PI;

/// The SH basis normalisation constants.
const K0: f64 = 0.282_094_791_773_878_14; // ½√(1/π)
const K1: f64 = 0.488_602_511_902_919_9; // √(3/4π)
const K2: f64 = 1.092_548_430_592_079_2; // ½√(15/π)
const K20: f64 = 0.315_391_565_252_520_05; // ¼√(5/π)
const K22: f64 = 0.546_274_215_296_039_6; // ¼√(15/π)

/// Each basis function's constant: `Yᵢ(d) = CONSTANTS[i] · Pᵢ(d)` with the polynomials
/// `1, y, z, x, xy, yz, 3z² − 1, xz, x² − y²` (engines that store SH "pre-scaled" fold
/// these into the coefficients).
pub const CONSTANTS: [f64; 9] = [K0, K1, K1, K1, K2, K2, K20, K2, K22];

/// The basis in words, for the documents that carry coefficients (the SH JSON).
pub const BASIS_TEXT: &str = "real spherical harmonics, bands 0-2, index l(l+1)+m, orthonormal over the sphere, in world axes (+Y up, -Z ahead): Y0=0.282095, Y1=0.488603 y, Y2=0.488603 z, Y3=0.488603 x, Y4=1.092548 xy, Y5=1.092548 yz, Y6=0.315392 (3z^2-1), Y7=1.092548 xz, Y8=0.546274 (x^2-y^2)";

/// How to read [`Sh9::lambert`]'s coefficients, for the same documents.
pub const IRRADIANCE_TEXT: &str = "evaluate sum_i c_i Y_i(n) with irradiance_over_pi to get E(n)/pi, the radiance a white Lambertian surface with normal n reflects (Ramamoorthi & Hanrahan 2001: A0 = pi, A1 = 2pi/3, A2 = pi/4, divided by pi)";

/// The nine basis functions at unit direction `d`.
#[inline]
pub fn basis(d: DVec3) -> [f64; 9] {
    let (x, y, z) = (d.x, d.y, d.z);
    [
        K0,
        K1 * y,
        K1 * z,
        K1 * x,
        K2 * x * y,
        K2 * y * z,
        K20 * (3.0 * z * z - 1.0),
        K2 * x * z,
        K22 * (x * x - y * y),
    ]
}

#[inline(always)]
fn basis_f32(d: Vec3) -> [f32; 9] {
    let (x, y, z) = (d.x, d.y, d.z);
    [
        K0 as f32,
        K1 as f32 * y,
        K1 as f32 * z,
        K1 as f32 * x,
        K2 as f32 * x * y,
        K2 as f32 * y * z,
        K20 as f32 * (3.0 * z * z - 1.0),
        K2 as f32 * x * z,
        K22 as f32 * (x * x - y * y),
    ]
}

/// The band `l` of coefficient `i`.
#[inline]
pub fn band(i: usize) -> usize {
    match i {
        0 => 0,
        1..=3 => 1,
        _ => 2,
    }
}

/// Nine RGB coefficients.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sh9 {
    /// `coeffs[i][channel]`, index `i = l(l + 1) + m`.
    pub coeffs: [[f64; 3]; 9],
}

/// A window against ringing: a factor per band.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Window {
    /// No attenuation.
    #[default]
    None,
    /// Hann: `σ_l = (1 + cos(π l / width))/2` for `l < width`, else 0.
    Hann {
        /// The band at which the window reaches zero (> 0; 3 is a common choice).
        width: f64,
    },
    /// Lanczos: `σ_l = sin(π l/width)/(π l/width)` for `l < width`, else 0.
    Lanczos {
        /// The band at which the window reaches zero (> 0).
        width: f64,
    },
    /// The weakest Hann window whose irradiance is non-negative in every direction.
    NonNegative,
}

impl Window {
    /// Parses `none`, `hann[:W]`, `lanczos[:W]`, `auto` / `nonnegative`.
    pub fn parse(s: &str) -> Option<Window> {
        let s = s.trim().to_ascii_lowercase();
        let (name, arg) = match s.split_once(':') {
            Some((a, b)) => (a.to_string(), Some(b.trim().parse::<f64>().ok()?)),
            None => (s.clone(), None),
        };
        let width = arg.unwrap_or(3.0);
        if !(width.is_finite() && width > 0.0) {
            return None;
        }
        Some(match name.as_str() {
            "none" | "off" => Window::None,
            "hann" | "hanning" => Window::Hann { width },
            "lanczos" | "sinc" => Window::Lanczos { width },
            "auto" | "nonnegative" | "non-negative" | "dering" => Window::NonNegative,
            _ => return None,
        })
    }

    /// The factor for band `l` (for [`Window::NonNegative`], which depends on the
    /// coefficients, 1; see [`Sh9::windowed`]).
    pub fn factor(&self, l: usize) -> f64 {
        let l = l as f64;
        match *self {
            Window::None | Window::NonNegative => 1.0,
            Window::Hann { width } => {
                if l >= width {
                    0.0
                } else {
                    0.5 * (1.0 + (PI * l / width).cos())
                }
            }
            Window::Lanczos { width } => {
                if l == 0.0 {
                    1.0
                } else if l >= width {
                    0.0
                } else {
                    let x = PI * l / width;
                    x.sin() / x
                }
            }
        }
    }
}

impl Sh9 {
    /// The value at unit direction `d`.
    pub fn eval(&self, d: DVec3) -> [f64; 3] {
        let b = basis(d);
        let mut out = [0.0; 3];
        for (bi, c) in b.iter().zip(&self.coeffs) {
            for k in 0..3 {
                out[k] += bi * c[k];
            }
        }
        out
    }

    /// Each band scaled by `f(l)`.
    pub fn scaled_bands(&self, f: impl Fn(usize) -> f64) -> Sh9 {
        let mut out = *self;
        for (i, c) in out.coeffs.iter_mut().enumerate() {
            let s = f(band(i));
            for v in c.iter_mut() {
                *v *= s;
            }
        }
        out
    }

    /// The coefficients of the same function seen through `map`: `f'(d) = f(map.source_of(d))`
    /// (an engine's axes). Exact: the nine functions are closed under orthogonal maps, and
    /// the projection integral (Gauss–Legendre in z, 16 equal steps in longitude) is exact
    /// for the products of two of them.
    pub fn transformed(&self, map: &mirrorball_core::AxisMap) -> Sh9 {
        if map.is_identity() {
            return *self;
        }
        let mut out = Sh9::default();
        let steps = 16;
        for k in 0..steps {
            let phi = 2.0 * PI * (k as f64 + 0.5) / steps as f64;
            for (j, o) in out.coeffs.iter_mut().enumerate() {
                for (c, oc) in o.iter_mut().enumerate() {
                    // ∫ dφ ∫ dz: the φ sum is weighted 2π/steps.
                    *oc += 2.0 * PI / steps as f64
                        * mirrorball_core::quadrature::gauss_legendre(-1.0, 1.0, |z| {
                            let r = (1.0 - z * z).max(0.0).sqrt();
                            let d = DVec3::new(r * phi.cos(), z, r * phi.sin());
                            self.eval(map.source_of(d))[c] * basis(d)[j]
                        });
                }
            }
        }
        out
    }

    /// Convolved with Lambert's cosine and divided by π: evaluating the result gives `E/π`
    /// (`Â_l/π` = 1, 2/3, 1/4).
    pub fn lambert(&self) -> Sh9 {
        self.scaled_bands(|l| [1.0, 2.0 / 3.0, 0.25][l])
    }

    /// With `window` applied (for [`Window::NonNegative`], the weakest Hann window that
    /// makes the *irradiance* of the result non-negative everywhere).
    pub fn windowed(&self, window: Window) -> Sh9 {
        match window {
            Window::NonNegative => self.windowed(Window::Hann {
                width: self.nonnegative_hann_width(),
            }),
            w => self.scaled_bands(|l| w.factor(l)),
        }
    }

    /// The largest Hann width (weakest window) for which the irradiance is ≥ 0 in every
    /// direction (checked on 4096 Fibonacci directions, with a margin of 1e-6 of the mean);
    /// `f64::INFINITY` when no window is needed.
    pub fn nonnegative_hann_width(&self) -> f64 {
        let dirs = crate::directions::fibonacci(4096);
        let ok = |sh: &Sh9| -> bool {
            let conv = sh.lambert();
            let dc = conv.coeffs[0].map(|c| c * K0);
            dirs.iter().all(|&d| {
                let v = conv.eval(d);
                (0..3).all(|k| v[k] >= -1e-6 * dc[k].abs())
            })
        };
        if ok(self) {
            return f64::INFINITY;
        }
        // Bisection on t = 1/width ∈ (0, 1]: t = 1 keeps band 0 only.
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            let sh = self.scaled_bands(|l| Window::Hann { width: 1.0 / mid }.factor(l));
            if ok(&sh) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        1.0 / hi
    }

    /// The irradiance `E/π` in direction `d`, with `window` against ringing.
    pub fn irradiance(&self, d: DVec3, window: Window) -> [f64; 3] {
        self.windowed(window).lambert().eval(d)
    }
}

/// Projects `env` onto the nine basis functions with exact texel solid angles, fast: cube
/// maps use the shared face geometry; other projections their rows of directions.
pub fn project(env: &EnvMap) -> Sh9 {
    let c = env.channels();
    let (w, h) = (env.width() as usize, env.height() as usize);
    let p = *env.projection();
    let acc = if p.kind() == ProjectionKind::Cube && w == h {
        let geom = FaceGeometry::new(w);
        let rows = (0..6 * h).into_par_iter().map(|row| {
            let (f, y) = (row / h, row % h);
            let data = env.layers()[f].row(y as u32);
            let g = &geom.texels[y * w..(y + 1) * w];
            let mut acc = [[0.0f32; 3]; 9];
            for (px, g) in data.chunks_exact(c).zip(g) {
                let d = CubeFace::from_face(f, Vec3::new(g[0], g[1], g[2]));
                let b = basis_f32(d);
                let l = [px[0] * g[3], px[1] * g[3], px[2] * g[3]];
                for (a, bi) in acc.iter_mut().zip(b) {
                    a[0] += bi * l[0];
                    a[1] += bi * l[1];
                    a[2] += bi * l[2];
                }
            }
            acc.map(|a| a.map(|v| v as f64))
        });
        fold_in_order(rows, [[0.0; 3]; 9], add9)
    } else {
        let layers = p.layer_count();
        let rows = (0..layers * h).into_par_iter().map_init(
            || vec![None; w],
            |dirs, row| {
                let (layer, y) = (row / h, row % h);
                p.row_dirs(layer, y as u32, w as u32, h as u32, dirs);
                let data = env.layers()[layer].row(y as u32);
                let mut acc = [[0.0f64; 3]; 9];
                // A lat-long row's texels all cover the same solid angle.
                let row_omega = (p.kind() == ProjectionKind::LatLong)
                    .then(|| p.texel_solid_angle(layer, 0, y as u32, w as u32, h as u32));
                for (x, (px, d)) in data.chunks_exact(c).zip(dirs.iter()).enumerate() {
                    let Some((d, dens)) = *d else { continue };
                    if dens <= 0.0 {
                        continue;
                    }
                    let om = row_omega.unwrap_or_else(|| {
                        p.texel_solid_angle(layer, x as u32, y as u32, w as u32, h as u32)
                    });
                    let b = basis(d);
                    for (a, bi) in acc.iter_mut().zip(b) {
                        for k in 0..3 {
                            a[k] += bi * om * px[k] as f64;
                        }
                    }
                }
                acc
            },
        );
        fold_in_order(rows, [[0.0; 3]; 9], add9)
    };
    Sh9 { coeffs: acc }
}

fn add9(mut a: [[f64; 3]; 9], b: [[f64; 3]; 9]) -> [[f64; 3]; 9] {
    for (x, y) in a.iter_mut().zip(b) {
        for k in 0..3 {
            x[k] += y[k];
        }
    }
    a
}

/// The brute-force projection: for every texel, its centre direction from
/// [`WorldProjection::uv_to_dir`] and its exact solid angle from
/// [`WorldProjection::texel_solid_angle`], all in `f64`, summed in order. The yardstick for
/// [`project`].
pub fn project_reference(env: &EnvMap) -> Sh9 {
    let p = *env.projection();
    let (w, h) = (env.width(), env.height());
    let mut acc = [[0.0f64; 3]; 9];
    for (layer, img) in env.layers().iter().enumerate() {
        for y in 0..h {
            for x in 0..w {
                let om = p.texel_solid_angle(layer, x, y, w, h);
                if om <= 0.0 {
                    continue;
                }
                let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                let Some(d) = p.uv_to_dir(layer, uv) else {
                    continue;
                };
                let b = basis(d);
                let px = img.get(x, y);
                for (a, bi) in acc.iter_mut().zip(b) {
                    for k in 0..3 {
                        a[k] += bi * om * px[k] as f64;
                    }
                }
            }
        }
    }
    Sh9 { coeffs: acc }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Seen through any signed axis permutation, the SH evaluates at `d` as the original
    /// does at `source_of(d)`; and it is what projecting the transformed map gives.
    #[test]
    fn transformed_sh_is_the_sh_of_the_transformed_map() {
        use mirrorball_core::{Axis, AxisMap};
        let mut sh = Sh9::default();
        for (i, c) in sh.coeffs.iter_mut().enumerate() {
            *c = [0.3 + i as f64, -0.7 * i as f64, (i * i) as f64 * 0.11 - 1.0];
        }
        let maps = [
            AxisMap::mirror(Axis::X),
            AxisMap::mirror(Axis::Z),
            AxisMap::new([(Axis::Y, 1), (Axis::Z, 1), (Axis::X, -1)]).unwrap(),
            AxisMap::new([(Axis::Z, -1), (Axis::X, 1), (Axis::Y, -1)]).unwrap(),
        ];
        for m in maps {
            let t = sh.transformed(&m);
            for d in [
                DVec3::new(0.3, 0.4, -0.866).normalize(),
                DVec3::new(-0.9, 0.1, 0.2).normalize(),
                DVec3::Y,
            ] {
                let (a, b) = (t.eval(d), sh.eval(m.source_of(d)));
                for k in 0..3 {
                    assert!((a[k] - b[k]).abs() < 1e-11, "{m}: {a:?} vs {b:?}");
                }
            }
        }
        let proj = ProjectionKind::Cube.default_projection();
        let env = EnvMap::from_fn(proj, 32, 3, |d| {
            [
                (1.0 + d.x + d.y * d.z) as f32,
                (1.5 - d.z) as f32,
                (1.0 + d.x * d.x) as f32,
                1.0,
            ]
        });
        let m = maps[2];
        let moved = env.transformed(&m).unwrap();
        let (a, b) = (project(&env).transformed(&m), project(&moved));
        for (x, y) in a.coeffs.iter().flatten().zip(b.coeffs.iter().flatten()) {
            assert!((x - y).abs() < 1e-5, "{x} vs {y}");
        }
    }

    /// The coefficients do not depend on how many threads made them (nor on how rayon
    /// split the rows): a prefilter run writes the same `.sh.json` every time.
    #[test]
    fn projection_gives_the_same_bits_on_any_thread_count() {
        use mirrorball_core::Projection;
        let latlong = ProjectionKind::LatLong.default_projection();
        let cube = ProjectionKind::Cube.default_projection();
        let f = |d: DVec3| [(d.x * 3.1).sin() as f32 + 1.0, d.y as f32 + 1.5, 0.7, 1.0];
        let maps: [(Projection, u32); 2] = [(latlong, 96), (cube, 40)];
        for (p, size) in maps {
            let env = EnvMap::from_fn(p, size, 3, f);
            let on = |threads: usize| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap()
                    .install(|| project(&env))
            };
            let one = on(1);
            for threads in [2, 3, 7] {
                let bits = |s: &Sh9| s.coeffs.map(|c| c.map(f64::to_bits));
                assert_eq!(
                    bits(&on(threads)),
                    bits(&one),
                    "{:?}, {threads} threads",
                    p.kind()
                );
            }
        }
    }

    #[test]
    #[allow(clippy::needless_range_loop)]
    fn basis_is_orthonormal() {
        let dirs = crate::directions::fibonacci(20_000);
        let mut g = [[0.0f64; 9]; 9];
        for d in &dirs {
            let b = basis(*d);
            for i in 0..9 {
                for j in 0..9 {
                    g[i][j] += b[i] * b[j] * 4.0 * PI / dirs.len() as f64;
                }
            }
        }
        for i in 0..9 {
            for j in 0..9 {
                let e = if i == j { 1.0 } else { 0.0 };
                assert!((g[i][j] - e).abs() < 2e-3, "{i} {j} {}", g[i][j]);
            }
        }
    }

    #[test]
    fn windows() {
        assert_eq!(Window::Hann { width: 3.0 }.factor(0), 1.0);
        assert!((Window::Hann { width: 3.0 }.factor(1) - 0.75).abs() < 1e-12);
        assert_eq!(
            Window::parse("lanczos:4"),
            Some(Window::Lanczos { width: 4.0 })
        );
        assert_eq!(Window::parse("auto"), Some(Window::NonNegative));
        assert!(Window::parse("hann:-1").is_none());
    }
}
