//! The cube projection (Greene 1986, §3), exactly as OpenGL samples a cube map.

use super::{texel_range, DirRun, Lookup, WorldProjection};
use glam::{DVec2, DVec3};

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
        if a.x >= a.y && a.x >= a.z {
            if r.x >= 0.0 {
                (CubeFace::PosX, -r.z, -r.y, a.x)
            } else {
                (CubeFace::NegX, r.z, -r.y, a.x)
            }
        } else if a.y >= a.z {
            if r.y >= 0.0 {
                (CubeFace::PosY, r.x, r.z, a.y)
            } else {
                (CubeFace::NegY, r.x, -r.z, a.y)
            }
        } else if r.z >= 0.0 {
            (CubeFace::PosZ, r.x, -r.y, a.z)
        } else {
            (CubeFace::NegZ, -r.x, -r.y, a.z)
        }
    }

    /// [`CubeFace::select`] in `f32` for the fast paths of the filter and render crates:
    /// `(layer, sc, tc, |ma|)`, with the same ties.
    #[inline(always)]
    pub fn select_f32(d: glam::Vec3) -> (usize, f32, f32, f32) {
        let a = d.abs();
        if a.x >= a.y && a.x >= a.z {
            if d.x >= 0.0 {
                (0, -d.z, -d.y, a.x)
            } else {
                (1, d.z, -d.y, a.x)
            }
        } else if a.y >= a.z {
            if d.y >= 0.0 {
                (2, d.x, d.z, a.y)
            } else {
                (3, d.x, -d.z, a.y)
            }
        } else if d.z >= 0.0 {
            (4, d.x, -d.y, a.z)
        } else {
            (5, -d.x, -d.y, a.z)
        }
    }

    /// The point on the unit cube for face coordinates `sc`, `tc` ∈ `[-1, 1]` (the inverse
    /// of the table; also meaningful a little outside the face, which filtering uses).
    #[inline]
    pub fn point(self, sc: f64, tc: f64) -> DVec3 {
        match self {
            CubeFace::PosX => DVec3::new(1.0, -tc, -sc),
            CubeFace::NegX => DVec3::new(-1.0, -tc, sc),
            CubeFace::PosY => DVec3::new(sc, 1.0, tc),
            CubeFace::NegY => DVec3::new(sc, -1.0, -tc),
            CubeFace::PosZ => DVec3::new(sc, -tc, 1.0),
            CubeFace::NegZ => DVec3::new(-sc, -tc, -1.0),
        }
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

/// `atan(ab/√(1+a²+b²))`: the solid angle of the face rectangle `[0,a]×[0,b]`.
#[inline]
fn cube_area(a: f64, b: f64) -> f64 {
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
        // The major-axis table with selects instead of branches.
        let n = out.len().min(xs.len()).min(ys.len()).min(zs.len());
        let (xs, ys, zs) = (&xs[..n], &ys[..n], &zs[..n]);
        for (i, o) in out[..n].iter_mut().enumerate() {
            let (x, y, z) = (xs[i], ys[i], zs[i]);
            let (ax, ay, az) = (x.abs(), y.abs(), z.abs());
            let is_x = ax >= ay && ax >= az;
            let is_y = !is_x && ay >= az;
            let ma = if is_x {
                ax
            } else if is_y {
                ay
            } else {
                az
            };
            let neg = if is_x {
                x < 0.0
            } else if is_y {
                y < 0.0
            } else {
                z < 0.0
            };
            // sc: +X −z, −X +z, ±Y +x, +Z +x, −Z −x;  tc: ±X −y, +Y +z, −Y −z, ±Z −y.
            let sc = if is_x {
                if neg {
                    z
                } else {
                    -z
                }
            } else if is_y || !neg {
                x
            } else {
                -x
            };
            let tc = if is_y {
                if neg {
                    -z
                } else {
                    z
                }
            } else {
                -y
            };
            let base: u32 = if is_x {
                0
            } else if is_y {
                2
            } else {
                4
            };
            let inv = 0.5 / ma;
            *o = Lookup {
                layer: base + neg as u32,
                u: sc * inv + 0.5,
                v: tc * inv + 0.5,
                density: 4.0 * ma * ma * ma,
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
