//! `f32` fast paths for the per-pixel lookups of the two most common projections, cube and
//! lat-long, with the same conventions as `mirrorball-core` (which works in `f64`; tested
//! against it). Texels whose bilinear footprint crosses a seam are handed to
//! [`EnvMap::bilinear_at`], which joins faces and wraps longitude.

use glam::{DVec2, DVec3, Vec3};
use mirrorball_core::{EnvMap, Projection, WorldProjection};

/// `(layer, u, v)` of direction `d` (not necessarily unit length for the cube).
#[inline]
pub fn dir_to_uv(map: &EnvMap, d: Vec3) -> Option<(usize, f32, f32)> {
    match map.projection() {
        Projection::Cube(_) => {
            // OpenGL 4.6 table 8.19; ties go to x, then y, as CubeFace::select.
            let (layer, sc, tc, ma) = mirrorball_core::CubeFace::select_f32(d);
            if ma <= 0.0 || ma.is_nan() {
                return None;
            }
            let k = 0.5 / ma;
            Some((layer, sc * k + 0.5, tc * k + 0.5))
        }
        Projection::LatLong(_) => {
            let n = d.normalize_or_zero();
            if n == Vec3::ZERO {
                return None;
            }
            let u = 0.5 + n.x.atan2(-n.z) * (0.5 / std::f32::consts::PI);
            let v = 0.5 - n.y.clamp(-1.0, 1.0).asin() * (1.0 / std::f32::consts::PI);
            Some((0, u, v))
        }
        p => p
            .dir_to_uv(d.as_dvec3().normalize_or_zero())
            .map(|(l, uv)| (l, uv.x as f32, uv.y as f32)),
    }
}

/// Bilinear lookup at `(layer, u, v)`, RGB.
#[inline]
pub fn bilinear(map: &EnvMap, layer: usize, u: f32, v: f32) -> [f32; 3] {
    let img = &map.layers()[layer];
    let (x0, y0, fx, fy) = mirrorball_core::bilinear_corner(u, v, img.width(), img.height());
    let (w, h) = (img.width() as i32, img.height() as i32);
    let c = img.channels();
    if x0 >= 0 && y0 >= 0 && x0 + 1 < w && y0 + 1 < h {
        let data = img.data();
        let stride = w as usize * c;
        let i = y0 as usize * stride + x0 as usize * c;
        let j = i + stride;
        let mut out = [0.0f32; 3];
        for (k, o) in out.iter_mut().enumerate() {
            let top = data[i + k] + fx * (data[i + c + k] - data[i + k]);
            let bot = data[j + k] + fx * (data[j + c + k] - data[j + k]);
            *o = top + fy * (bot - top);
        }
        return out;
    }
    let mut out = [0.0f32; 3];
    map.bilinear_at(layer, DVec2::new(u as f64, v as f64), &mut out);
    out
}

/// A cube map's six faces, looked up once per frame instead of per sample: the per-pixel
/// loop's bilinear lookup without the projection, filter and layer indirections. Gives
/// exactly what [`dir_to_uv`] then [`bilinear`] give.
#[derive(Clone, Copy)]
pub struct CubeFaces<'a> {
    map: &'a EnvMap,
    pub(crate) faces: [&'a [f32]; 6],
    /// Face edge in texels.
    pub(crate) n: i32,
    /// Channels a texel.
    pub(crate) c: usize,
}

