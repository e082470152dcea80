//! The working representation of the prefilterers: an OpenGL cube map with a
//! solid-angle-weighted box mip pyramid whose faces carry a one-texel border copied from
//! their neighbours, so that bilinear and trilinear lookups are seamless (as
//! ARB_seamless_cube_map filters: across an edge from the adjacent face; at a corner, the
//! missing texel is the mean of the three that meet there) without any branch in the inner
//! loop. `f32`, four channels (RGB and a spare), in `glam::Vec4` for SIMD.

use crate::lobe::Lobe;
use crate::mip::{downsample, MipFilter};
use glam::{Vec3, Vec4};
use mirrorball_core::{
    resample, CubeFace, CubeMap, EnvMap, Image, Projection, ResampleOptions, WorldProjection,
};
use rayon::prelude::*;

/// `log₂ x` for positive normal `x`, to about 2e-4 (exponent plus a quartic in the
/// mantissa, least-squares fit on `[1, 2)` with `p(1) = 0`). Mip level selection needs no
/// more.
#[inline(always)]
pub(crate) fn fast_log2(x: f32) -> f32 {
    let bits = x.to_bits();
    let e = ((bits >> 23) & 0xff) as i32 - 127;
    let t = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000) - 1.0;
    let p = t * (1.438_545_4 + t * (-0.678_071_5 + t * (0.323_610_5 - 0.084_273_16 * t)));
    e as f32 + p
}

/// Fills one level (six faces of `size²` texels) with a one-texel border,
/// `stride = size + 2`, into `out` (`6·stride²` texels).
fn pad_level(faces: &[Image], out: &mut [Vec4]) {
    let size = faces[0].width() as usize;
    let stride = size + 2;
    let proj = CubeMap;
    let texel = |f: usize, x: i64, y: i64| -> Vec4 {
        let (l, tx, ty) = if x >= 0 && y >= 0 && x < size as i64 && y < size as i64 {
            (f, x as u32, y as u32)
        } else {
            proj.wrap_texel(f, x, y, size as u32, size as u32)
        };
        let t = faces[l].get(tx, ty);
        Vec4::new(t[0], t[1], t[2], if t.len() > 3 { t[3] } else { 1.0 })
    };
    let c = faces[0].channels();
    // Row by row (`6·stride` rows): a face's own rows straight from the image, with their
    // two border texels through the wrap; the border rows above and below through the wrap.
    out.par_chunks_mut(stride)
        .enumerate()
        .for_each(|(row, line)| {
            let (f, py) = (row / stride, row % stride);
            let y = py as i64 - 1;
            if (0..size as i64).contains(&y) {
                let src = faces[f].row(y as u32);
                for (o, t) in line[1..=size].iter_mut().zip(src.chunks_exact(c)) {
                    *o = Vec4::new(t[0], t[1], t[2], if c > 3 { t[3] } else { 1.0 });
                }
                line[0] = texel(f, -1, y);
                line[size + 1] = texel(f, size as i64, y);
                return;
            }
            for (px, o) in line.iter_mut().enumerate() {
                let x = px as i64 - 1;
                *o = if x < 0 || x >= size as i64 {
                    // A corner: the mean of the three texels that meet there.
                    let cx = x.clamp(0, size as i64 - 1);
                    let cy = y.clamp(0, size as i64 - 1);
                    (texel(f, cx, cy) + texel(f, x, cy) + texel(f, cx, y)) / 3.0
                } else {
                    texel(f, x, y)
                };
            }
        });
}

/// One level of a [`SeamlessCube`].
pub(crate) struct Level {
    /// Face size.
    pub size: f32,
    /// Bordered row stride, `size + 2`.
    pub stride: usize,
    /// Where each of the six bordered faces starts in the texel buffer.
    pub face: [usize; 6],
}

