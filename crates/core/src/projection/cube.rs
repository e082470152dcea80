//! The cube projection (Greene 1986, §3), exactly as OpenGL samples a cube map.

use super::{texel_range, DirRun, Lookup, WorldProjection};
use glam::{DVec2, DVec3, Vec3};
use mirrorball_simd::{F32x4, F32x8, I32x4, I32x8, M32x4, M32x8, X8};

/// [`face_coords`] with the face chosen as [`CubeFace::select_f32`] chooses it, by masks:
/// `x` major (ties to x), else `y` major (ties to y), else `z`; its positive side where the
/// component is `≥ 0`. Written once for [`F32x4`] and [`F32x8`] (`[$splat]`: what makes a
/// lane constant; `$m`: the mask type), without closures: a closure is compiled as a
/// function of its own, without an eight-lane kernel's AVX2.
macro_rules! select_lanes {
    ($x:expr, $y:expr, $z:expr, [$($splat:tt)+], [$($splat_i:tt)+], $m:ty) => {{
        let (x, y, z) = ($x, $y, $z);
        let (ax, ay, az) = (x.abs(), y.abs(), z.abs());
        let is_x: $m = ax.ge(ay) & ax.ge(az);
        let is_y: $m = ay.ge(az).and_not(is_x);
        let is_z: $m = !(is_x | is_y);
        let zero = $($splat)+(0.0);
        let (px, py, pz) = (x.ge(zero), y.ge(zero), z.ge(zero));
        let pos = (is_x & px) | (is_y & py) | (is_z & pz);
        FaceLanes {
            // 0, 2 or 4 by the major axis, plus 1 on its negative side (a set mask is −1).
            layer: is_x.select_i32(
                $($splat_i)+(0),
                is_y.select_i32($($splat_i)+(2), $($splat_i)+(4)),
            )
                - (!pos).to_i32(),
            sc: is_x.select(px.select(-z, z), is_y.select(x, pz.select(x, -x))),
            tc: is_x.select(-y, is_y.select(py.select(z, -z), -y)),
            ma: is_x.select(ax, is_y.select(ay, az)),
        }
    }};
}

/// One face of a cube map, in OpenGL's order (ARB_texture_cube_map, OpenGL 4.6 §8.13):
/// `TEXTURE_CUBE_MAP_POSITIVE_X` = layer 0 … `NEGATIVE_Z` = layer 5. KTX2, DDS and Vulkan
/// use the same order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum CubeFace {
    /// +X, layer 0.
    PosX = 0,
    /// −X, layer 1.
    NegX = 1,
    /// +Y, layer 2.
    PosY = 2,
    /// −Y, layer 3.
    NegY = 3,
    /// +Z, layer 4.
    PosZ = 4,
    /// −Z, layer 5.
    NegZ = 5,
}

impl CubeFace {
    /// All six, in layer order.
    pub const ALL: [CubeFace; 6] = [
        CubeFace::PosX,
        CubeFace::NegX,
        CubeFace::PosY,
        CubeFace::NegY,
        CubeFace::PosZ,
        CubeFace::NegZ,
    ];

    /// The face with this layer index (0..6).
    pub fn from_index(i: usize) -> Option<CubeFace> {
        CubeFace::ALL.get(i).copied()
    }