impl<'a> CubeFaces<'a> {
    /// `None` unless `map` is a cube of six equal square faces.
    pub fn new(map: &'a EnvMap) -> Option<CubeFaces<'a>> {
        if !matches!(map.projection(), Projection::Cube(_)) {
            return None;
        }
        let l = map.layers();
        if l.len() != 6 {
            return None;
        }
        let (w, c) = (l[0].width(), l[0].channels());
        if w < 2
            || w as u64 * w as u64 * c as u64 >= SEAM as u64
            || c < 3
            || l.iter()
                .any(|i| i.width() != w || i.height() != w || i.channels() != c)
        {
            return None;
        }
        Some(CubeFaces {
            map,
            faces: std::array::from_fn(|k| l[k].data()),
            n: w as i32,
            c,
        })
    }

    /// Bilinear lookup in direction `d` (any length); zero where `d` has no face.
    #[inline(always)]
    pub fn sample(&self, d: Vec3) -> [f32; 3] {
        self.fetch(&self.locate(d))
    }

    /// First half of [`CubeFaces::sample`]: where the lookup in direction `d` reads. The
    /// texels are prefetched, so that a batch of locations has its cache misses in flight
    /// together before [`CubeFaces::fetch`] reads them.
    #[inline(always)]
    pub fn locate(&self, d: Vec3) -> CubeLoc {
        let (layer, sc, tc, ma) = mirrorball_core::CubeFace::select_f32(d);
        if ma <= 0.0 || ma.is_nan() {
            return CubeLoc::NONE;
        }
        let k = 0.5 / ma;
        let (u, v) = (sc * k + 0.5, tc * k + 0.5);
        if !(u.is_finite() && v.is_finite()) {
            return CubeLoc::NONE;
        }
        let n = self.n;
        let (x0, y0, a, b) = mirrorball_core::bilinear_corner(u, v, n as u32, n as u32);
        if x0 >= 0 && y0 >= 0 && x0 + 1 < n && y0 + 1 < n {
            let stride = n as usize * self.c;
            let i = y0 as usize * stride + x0 as usize * self.c;
            prefetch(&self.faces[layer][i..]);
            prefetch(&self.faces[layer][i + stride..]);
            return CubeLoc {
                layer: layer as u32,
                i: i as u32,
                a,
                b,
            };
        }
        // Across a seam: the core's lookup, which joins the faces.
        CubeLoc {
            layer: layer as u32,
            i: SEAM,
            a: u,
            b: v,
        }
    }

    /// [`CubeFaces::locate`] of four directions at once, given as component arrays,
    /// branch-free (SSE2 on x86-64): lane `k` gives exactly what `locate(Vec3::new(x[k],
    /// y[k], z[k]))` gives, bit for bit (the same operations
    /// in the same order, face chosen by masks instead of branches).
    #[inline(always)]
    pub fn locate4(&self, x: &[f32; 4], y: &[f32; 4], z: &[f32; 4]) -> [CubeLoc; 4] {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: SSE2 is part of x86-64's baseline; the intrinsics only read and write
        // local arrays.
        unsafe {
            use std::arch::x86_64::*;
            let sel =
                |m: __m128, a: __m128, b: __m128| _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b));
            let (x, y, z) = (
                _mm_loadu_ps(x.as_ptr()),
                _mm_loadu_ps(y.as_ptr()),
                _mm_loadu_ps(z.as_ptr()),
            );
            let sign = _mm_set1_ps(-0.0);
            let (ax, ay, az) = (
                _mm_andnot_ps(sign, x),
                _mm_andnot_ps(sign, y),
                _mm_andnot_ps(sign, z),
            );
            let (nx, ny, nz) = (
                _mm_xor_ps(sign, x),
                _mm_xor_ps(sign, y),
                _mm_xor_ps(sign, z),
            );
            // CubeFace::select_f32's branches as masks: x major, else y major, else z.
            let is_x = _mm_and_ps(_mm_cmpge_ps(ax, ay), _mm_cmpge_ps(ax, az));
            let is_y = _mm_andnot_ps(is_x, _mm_cmpge_ps(ay, az));
            let zero = _mm_setzero_ps();
            let (px, py, pz) = (
                _mm_cmpge_ps(x, zero),
                _mm_cmpge_ps(y, zero),
                _mm_cmpge_ps(z, zero),
            );
            let sc = sel(is_x, sel(px, nz, z), sel(is_y, x, sel(pz, x, nx)));
            let tc = sel(is_x, ny, sel(is_y, sel(py, z, nz), ny));
            let ma = sel(is_x, ax, sel(is_y, ay, az));
            let pos = sel(is_x, px, sel(is_y, py, pz));
            // Layer: 0, 2 or 4 by the major axis, plus 1 on its negative side.
            let layer = _mm_add_epi32(
                _mm_or_si128(
                    _mm_and_si128(_mm_castps_si128(is_y), _mm_set1_epi32(2)),
                    _mm_andnot_si128(_mm_castps_si128(_mm_or_ps(is_x, is_y)), _mm_set1_epi32(4)),
                ),
                _mm_andnot_si128(_mm_castps_si128(pos), _mm_set1_epi32(1)),
            );
            let valid = _mm_cmpgt_ps(ma, zero); // false for NaN
            let k = _mm_div_ps(_mm_set1_ps(0.5), ma);
            let half = _mm_set1_ps(0.5);
            let u = _mm_add_ps(_mm_mul_ps(sc, k), half);
            let v = _mm_add_ps(_mm_mul_ps(tc, k), half);
            let inf = _mm_set1_ps(f32::INFINITY);
            let finite = _mm_and_ps(
                _mm_cmplt_ps(_mm_andnot_ps(sign, u), inf),
                _mm_cmplt_ps(_mm_andnot_ps(sign, v), inf),
            );
            let ok = _mm_movemask_ps(_mm_and_ps(valid, finite));
            // bilinear_corner, four lanes: truncate, then step down where that rounded up.
            let nf = _mm_set1_ps(self.n as f32);
            let fxy = |t: __m128| {
                let c = _mm_sub_ps(_mm_mul_ps(t, nf), half);
                let ti = _mm_cvttps_epi32(c);
                let t0 = _mm_add_epi32(ti, _mm_castps_si128(_mm_cmpgt_ps(_mm_cvtepi32_ps(ti), c)));
                (t0, _mm_sub_ps(c, _mm_cvtepi32_ps(t0)))
            };
            let (x0, fx) = fxy(u);
            let (y0, fy) = fxy(v);
            let lo = _mm_set1_epi32(-1);
            let hi = _mm_set1_epi32(self.n - 1);
            let inside = _mm_movemask_ps(_mm_castsi128_ps(_mm_and_si128(
                _mm_and_si128(_mm_cmpgt_epi32(x0, lo), _mm_cmplt_epi32(x0, hi)),
                _mm_and_si128(_mm_cmpgt_epi32(y0, lo), _mm_cmplt_epi32(y0, hi)),
            )));
            let mut a = [[0i32; 4]; 3];
            let mut f = [[0f32; 4]; 4];
            _mm_storeu_si128(a[0].as_mut_ptr() as *mut __m128i, layer);
            _mm_storeu_si128(a[1].as_mut_ptr() as *mut __m128i, x0);
            _mm_storeu_si128(a[2].as_mut_ptr() as *mut __m128i, y0);
            for (o, t) in f.iter_mut().zip([fx, fy, u, v]) {
                _mm_storeu_ps(o.as_mut_ptr(), t);
            }
            let stride = self.n as usize * self.c;
            std::array::from_fn(|lane| {
                if ok & (1 << lane) == 0 {
                    return CubeLoc::NONE;
                }
                let layer = a[0][lane] as usize;
                if inside & (1 << lane) == 0 {
                    return CubeLoc {
                        layer: layer as u32,
                        i: SEAM,
                        a: f[2][lane],
                        b: f[3][lane],
                    };
                }
                let i = a[2][lane] as usize * stride + a[1][lane] as usize * self.c;
                prefetch(&self.faces[layer][i..]);
                prefetch(&self.faces[layer][i + stride..]);
                CubeLoc {
                    layer: layer as u32,
                    i: i as u32,
                    a: f[0][lane],
                    b: f[1][lane],
                }
            })
        }
        #[cfg(not(target_arch = "x86_64"))]
        std::array::from_fn(|k| self.locate(Vec3::new(x[k], y[k], z[k])))
    }

    /// [`CubeFaces::fetch`] as `[r, g, b, 1]` times `[t0, t1, t2, 1]` (the tint): inside a
    /// face, the two rows of the footprint are read as four-lane vectors (SSE2 on x86-64)
    /// with the scalar read's operations lane by lane, so the colour is the same to the bit.
    #[inline(always)]
    pub fn fetch_tinted(&self, l: &CubeLoc, t: [f32; 4]) -> [f32; 4] {
        #[cfg(target_arch = "x86_64")]
        if (l.layer as usize) < 6 && l.i != SEAM {
            let data = self.faces[l.layer as usize];
            let stride = self.n as usize * self.c;
            let i = l.i as usize;
            // The second texel of each row is read as four lanes from its first channel,
            // which for three channels reaches one float past it: not past the face.
            if i + stride + self.c + 4 <= data.len() {
                let mut out = [0.0f32; 4];
                bilinear_tinted(&data[i..], stride, self.c, l.a, l.b, &t, &mut out);
                return out;
            }
        }
        let c = self.fetch(l);
        [c[0] * t[0], c[1] * t[1], c[2] * t[2], 1.0]
    }

    /// Second half of [`CubeFaces::sample`]: the bilinear read at `l`.
    #[inline(always)]
    pub fn fetch(&self, l: &CubeLoc) -> [f32; 3] {
        let mut out = [0.0f32; 3];
        if l.layer as usize >= 6 {
            return out;
        }
        if l.i == SEAM {
            self.map.bilinear_at(
                l.layer as usize,
                DVec2::new(l.a as f64, l.b as f64),
                &mut out,
            );
            return out;
        }
        match self.c {
            3 => self.footprint::<3>(l),
            _ => self.footprint::<4>(l),
        }
    }

    /// The bilinear blend of the 2×2 texels at `l` (inside a face), `C` channels a texel:
    /// two row slices of constant length, so the reads need no further bounds checks.
    #[inline(always)]
    fn footprint<const C: usize>(&self, l: &CubeLoc) -> [f32; 3] {
        let stride = self.n as usize * C;
        let (fx, fy) = (l.a, l.b);
        let i = l.i as usize;
        let data = self.faces[l.layer as usize];
        let r0 = &data[i..i + 2 * C];
        let r1 = &data[i + stride..i + stride + 2 * C];
        let mut out = [0.0f32; 3];
        for (k, o) in out.iter_mut().enumerate() {
            let (a, b) = (r0[k], r0[C + k]);
            let (e, f) = (r1[k], r1[C + k]);
            let top = a + fx * (b - a);
            let bot = e + fx * (f - e);
            *o = top + fy * (bot - top);
        }
        out
    }
}