/// A cube map with its seamless, solid-angle-weighted box pyramid, for fast lookups: every
/// level's six bordered faces in one buffer.
///
/// Addresses are integers: a face's start (`usize`) plus `y·stride + x` within the face,
/// with `x` and `y` converted from `f32` each on their own (both below 2²³, so exact). Only
/// the continuous coordinate `u·size + ½` is `f32`: for faces up to 4096² its rounding
/// error is at most about `2⁻¹¹` texel (the `f32` spacing near 4096, plus `u`'s own
/// relative error of a few `2⁻²⁴` from the face division), which moves a bilinear weight by
/// under 0.1%; the largest working cube is 4096² ([`MAX_CUBE`]).
pub(crate) struct SeamlessCube {
    texels: Vec<Vec4>,
    /// Per level, finest first.
    levels: Vec<Level>,
    /// `0.5·log₂(4/size₀²)`: half the log₂ of a level-0 texel's solid angle per `|ma|³`.
    half_log2_texel0: f32,
    /// The coarsest level, as a float.
    last_lod: f32,
}

impl SeamlessCube {
    /// The seamless box pyramid of a cube map with square power-of-two faces (box filter:
    /// energy-exact), made a level at a time: only the level being padded and the one it is
    /// made from exist besides the bordered buffer.
    pub fn new(cube: &EnvMap) -> SeamlessCube {
        let s0 = cube.width() as usize;
        let mut levels = Vec::new();
        let mut total = 0usize;
        let mut s = s0;
        loop {
            levels.push(Level {
                size: s as f32,
                stride: s + 2,
                face: std::array::from_fn(|f| total + f * (s + 2) * (s + 2)),
            });
            total += 6 * (s + 2) * (s + 2);
            if s == 1 {
                break;
            }
            s = (s / 2).max(1);
        }
        let mut texels = vec![Vec4::ZERO; total];
        let mut rest = texels.as_mut_slice();
        let mut level: Option<EnvMap> = None;
        for (l, lv) in levels.iter().enumerate() {
            if l > 0 {
                level = Some(downsample(level.as_ref().unwrap_or(cube), MipFilter::Box));
            }
            let cur = level.as_ref().unwrap_or(cube);
            let st = lv.stride;
            let (head, tail) = rest.split_at_mut(6 * st * st);
            pad_level(cur.layers(), head);
            rest = tail;
        }
        let s0 = s0 as f32;
        let last_lod = (levels.len() - 1) as f32;
        SeamlessCube {
            texels,
            levels,
            half_log2_texel0: 0.5 * (4.0 / (s0 * s0)).log2(),
            last_lod,
        }
    }

    /// `½ log₂(4/size₀²)`.
    #[inline(always)]
    pub fn half_log2_texel0(&self) -> f32 {
        self.half_log2_texel0
    }

    /// The coarsest level index.
    #[inline(always)]
    pub fn last_lod(&self) -> f32 {
        self.last_lod
    }

    /// Level `l`'s size, stride and face starts together.
    #[inline(always)]
    pub fn level(&self, l: usize) -> &Level {
        &self.levels[l]
    }

    /// The four texels of a bilinear footprint: `[i, i + 1, i + stride, i + stride + 1]`.
    #[inline(always)]
    pub fn quad(&self, i: usize, stride: usize) -> [Vec4; 4] {
        let d = &self.texels[i..i + stride + 2];
        [d[0], d[1], d[stride], d[stride + 1]]
    }

    /// Bilinear lookup at `(u, v)` ∈ `[0, 1]²` of `face` on level `l`; seamless thanks to
    /// the border.
    #[inline(always)]
    pub fn bilinear(&self, l: usize, face: usize, u: f32, v: f32) -> Vec4 {
        // Bordered texel i + 1 has its centre at u = (i + ½)/size, so the bordered
        // continuous coordinate is u·size + ½ ∈ [½, size + ½]; clamping below size + ½ keeps
        // x0 + 1 ≤ size + 1 and lets a truncating conversion act as floor.
        let lv = self.level(l);
        let max = lv.size + 0.499_9;
        let x = (u * lv.size + 0.5).max(0.5).min(max);
        let y = (v * lv.size + 0.5).max(0.5).min(max);
        let (x0, y0) = (x as u32, y as u32);
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let st = lv.stride;
        let i = lv.face[face] + y0 as usize * st + x0 as usize;
        let [a, b, c, d] = self.quad(i, st);
        a.lerp(b, fx).lerp(c.lerp(d, fx), fy)
    }