    /// Short name: `+x`, `-x`, …
    pub fn name(self) -> &'static str {
        ["+x", "-x", "+y", "-y", "+z", "-z"][self as usize]
    }

    /// The face OpenGL selects for direction `r`, with its `(sc, tc, ma)` from the
    /// major-axis table (OpenGL 4.6, table 8.19). Ties go to x, then y (the specification
    /// leaves them to the implementation).
    #[inline]
    pub fn select(r: DVec3) -> (CubeFace, f64, f64, f64) {
        let a = r.abs();
        let (layer, ma) = major_face(r.x, r.y, r.z, a.x, a.y, a.z);
        let (sc, tc, _) = face_coords(layer, r.x, r.y, r.z);
        (CubeFace::ALL[layer], sc, tc, ma)
    }

    /// [`CubeFace::select`] in `f32` for the fast paths of the filter and render crates:
    /// `(layer, sc, tc, |ma|)`, with the same ties.
    #[inline(always)]
    pub fn select_f32(d: Vec3) -> (usize, f32, f32, f32) {
        let a = d.abs();
        let (layer, ma) = major_face(d.x, d.y, d.z, a.x, a.y, a.z);
        let (sc, tc, _) = face_coords(layer, d.x, d.y, d.z);
        (layer, sc, tc, ma)
    }

    /// [`CubeFace::select_f32`] of four directions given as lanes of their components, the
    /// face chosen by masks instead of branches: lane `k` is, to the bit, `select_f32` of
    /// direction `k` (the same ties, the same sign flips; tested).
    #[inline(always)]
    pub fn select4(x: F32x4, y: F32x4, z: F32x4) -> FaceLanes<F32x4, I32x4> {
        select_lanes!(x, y, z, [F32x4::splat], [I32x4::splat], M32x4)
    }

    /// [`CubeFace::select4`] of eight directions (AVX2 where the processor has it: `x8`).
    #[inline(always)]
    pub fn select8(x8: X8, x: F32x8, y: F32x8, z: F32x8) -> FaceLanes<F32x8, I32x8> {
        select_lanes!(x, y, z, [x8.splat], [x8.splat_i32], M32x8)
    }

    /// The point on the unit cube for face coordinates `sc`, `tc` ∈ `[-1, 1]` (the inverse
    /// of the table; also meaningful a little outside the face, which filtering uses).
    #[inline]
    pub fn point(self, sc: f64, tc: f64) -> DVec3 {
        DVec3::from(face_point(self as usize, sc, tc, 1.0))
    }

    /// The world vector of face-local coordinates `l = (sc, tc, ma)` on face `layer` (the
    /// map [`CubeFace::point`] is with `ma = 1`, linear in `l`): the inverse of
    /// [`CubeFace::to_face`].
    #[inline(always)]
    pub fn from_face(layer: usize, l: Vec3) -> Vec3 {
        Vec3::from(face_point(layer, l.x, l.y, l.z))
    }

    /// The face-local coordinates `(sc, tc, ma)` of world vector `w` on face `layer` (the
    /// table's row for that face, `ma` signed): the inverse of [`CubeFace::from_face`].
    #[inline(always)]
    pub fn to_face(layer: usize, w: Vec3) -> Vec3 {
        let (sc, tc, ma) = face_coords(layer, w.x, w.y, w.z);
        Vec3::new(sc, tc, ma)
    }
}

/// What [`CubeFace::select4`] and [`CubeFace::select8`] give, lane by lane: the layer
/// (0..6), `sc`, `tc` and `|ma|`.
#[derive(Clone, Copy, Debug)]
pub struct FaceLanes<F, I> {
    /// The face's layer index.
    pub layer: I,
    /// `sc` of the major-axis table.
    pub sc: F,
    /// `tc` of the major-axis table.
    pub tc: F,
    /// `|ma|`, the major axis's magnitude.
    pub ma: F,
}

/// The face OpenGL selects for `(x, y, z)` with magnitudes `(ax, ay, az)`, and `|ma|`: the
/// major axis, ties going to x, then y (the specification leaves them to the
/// implementation); its positive face where the component is `≥ 0` (so `-0.0` is positive,
/// and a NaN component, never major unless it is z, negative).
#[inline(always)]
fn major_face<T: Copy + PartialOrd + Default>(x: T, y: T, z: T, ax: T, ay: T, az: T) -> (usize, T) {
    let zero = T::default();
    if ax >= ay && ax >= az {
        (if x >= zero { 0 } else { 1 }, ax)
    } else if ay >= az {
        (if y >= zero { 2 } else { 3 }, ay)
    } else {
        (if z >= zero { 4 } else { 5 }, az)
    }
}