/// The bilinear blend inside a face, four lanes (SSE2): the texels at `p[0]`, `p[c]` and a
/// row below (`stride` floats), weights `fx`, `fy` (`CubeFaces::footprint`'s arithmetic, lane
/// by lane, so the same bits), times the tint `t`, alpha 1, into `o[..4]`. For three
/// channels the second texel is read as four lanes, one float past it, so `p` must hold
/// `stride + c + 4` floats (asserted). The one copy of this blend: [`CubeFaces::fetch_tinted`]
/// calls it, and the renderer's AVX2 mirror rows its unchecked form.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn bilinear_tinted(
    p: &[f32],
    stride: usize,
    c: usize,
    fx: f32,
    fy: f32,
    t: &[f32; 4],
    o: &mut [f32],
) {
    assert!(p.len() >= stride + c + 4 && o.len() >= 4);
    // SAFETY: the reads stay within `p` and the write within `o` (asserted above).
    unsafe { bilinear_tinted_unchecked(p.as_ptr(), stride, c, fx, fy, t, o.as_mut_ptr()) }
}

/// [`bilinear_tinted`] on raw pointers, for callers that have established the bounds for
/// eight lanes at once.
///
/// # Safety
/// `p` must be valid for reads of `stride + c + 4` floats and `o` for writes of four.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) unsafe fn bilinear_tinted_unchecked(
    p: *const f32,
    stride: usize,
    c: usize,
    fx: f32,
    fy: f32,
    t: &[f32; 4],
    o: *mut f32,
) {
    use std::arch::x86_64::*;
    // SAFETY: SSE2 is part of x86-64's baseline; the caller vouches for the pointers.
    unsafe {
        let (a, b) = (_mm_loadu_ps(p), _mm_loadu_ps(p.add(c)));
        let (e, f) = (_mm_loadu_ps(p.add(stride)), _mm_loadu_ps(p.add(stride + c)));
        let fx = _mm_set1_ps(fx);
        let top = _mm_add_ps(a, _mm_mul_ps(fx, _mm_sub_ps(b, a)));
        let bot = _mm_add_ps(e, _mm_mul_ps(fx, _mm_sub_ps(f, e)));
        let v = _mm_add_ps(top, _mm_mul_ps(_mm_set1_ps(fy), _mm_sub_ps(bot, top)));
        _mm_storeu_ps(o, _mm_mul_ps(v, _mm_loadu_ps(t.as_ptr())));
        *o.add(3) = 1.0;
    }
}