    /// Trilinear lookup in direction `d` at the mip level whose texels cover solid angle
    /// `2^(2·half_log2_omega)` where `d` lands: level 0 texels there cover
    /// `(2/size₀)²·|ma|³` steradians (the cube's area element `4/(1 + a² + b²)^{3/2}` times
    /// the texel's `uv` area, and `1 + a² + b² = 1/ma²` for a unit direction).
    #[inline(always)]
    pub fn lookup(&self, d: Vec3, half_log2_omega: f32) -> Vec4 {
        let (face, sc, tc, ma) = CubeFace::select_f32(d);
        let inv = 0.5 / ma;
        let (u, v) = (sc * inv + 0.5, tc * inv + 0.5);
        let lod = half_log2_omega - self.half_log2_texel0 - 1.5 * fast_log2(ma);
        self.trilinear(face, u, v, lod)
    }

    /// Trilinear lookup at `(face, u, v)` and fractional level `lod`.
    #[inline(always)]
    pub fn trilinear(&self, face: usize, u: f32, v: f32, lod: f32) -> Vec4 {
        let lod = lod.max(0.0).min(self.last_lod);
        let l0 = lod as i32 as usize;
        let f = lod - l0 as f32;
        let a = self.bilinear(l0, face, u, v);
        if f <= 0.0 {
            return a;
        }
        let b = self.bilinear((l0 + 1).min(self.levels.len() - 1), face, u, v);
        a.lerp(b, f)
    }
}

/// The largest working cube face. Six 4096² faces of `Vec4` are 1.6 GB, and the bordered
/// pyramid of the body (bright texels capped) as much again plus a third; with the pyramid
/// of the whole map (made when bright texels were split off) a 4096² working cube holds
/// about 5.9 GB, and building it briefly about 1.6 GB more.
pub(crate) const MAX_CUBE: u32 = 4096;

/// The coarsest working cube chosen for a lobe: 256² faces (a texel's centre is at most
/// 0.0055 rad from any point it stands for, so a point source's share of the widest
/// lobe, Lambert's, moves by at most about 0.5%).
pub(crate) const MIN_CUBE: u32 = 256;

/// The working-cube face size that rendering `lobe` into `w×h` layers of `out` needs.
///
/// The result can resolve nothing finer than the larger of the output's texels and the
/// lobe's own blur, so the working cube's texels need only be as small as that:
///
/// * `t_out`: the output's mean texel side, `√(Ω_covered/texels)` (a cube output of face
///   `N`: `1.447/N`);
/// * `t_lobe`: half the lobe's half-maximum radius ([`Lobe::angular_scale`]; 0 for a
///   mirror). Samples that stand for less than a working texel read level 0, whose
///   bilinear tent (variance `t²/6` per axis) then widens the lobe: for a texel of side
///   `t_lobe`, a Gaussian of that half-maximum radius by about 3% (GGX's heavier tails, by
///   less);
/// * the face size whose mean texel side is `max(t_out, t_lobe)`: `s = √(4π/6)/t`, at
///   least [`MIN_CUBE`] (the caller rounds up to a power of two and caps at the source's
///   own density).
///
/// A chain whose level 0 is `N²` (`N` a power of two, any lobes) so needs an `N²` working
/// cube: level `m` has `N/2ᵐ` faces and needs at most that. Its mirror level is then the
/// working cube itself, the antialiased conversion of the source at `N`, which is what a
/// mirror level should hold; reading a `2N` cube's level 1 instead would add a box over
/// its bilinear samples. Rough lobes need little whatever the output: GGX roughness 1/9
/// (level 1 of the linear mapping on ten levels) needs 183, roughness ½ needs 10 (so
/// [`MIN_CUBE`]).
pub(crate) fn needed_face(lobe: &Lobe, out: &Projection, w: u32, h: u32) -> u32 {
    let texels = w.max(1) as f64 * h.max(1) as f64 * out.layer_count() as f64;
    let t_out = (out.covered_solid_angle() / texels).sqrt();
    let t_lobe = if lobe.is_mirror() {
        0.0
    } else {
        0.5 * lobe.angular_scale()
    };
    let s = (4.0 * std::f64::consts::PI / 6.0).sqrt() / t_out.max(t_lobe);
    // A cube output of face N gives s = N up to rounding, which must not round up to N + 1.
    ((s * (1.0 - 1e-9)).ceil().min(MAX_CUBE as f64) as u32).max(MIN_CUBE)
}

