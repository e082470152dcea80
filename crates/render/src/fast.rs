//! `f32` fast paths for the per-pixel lookups of the two most common projections, cube and
//! lat-long, with the same conventions as `mirrorball-core` (which works in `f64`; tested
//! against it). Texels whose bilinear footprint crosses a seam are handed to
//! [`EnvMap::bilinear_at`], which joins faces and wraps longitude.

use glam::{DVec2, Vec3};
use mirrorball_core::simd::{prefetch, F32x4, Taps};
use mirrorball_core::{
    bilinear_corner4, bilinear_mix, bilinear_taps, CubeMap, EnvMap, Projection, WorldProjection,
};

/// `(layer, u, v)` of direction `d` (not necessarily unit length for the cube).
#[inline]
pub fn dir_to_uv(map: &EnvMap, d: Vec3) -> Option<(usize, f32, f32)> {
    match map.projection() {
        Projection::Cube(_) => {
            let (layer, u, v, ma) = CubeMap::uv_f32(d);
            if ma <= 0.0 || ma.is_nan() {
                return None;
            }
            Some((layer, u, v))
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
    /// The faces' bilinear footprints, read without a bounds check a read (`None` where a
    /// face is too small to hold one).
    pub(crate) taps: Option<Taps<'a, 6>>,
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
        let faces = std::array::from_fn(|k| l[k].data());
        Some(CubeFaces {
            map,
            faces,
            taps: bilinear_taps(faces, w as usize * c, c),
            n: w as i32,
            c,
        })
    }

    /// First half of a lookup (`fetch(&locate(d))`): where the lookup in direction `d` reads. The
    /// texels are prefetched, so that a batch of locations has its cache misses in flight
    /// together before [`CubeFaces::fetch`] reads them.
    #[inline(always)]
    pub fn locate(&self, d: Vec3) -> CubeLoc {
        let (layer, u, v, ma) = CubeMap::uv_f32(d);
        if ma <= 0.0 || ma.is_nan() {
            return CubeLoc::NONE;
        }
        if !(u.is_finite() && v.is_finite()) {
            return CubeLoc::NONE;
        }
        let n = self.n;
        let (x0, y0, a, b) = mirrorball_core::bilinear_corner(u, v, n as u32, n as u32);
        if x0 >= 0 && y0 >= 0 && x0 + 1 < n && y0 + 1 < n {
            let stride = n as usize * self.c;
            let i = y0 as usize * stride + x0 as usize * self.c;
            prefetch(self.faces[layer][i..].as_ptr());
            prefetch(self.faces[layer][i + stride..].as_ptr());
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
    /// branch-free ([`CubeMap::uv4`], [`bilinear_corner4`]): lane `k` gives exactly what
    /// `locate(Vec3::new(x[k], y[k], z[k]))` gives, bit for bit (the same operations in the
    /// same order, face chosen by masks instead of branches).
    #[inline(always)]
    pub fn locate4(&self, x: &[f32; 4], y: &[f32; 4], z: &[f32; 4]) -> [CubeLoc; 4] {
        let f = CubeMap::uv4(
            F32x4::from_array(*x),
            F32x4::from_array(*y),
            F32x4::from_array(*z),
        );
        let (u, v) = (f.sc, f.tc);
        let inf = F32x4::splat(f32::INFINITY);
        let ok = (f.ma.gt(F32x4::splat(0.0)) & u.abs().lt(inf) & v.abs().lt(inf)).bitmask();
        let c = bilinear_corner4(u, v, self.n as u32, self.n as u32);
        let inside = c.inside.bitmask();
        let (layers, x0, y0) = (f.layer.to_array(), c.x0.to_array(), c.y0.to_array());
        let (fx, fy, u, v) = (c.fx.to_array(), c.fy.to_array(), u.to_array(), v.to_array());
        let stride = self.n as usize * self.c;
        std::array::from_fn(|lane| {
            if ok & (1 << lane) == 0 {
                return CubeLoc::NONE;
            }
            let layer = layers[lane] as usize;
            if inside & (1 << lane) == 0 {
                return CubeLoc {
                    layer: layer as u32,
                    i: SEAM,
                    a: u[lane],
                    b: v[lane],
                };
            }
            let i = y0[lane] as usize * stride + x0[lane] as usize * self.c;
            prefetch(self.faces[layer][i..].as_ptr());
            prefetch(self.faces[layer][i + stride..].as_ptr());
            CubeLoc {
                layer: layer as u32,
                i: i as u32,
                a: fx[lane],
                b: fy[lane],
            }
        })
    }

    /// [`CubeFaces::fetch`] as `[r, g, b, 1]` times `[t0, t1, t2, 1]` (the tint): inside a
    /// face, the two rows of the footprint are read as four-lane vectors with the scalar
    /// read's operations lane by lane, so the colour is the same to the bit.
    #[inline(always)]
    pub fn fetch_tinted(&self, l: &CubeLoc, t: [f32; 4]) -> [f32; 4] {
        if let (true, Some(taps)) = ((l.layer as usize) < 6 && l.i != SEAM, &self.taps) {
            // The second texel of each row is read as four lanes from its first channel,
            // which for three channels reaches one float past it: within `last`, not past
            // the face.
            if l.i as usize <= taps.last() {
                let mut out = [0.0; 4];
                tinted(
                    taps.get(l.layer as usize, l.i as usize),
                    l.a,
                    l.b,
                    &t,
                    &mut out,
                );
                return out;
            }
        }
        let c = self.fetch(l);
        [c[0] * t[0], c[1] * t[1], c[2] * t[2], 1.0]
    }

    /// Second half of a lookup: the bilinear read at `l`.
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

/// The bilinear blend inside a face of the four reads `q` of a footprint (from
/// [`bilinear_taps`], blended by [`bilinear_mix`]: `CubeFaces::footprint`'s arithmetic,
/// lane by lane, so the same bits), weights `fx`, `fy`, times the tint `t`, alpha 1, into
/// `o`. [`CubeFaces::fetch_tinted`] and the renderer's eight-lane mirror rows call it.
#[inline(always)]
pub(crate) fn tinted(q: [F32x4; 4], fx: f32, fy: f32, t: &[f32; 4], o: &mut [f32; 4]) {
    (bilinear_mix(q, fx, fy) * F32x4::from_array(*t)).store(o);
    o[3] = 1.0;
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

/// Bilinear lookup in direction `d`; zero where the projection does not cover `d`.
#[cfg(test)]
fn sample(map: &EnvMap, d: Vec3) -> [f32; 3] {
    match dir_to_uv(map, d) {
        Some((l, u, v)) => bilinear(map, l, u, v),
        None => [0.0; 3],
    }
}

/// The `f64` reference, for tests: `EnvMap::sample`.
#[cfg(test)]
fn sample_reference(map: &EnvMap, d: Vec3) -> [f32; 3] {
    let s = map.sample(glam::DVec3::new(d.x as f64, d.y as f64, d.z as f64).normalize());
    [s[0], s[1], s[2]]
}

#[cfg(test)]
mod tests;