/// `CubeLoc::i` of a lookup whose footprint crosses a seam.
pub(crate) const SEAM: u32 = u32::MAX;

/// Where a [`CubeFaces`] lookup reads: the face, and the index of the footprint's top-left
/// texel with the bilinear weights `(a, b)` (or, across a seam, `(u, v)` in `a, b`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CubeLoc {
    pub(crate) layer: u32,
    pub(crate) i: u32,
    pub(crate) a: f32,
    pub(crate) b: f32,
}

impl CubeLoc {
    /// No face: reads as zero.
    pub const NONE: CubeLoc = CubeLoc {
        layer: u32::MAX,
        i: 0,
        a: 0.0,
        b: 0.0,
    };
}

/// Asks for the cache line holding `s[0]` (a hint; does nothing where unsupported).
#[inline(always)]
fn prefetch(s: &[f32]) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch is only a hint and cannot fault; the pointer is in bounds anyway.
    #[allow(unused_unsafe)]
    unsafe {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        _mm_prefetch::<_MM_HINT_T0>(s.as_ptr() as *const i8);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = s;
}

/// Bilinear lookup in direction `d`; zero where the projection does not cover `d`.
#[inline]
pub fn sample(map: &EnvMap, d: Vec3) -> [f32; 3] {
    match dir_to_uv(map, d) {
        Some((l, u, v)) => bilinear(map, l, u, v),
        None => [0.0; 3],
    }
}

/// The `f64` reference, for tests: `EnvMap::sample`.
pub fn sample_reference(map: &EnvMap, d: Vec3) -> [f32; 3] {
    let s = map.sample(DVec3::new(d.x as f64, d.y as f64, d.z as f64).normalize());
    [s[0], s[1], s[2]]
}