/// The face size of a cube with the same mean texel density (texels per steradian) as
/// `src` (a cube's own face size).
fn source_face(src: &EnvMap) -> u32 {
    if src.projection().kind() == mirrorball_core::ProjectionKind::Cube {
        return src.width();
    }
    let n = src.width() as f64 * src.height() as f64 * src.layers().len() as f64;
    let per_face = n * (4.0 * std::f64::consts::PI / src.projection().covered_solid_angle()) / 6.0;
    (per_face.sqrt().ceil() as u32).clamp(1, MAX_CUBE)
}

/// The largest power of two not above `x` (≥ 1).
fn floor_pow2(x: u32) -> u32 {
    1 << (31 - x.max(1).leading_zeros())
}

/// The face size of the working cube: `size` when given (rounded up to a power of two, at
/// most [`MAX_CUBE`]); otherwise `need` (see [`needed_face`]; `None`: no limit) rounded up
/// to a power of two but no finer than the source's own density rounded up to one, and at
/// most `max_size`.
pub(crate) fn working_face(
    src: &EnvMap,
    size: Option<u32>,
    need: Option<u32>,
    max_size: u32,
) -> u32 {
    if let Some(s) = size {
        return s.clamp(1, MAX_CUBE).next_power_of_two();
    }
    let density = source_face(src).next_power_of_two();
    let s = need.map_or(density, |n| n.next_power_of_two().min(density));
    s.min(floor_pow2(max_size.clamp(1, MAX_CUBE)))
}

/// The prefilterers' working map: a cube of `face²` faces with four channels, `src` itself
/// when it already is one, otherwise an antialiased conversion.
///
/// `progress`, when given, counts each row resampled with `unit` (the prefilter's bar).
pub(crate) fn working_cube(
    src: &EnvMap,
    face: u32,
    progress: Option<(std::sync::Arc<std::sync::atomic::AtomicU64>, u64)>,
) -> EnvMap {
    let is_cube = src.projection().kind() == mirrorball_core::ProjectionKind::Cube;
    if is_cube && src.width() == face {
        return with_four_channels(src.clone());
    }
    let (progress, progress_unit) = match progress {
        Some((p, unit)) => (Some(p), unit),
        None => (None, 1),
    };
    let opts = ResampleOptions {
        progress,
        progress_unit,
        ..ResampleOptions::default()
    };
    let out = resample(src, Projection::Cube(CubeMap), face, &opts);
    with_four_channels(out)
}

fn with_four_channels(env: EnvMap) -> EnvMap {
    if env.channels() == 4 {
        return env;
    }
    let proj = *env.projection();
    let layers = env.layers().iter().map(|l| l.with_channels(4)).collect();
    EnvMap::new(proj, layers).expect("same shape")
}

/// Builds the seamless pyramid of a cube map.
pub(crate) fn seamless_pyramid(cube: &EnvMap) -> SeamlessCube {
    SeamlessCube::new(cube)
}

/// Face-local geometry shared by the six faces of a `size²` cube: for texel `(x, y)`,
/// `a = 2(x + ½)/size − 1`, `b = 2(y + ½)/size − 1`, the unit direction in the face frame
/// `(a, b, 1)/√(1 + a² + b²)` and the exact solid angle
/// `F(a₁, b₁) − F(a₀, b₁) − F(a₁, b₀) + F(a₀, b₀)`, `F(a, b) = atan(ab/√(1 + a² + b²))`,
/// from a table of `F` at the `(size + 1)²` texel corners (odd in each argument, so only
/// a quadrant is computed).
pub(crate) struct FaceGeometry {
    /// `(a/ρ, b/ρ, 1/ρ, Ω)` per texel, row-major, `ρ = √(1 + a² + b²)`.
    pub texels: Vec<[f32; 4]>,
}