/// The major-axis table (OpenGL 4.6 §8.13, table 8.19), one row a face: the `(sc, tc, ma)`
/// of `(x, y, z)` on face `layer` (`ma` signed, positive on the face's own side).
/// `(s, t) = ((sc/|ma| + 1)/2, (tc/|ma| + 1)/2)`.
#[inline(always)]
fn face_coords<T: Copy + std::ops::Neg<Output = T>>(layer: usize, x: T, y: T, z: T) -> (T, T, T) {
    match layer {
        0 => (-z, -y, x),
        1 => (z, -y, -x),
        2 => (x, z, y),
        3 => (x, -z, -y),
        4 => (x, -y, z),
        _ => (-x, -y, -z),
    }
}

/// The inverse of [`face_coords`] (each row a signed permutation, so its transpose): the
/// `(x, y, z)` of `(sc, tc, ma)` on face `layer`.
#[inline(always)]
fn face_point<T: Copy + std::ops::Neg<Output = T>>(layer: usize, sc: T, tc: T, ma: T) -> [T; 3] {
    match layer {
        0 => [ma, -tc, -sc],
        1 => [-ma, -tc, sc],
        2 => [sc, ma, tc],
        3 => [sc, -ma, -tc],
        4 => [sc, -tc, ma],
        _ => [-sc, -tc, -ma],
    }
}

/// The OpenGL cube map. Direction `r` selects the face of its major axis and
/// `s = (sc/|ma| + 1)/2`, `t = (tc/|ma| + 1)/2` (OpenGL 4.6 eq. 8.8). Face images are stored
/// as OpenGL reads them: row 0 is `t = 0`, so `(u, v) = (s, t)`. Laid out as a horizontal
/// cross these faces join up without mirroring (tested).
///
/// Area element: with `a = 2u − 1`, `b = 2v − 1`, the face point is `(a, b, 1)` and
/// `dω = da db / (1 + a² + b²)^{3/2}`, whose antiderivative is
/// `F(a, b) = atan(ab / √(1 + a² + b²))`, so texel solid angles are exact in closed form.
///
/// ```
/// use mirrorball_core::{CubeMap, WorldProjection};
/// use glam::DVec3;
/// let (face, uv) = CubeMap.dir_to_uv(DVec3::new(0.0, 0.0, -1.0)).unwrap();
/// assert_eq!(face, 5); // -Z
/// assert!((uv.x - 0.5).abs() < 1e-12 && (uv.y - 0.5).abs() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CubeMap;

impl CubeMap {
    /// `(layer, u, v, |ma|)` of direction `d` (any length) in `f32`, by eq. 8.8 as
    /// `u = sc·(½/|ma|) + ½`: the fast paths' form of [`WorldProjection::dir_to_uv`].
    /// Meaningless (`u`, `v` not finite) where `|ma|` is zero or NaN; callers test that.
    #[inline(always)]
    pub fn uv_f32(d: Vec3) -> (usize, f32, f32, f32) {
        let (layer, sc, tc, ma) = CubeFace::select_f32(d);
        let k = 0.5 / ma;
        (layer, sc * k + 0.5, tc * k + 0.5, ma)
    }

    /// [`CubeMap::uv_f32`] of four directions, lane by lane to the bit.
    #[inline(always)]
    pub fn uv4(x: F32x4, y: F32x4, z: F32x4) -> FaceLanes<F32x4, I32x4> {
        let f = CubeFace::select4(x, y, z);
        let (k, half) = (F32x4::splat(0.5) / f.ma, F32x4::splat(0.5));
        FaceLanes {
            sc: f.sc * k + half,
            tc: f.tc * k + half,
            ..f
        }
    }