/// `F(a, b) = atan(ab/√(1 + a² + b²))` at the `(size + 1)²` texel corners of a cube face
/// (the solid angle of the face rectangle `[0, a]×[0, b]`). `F` is odd in each argument, so
/// for even sizes only the quadrant `a, b ≥ 0` is computed.
struct CornerTable {
    size: usize,
    half: usize,
    q: usize,
    even: bool,
    table: Vec<f64>,
}

impl CornerTable {
    fn new(size: usize) -> CornerTable {
        let n = size + 1;
        let half = size / 2;
        let even = size.is_multiple_of(2);
        let corner = |i: usize| 2.0 * i as f64 / size as f64 - 1.0;
        let (q, base) = if even { (n - half, half) } else { (n, 0) };
        let table = (0..q * q)
            .into_par_iter()
            .map(|k| {
                let (a, b) = (corner(base + k % q), corner(base + k / q));
                (a * b / (1.0 + a * a + b * b).sqrt()).atan()
            })
            .collect();
        CornerTable {
            size,
            half,
            q,
            even,
            table,
        }
    }

    /// `F` at corner `(i, j)`.
    #[inline]
    fn f(&self, i: usize, j: usize) -> f64 {
        if self.even {
            let h = self.half;
            let (si, ii) = if i >= h { (1.0, i - h) } else { (-1.0, h - i) };
            let (sj, jj) = if j >= h { (1.0, j - h) } else { (-1.0, h - j) };
            si * sj * self.table[jj * self.q + ii]
        } else {
            self.table[j * self.q + i]
        }
    }

    /// The exact solid angle of texel `(x, y)`.
    #[inline]
    fn omega(&self, x: usize, y: usize) -> f64 {
        debug_assert!(x < self.size && y < self.size);
        self.f(x + 1, y + 1) - self.f(x, y + 1) - self.f(x + 1, y) + self.f(x, y)
    }
}

/// Exact solid angles of the texels of one `size²` cube face (the same for all six), row
/// by row: `F(a₁, b₁) − F(a₀, b₁) − F(a₁, b₀) + F(a₀, b₀)` from [`CornerTable`].
pub(crate) fn face_solid_angles(size: usize) -> Vec<f64> {
    let t = CornerTable::new(size);
    (0..size * size)
        .into_par_iter()
        .map(|k| t.omega(k % size, k / size))
        .collect()
}

impl FaceGeometry {
    pub fn new(size: usize) -> FaceGeometry {
        let t = CornerTable::new(size);
        let texels = (0..size * size)
            .into_par_iter()
            .map(|k| {
                let (x, y) = (k % size, k / size);
                let a = 2.0 * (x as f64 + 0.5) / size as f64 - 1.0;
                let b = 2.0 * (y as f64 + 0.5) / size as f64 - 1.0;
                let inv = 1.0 / (1.0 + a * a + b * b).sqrt();
                [
                    (a * inv) as f32,
                    (b * inv) as f32,
                    inv as f32,
                    t.omega(x, y) as f32,
                ]
            })
            .collect();
        FaceGeometry { texels }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn select_matches_core() {
        for i in 0..2000 {
            let t = i as f64 * 0.618_033_988_749_895;
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / 2000.0;
            let r = (1.0 - z * z).sqrt();
            let a = t * std::f64::consts::TAU;
            let d = DVec3::new(r * a.cos(), z, r * a.sin());
            let (f, uv) = CubeMap.dir_to_uv(d).unwrap();
            let (g, sc, tc, ma) = CubeFace::select_f32(d.as_vec3());
            assert_eq!(f, g);
            assert!(((sc / ma * 0.5 + 0.5) as f64 - uv.x).abs() < 1e-5);
            assert!(((tc / ma * 0.5 + 0.5) as f64 - uv.y).abs() < 1e-5);
            let w = CubeFace::from_face(f, Vec3::new(sc / ma, tc / ma, 1.0) * ma);
            assert!((w.as_dvec3() - d).length() < 1e-5);
        }
    }

    #[test]
    fn working_cube_follows_the_outputs() {
        use crate::lobe::LobeKind;
        use crate::prefilter::chain_lobes;
        use crate::specular::RoughnessMapping;
        let cube = Projection::Cube(CubeMap);
        let ll = mirrorball_core::ProjectionKind::LatLong.default_projection();
        let mirror = Lobe::Phong {
            exponent: f64::INFINITY,
        };
        // A mirror into a cube of face N needs N; small outputs get the least cube.
        assert_eq!(needed_face(&mirror, &cube, 512, 512), 512);
        assert_eq!(needed_face(&mirror, &cube, 2048, 2048), 2048);
        assert_eq!(needed_face(&mirror, &cube, 64, 64), MIN_CUBE);
        // Lambert's blur (π/3) is far wider than a 512² output's texels.
        assert_eq!(needed_face(&Lobe::Lambert, &cube, 512, 512), MIN_CUBE);
        // Rough lobes need less than their output: GGX roughness 1/9 needs 183.
        let r9 = Lobe::Ggx {
            roughness: 1.0 / 9.0,
        };
        assert_eq!(needed_face(&r9, &cube, 4096, 4096), MIN_CUBE);
        // Every level of a GGX chain of edge N needs at most N, level 0 exactly N.
        for n in [256u32, 512, 1024] {
            let lobes = chain_lobes(LobeKind::Ggx, &RoughnessMapping::Linear, 10);
            let need: Vec<u32> = lobes
                .iter()
                .enumerate()
                .map(|(i, l)| needed_face(l, &cube, (n >> i).max(1), (n >> i).max(1)))
                .collect();
            assert_eq!(need[0], n);
            assert!(need.iter().all(|&s| s <= n), "{need:?}");
        }
        // A 1024×512 lat-long output: mean texel 0.0049 rad, so 512² faces.
        assert_eq!(
            needed_face(&mirror, &ll, 1024, 512).next_power_of_two(),
            512
        );
        // The source bounds the choice; an explicit size is honoured up to MAX_CUBE.
        let src = EnvMap::new(ll, vec![Image::new(4096, 2048, 3)]).unwrap();
        assert_eq!(working_face(&src, None, None, 2048), 2048);
        assert_eq!(working_face(&src, None, Some(512), 2048), 512);
        assert_eq!(working_face(&src, None, Some(MAX_CUBE), 2048), 2048);
        assert_eq!(working_face(&src, None, Some(MAX_CUBE), 4096), 2048);
        assert_eq!(working_face(&src, Some(4096), Some(512), 2048), 4096);
        assert_eq!(working_face(&src, Some(3000), None, 2048), 4096);
        assert_eq!(working_face(&src, Some(9000), None, 2048), MAX_CUBE);
        let small = EnvMap::new(ll, vec![Image::new(512, 256, 3)]).unwrap();
        assert_eq!(working_face(&small, None, Some(1024), 2048), 256);
    }

    #[test]
    fn log2_is_close() {
        for i in 1..10_000 {
            let x = i as f32 * 0.013;
            assert!((fast_log2(x) - x.log2()).abs() < 3e-4);
        }
    }

    #[test]
    fn face_geometry_solid_angles() {
        for size in [1usize, 2, 5, 8] {
            let g = FaceGeometry::new(size);
            let mut total = 0.0;
            for y in 0..size {
                for x in 0..size {
                    let om =
                        CubeMap.texel_solid_angle(0, x as u32, y as u32, size as u32, size as u32);
                    let t = g.texels[y * size + x];
                    assert!(
                        (t[3] as f64 - om).abs() < 1e-6 * om.max(1e-3),
                        "{size} {x} {y}"
                    );
                    total += t[3] as f64;
                }
            }
            assert!((total - 4.0 * std::f64::consts::PI / 6.0).abs() < 1e-5);
        }
    }
}