    /// [`CubeMap::uv_f32`] of eight directions, lane by lane to the bit.
    #[inline(always)]
    pub fn uv8(x8: X8, x: F32x8, y: F32x8, z: F32x8) -> FaceLanes<F32x8, I32x8> {
        let f = CubeFace::select8(x8, x, y, z);
        let (k, half) = (x8.splat(0.5) / f.ma, x8.splat(0.5));
        FaceLanes {
            sc: f.sc * k + half,
            tc: f.tc * k + half,
            ..f
        }
    }
}

/// `atan(ab/√(1+a²+b²))`: the solid angle of the face rectangle `[0,a]×[0,b]`.
#[inline]
pub(super) fn cube_area(a: f64, b: f64) -> f64 {
    (a * b / (1.0 + a * a + b * b).sqrt()).atan()
}

impl WorldProjection for CubeMap {
    fn layer_count(&self) -> usize {
        6
    }
    fn layer_extent(&self, size: u32) -> (u32, u32) {
        (size, size)
    }
    #[inline]
    fn dir_to_uv(&self, dir: DVec3) -> Option<(usize, DVec2)> {
        let (face, sc, tc, ma) = CubeFace::select(dir);
        if ma <= 0.0 || !ma.is_finite() {
            return None;
        }
        let inv = 0.5 / ma;
        Some((face as usize, DVec2::new(sc * inv + 0.5, tc * inv + 0.5)))
    }
    #[inline]
    fn uv_to_dir(&self, layer: usize, uv: DVec2) -> Option<DVec3> {
        let face = CubeFace::from_index(layer)?;
        Some(face.point(2.0 * uv.x - 1.0, 2.0 * uv.y - 1.0).normalize())
    }
    #[inline]
    fn density(&self, _layer: usize, uv: DVec2) -> f64 {
        let (a, b) = (2.0 * uv.x - 1.0, 2.0 * uv.y - 1.0);
        let q = 1.0 + a * a + b * b;
        4.0 / (q * q.sqrt())
    }
    fn lookup_batch(&self, xs: &[f32], ys: &[f32], zs: &[f32], out: &mut [Lookup]) {
        let n = out.len().min(xs.len()).min(ys.len()).min(zs.len());
        let (xs, ys, zs, out) = (&xs[..n], &ys[..n], &zs[..n], &mut out[..n]);
        let mut i = 0;
        // Four lanes a step ([`CubeMap::uv4`]); `Lookup` is four 4-byte fields (`repr(C)`),
        // so four of them are the transpose of the lanes (layer bits, u, v, density).
        while i + 4 <= n {
            let f = CubeMap::uv4(
                F32x4::load(&xs[i..]),
                F32x4::load(&ys[i..]),
                F32x4::load(&zs[i..]),
            );
            let m = f.ma;
            let d = F32x4::splat(4.0) * m * m * m;
            let rows = F32x4::transpose([F32x4::from_bits(f.layer), f.sc, f.tc, d]);
            for (o, r) in out[i..i + 4].iter_mut().zip(rows) {
                let [l, u, v, density] = r.to_array();
                *o = Lookup {
                    layer: l.to_bits(),
                    u,
                    v,
                    density,
                };
            }
            i += 4;
        }
        for i in i..n {
            let (layer, u, v, m) = CubeMap::uv_f32(Vec3::new(xs[i], ys[i], zs[i]));
            out[i] = Lookup {
                layer: layer as u32,
                u,
                v,
                density: 4.0 * m * m * m,
            };
        }
    }
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
            return;
        };
        let tc = 2.0 * (y as f64 + 0.5) / h as f64 - 1.0;
        let step = 2.0 / w as f64;
        for (i, o) in out.iter_mut().enumerate() {
            let sc = ((x0 as usize + i) as f64 + 0.5) * step - 1.0;
            let inv = 1.0 / (1.0 + sc * sc + tc * tc).sqrt();
            // density 4/(1 + a² + b²)^{3/2}
            *o = Some((face.point(sc, tc) * inv, 4.0 * inv * inv * inv));
        }
    }
    fn span_dirs_f32(&self, layer: usize, y: u32, w: u32, h: u32, x0: u32, out: DirRun) {
        let Some(face) = CubeFace::from_index(layer) else {
            return;
        };
        // Along a row the unnormalised direction is o + sc·e (e the face's s axis), and
        // |o + sc·e|² = 1 + sc² + tc².
        let tc = 2.0 * (y as f64 + 0.5) / h as f64 - 1.0;
        let o = face.point(0.0, tc).as_vec3();
        let e = (face.point(1.0, tc) - face.point(0.0, tc)).as_vec3();
        let step = 2.0 / w as f32;
        for (i, (x, y, z, d)) in out.texels().enumerate() {
            let sc = ((x0 as usize + i) as f32 + 0.5) * step - 1.0;
            let p = o + sc * e;
            let inv = 1.0 / p.length();
            (*x, *y, *z) = (p.x * inv, p.y * inv, p.z * inv);
            // density 4/(1 + a² + b²)^{3/2}
            *d = 4.0 * inv * inv * inv;
        }
    }
    #[inline]
    fn density_of_dir(&self, d: DVec3) -> f64 {
        // 1 + a² + b² = 1/m_a² for a unit direction.
        let m = d.abs().max_element();
        4.0 * m * m * m
    }
    fn texel_solid_angle(&self, _layer: usize, x: u32, y: u32, w: u32, h: u32) -> f64 {
        let (u0, u1) = texel_range(x, w);
        let (v0, v1) = texel_range(y, h);
        let (a0, a1, b0, b1) = (
            2.0 * u0 - 1.0,
            2.0 * u1 - 1.0,
            2.0 * v0 - 1.0,
            2.0 * v1 - 1.0,
        );
        cube_area(a1, b1) - cube_area(a0, b1) - cube_area(a1, b0) + cube_area(a0, b0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Directions over the sphere, the cube's edges and corners (ties), signed zeros,
    /// lengths far from one, and non-finite components.
    fn dirs() -> Vec<Vec3> {
        let mut v = Vec::new();
        for i in 0..4000 {
            let t = i as f32 * 0.618_034;
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / 4000.0;
            let r = (1.0 - z * z).sqrt();
            let a = t * std::f32::consts::TAU;
            v.push(Vec3::new(r * a.cos(), z, r * a.sin()) * (1.0 + (i % 7) as f32 * 300.0));
        }
        let e = [-1.0, -0.5, -0.0, 0.0, 0.5, 1.0, f32::INFINITY, f32::NAN];
        for x in e {
            for y in e {
                for z in e {
                    v.push(Vec3::new(x, y, z));
                }
            }
        }
        v
    }

    /// The bits, with every NaN the same (which NaN an operation of two NaNs returns is the
    /// processor's choice, and the compiler may swap a product's operands).
    fn bits(x: f32) -> u32 {
        if x.is_nan() {
            f32::NAN.to_bits()
        } else {
            x.to_bits()
        }
    }

    #[test]
    fn select_f32_is_select() {
        for d in dirs().into_iter().filter(|d| d.is_finite()) {
            let (f, sc, tc, ma) = CubeFace::select(d.as_dvec3());
            let (g, sc32, tc32, ma32) = CubeFace::select_f32(d);
            assert_eq!(f as usize, g, "{d}");
            assert_eq!((sc as f32, tc as f32, ma as f32), (sc32, tc32, ma32), "{d}");
        }
    }

    #[test]
    fn lanes_are_select_f32_to_the_bit() {
        let ds = dirs();
        let x8 = X8::get();
        for c in ds.chunks_exact(8) {
            let lane = |k: usize, i: usize| c[k + i].to_array();
            let four =
                |k: usize, a: usize| F32x4::from_array(std::array::from_fn(|i| lane(k, i)[a]));
            for k in [0, 4] {
                let s = CubeFace::select4(four(k, 0), four(k, 1), four(k, 2));
                let u = CubeMap::uv4(four(k, 0), four(k, 1), four(k, 2));
                let (l, sc, tc, ma) = (
                    s.layer.to_array(),
                    s.sc.to_array(),
                    s.tc.to_array(),
                    s.ma.to_array(),
                );
                let (ul, uu, uv, um) = (
                    u.layer.to_array(),
                    u.sc.to_array(),
                    u.tc.to_array(),
                    u.ma.to_array(),
                );
                for i in 0..4 {
                    let d = c[k + i];
                    let (g, gs, gt, gm) = CubeFace::select_f32(d);
                    assert_eq!(l[i] as usize, g, "{d}");
                    assert_eq!(
                        [sc[i], tc[i], ma[i]].map(bits),
                        [gs, gt, gm].map(bits),
                        "{d}"
                    );
                    let (h, hu, hv, hm) = CubeMap::uv_f32(d);
                    assert_eq!(ul[i] as usize, h, "{d}");
                    assert_eq!(
                        [uu[i], uv[i], um[i]].map(bits),
                        [hu, hv, hm].map(bits),
                        "{d}"
                    );
                }
            }
            if let Some(x8) = x8 {
                {
                    let eight = |a: usize| x8.f32s(std::array::from_fn(|i| lane(0, i)[a]));
                    let s = CubeMap::uv8(x8, eight(0), eight(1), eight(2));
                    let (l, u, v, m) = (
                        s.layer.to_array(),
                        s.sc.to_array(),
                        s.tc.to_array(),
                        s.ma.to_array(),
                    );
                    for (i, &d) in c.iter().enumerate() {
                        let (h, hu, hv, hm) = CubeMap::uv_f32(d);
                        assert_eq!(l[i] as usize, h, "{d}");
                        assert_eq!([u[i], v[i], m[i]].map(bits), [hu, hv, hm].map(bits), "{d}");
                    }
                }
            }
        }
    }

    #[test]
    fn face_coordinates_invert() {
        for d in dirs().into_iter().filter(|d| d.is_finite()) {
            for f in 0..6 {
                let l = CubeFace::to_face(f, d);
                assert_eq!(CubeFace::from_face(f, l), d);
                let p = CubeFace::ALL[f].point(l.x as f64, l.y as f64);
                assert_eq!(
                    p.as_vec3() * l.z,
                    CubeFace::from_face(f, Vec3::new(l.x, l.y, 1.0)) * l.z
                );
            }
            // The selected face's own coordinates are select's, with ma = |ma| > 0.
            let (f, sc, tc, ma) = CubeFace::select_f32(d);
            if ma > 0.0 {
                assert_eq!(CubeFace::to_face(f, d), Vec3::new(sc, tc, ma), "{d}");
            }
        }
    }

    #[test]
    fn lookup_batch_is_uv_f32() {
        let ds: Vec<Vec3> = dirs();
        let (xs, ys, zs): (Vec<f32>, Vec<f32>, Vec<f32>) = (
            ds.iter().map(|d| d.x).collect(),
            ds.iter().map(|d| d.y).collect(),
            ds.iter().map(|d| d.z).collect(),
        );
        let mut out = vec![
            Lookup {
                layer: 0,
                u: 0.0,
                v: 0.0,
                density: 0.0
            };
            ds.len() - 3
        ];
        CubeMap.lookup_batch(&xs, &ys, &zs, &mut out);
        for (d, o) in ds.iter().zip(&out) {
            let (l, u, v, m) = CubeMap::uv_f32(*d);
            assert_eq!(o.layer as usize, l, "{d}");
            assert_eq!(
                [o.u, o.v, o.density].map(bits),
                [u, v, 4.0 * m * m * m].map(bits),
                "{d}"
            );
        }
    }
}
