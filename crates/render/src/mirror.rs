//! The per-pixel mirror's reflected direction, the renderer's commonest and hottest case,
//! computed from per-setup corner attributes: one pixel at a time ([`mirror_dir`]), or
//! eight at a time with AVX2 where the processor has it ([`mirror_dirs`]), to the same bits.
//!
//! **Why no division and no square root.** At a sample inside a setup (a clipped, projected
//! triangle) with edge values `fₖ` (twice the areas of the sub-triangles opposite corner
//! `k`), the perspective-correct weight of corner `k` is `fₖ·sₖ / Σⱼ fⱼ·sⱼ` with
//! `sₖ = 1 / (wₖ · area)` (OpenGL 4.6 §14.6.1, eq. 14.9). With `nₖ`, `vₖ` the corner's
//! normal and eye-to-surface vector pre-multiplied by `sₖ` ([`MirrorSetup`]), `n = Σ fₖ·nₖ`
//! and `v = Σ fₖ·vₖ` are the interpolated normal and eye vector times the same positive
//! factor `Σ fⱼ·sⱼ`. The mirror direction of the unit normal `n̂ = n/|n|`,
//! `v − 2(n̂·v)n̂ = (v·(n·n) − 2(n·v)·n) / (n·n)`, is then `r = v·(n·n) − 2(n·v)·n` up to
//! a positive factor; a cube-map lookup needs only the direction (it divides by the major
//! axis), so the weights' normalisation, the normal's normalisation and the square root
//! all drop out.

use glam::{Mat3, Vec3, Vec3A};

/// What the per-pixel mirror needs of one setup, prepared once a frame: `n = Σ fₖ·nₖ` and
/// `v = Σ fₖ·vₖ` (see the module documentation) as planes over the sample grid. The edge
/// values `fₖ` are linear in `(x, y)`, so each sum is `a(o) + (x − oₓ)·∂a/∂x + (y − o_y)·∂a/∂y`
/// about an origin `o` at a corner of the setup (near every sample, so the terms stay small
/// and nothing cancels): two products a component where the sums took six.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MirrorSetup {
    /// The planes' origin `o` in the sample grid.
    pub origin: [f32; 2],
    /// `n` at `o`, and its change per unit of `x` and of `y`.
    pub n: [Vec3A; 3],
    /// `v` likewise (mode 2: the interpolated reflected vector).
    pub v: [Vec3A; 3],
    pub tint: [f32; 3],
    /// Whether the setup's material is a mirror (else it is shaded in full).
    pub mirror: bool,
}

impl MirrorSetup {
    /// The planes of corner attributes `n`, `v` (each already scaled by the corner's
    /// `1 / (w · area)`) over a setup with `edges` (`[b.x − a.x, a.y, b.y − a.y, a.x]` for
    /// the edge `a → b` opposite each corner, as `Binned::edges` gives them, whose value is
    /// `fₖ(x, y) = (b.x − a.x)(y − a.y) − (b.y − a.y)(x − a.x)`), worked out in `f64`.
    pub fn new(
        edges: [[f32; 4]; 3],
        n: [Vec3A; 3],
        v: [Vec3A; 3],
        tint: [f32; 3],
        mirror: bool,
    ) -> MirrorSetup {
        // The origin: the start of edge 0, a corner of the setup.
        let (ox, oy) = (edges[0][3] as f64, edges[0][1] as f64);
        let plane = |a: &[Vec3A; 3]| {
            let mut at = glam::DVec3::ZERO;
            let (mut ddx, mut ddy) = (glam::DVec3::ZERO, glam::DVec3::ZERO);
            for (ak, &[dx, ay, dy, ax]) in a.iter().zip(&edges) {
                let ak = ak.as_dvec3();
                let (dx, ay, dy, ax) = (dx as f64, ay as f64, dy as f64, ax as f64);
                at += ak * (dx * (oy - ay) - dy * (ox - ax));
                ddx -= ak * dy;
                ddy += ak * dx;
            }
            [at, ddx, ddy].map(|d| Vec3A::from(d.as_vec3()))
        };
        MirrorSetup {
            origin: [ox as f32, oy as f32],
            n: plane(&n),
            v: plane(&v),
            tint,
            mirror,
        }
    }
}

/// What all pixels of a frame share.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MirrorView {
    /// Perspective (the eye vector varies) or orthographic (it is `forward`).
    pub persp: bool,
    pub forward: Vec3A,
    /// World → eye rotation, for an environment attached to the eye.
    pub rot: Option<Mat3>,
    /// Mode 2: the setups' `v` hold the corners' reflected vectors, interpolated as they
    /// are (`r = Σ fₖ·vₖ`, the perspective-correct interpolation up to a positive factor).
    pub per_vertex: bool,
}

/// The reflected direction (any positive length) at the pixel centre `(fx, fy)` of setup
/// `m`: the reference for [`mirror_dirs`], which gives the same bits.
#[inline(always)]
pub(crate) fn mirror_dir(m: &MirrorSetup, fx: f32, fy: f32, view: &MirrorView) -> Vec3 {
    // The planes: the row's part first, then the column's (as `v8::reflect`).
    let (dx, dy) = (fx - m.origin[0], fy - m.origin[1]);
    let n = (m.n[0] + m.n[2] * dy) + m.n[1] * dx;
    let v = if view.persp || view.per_vertex {
        (m.v[0] + m.v[2] * dy) + m.v[1] * dx
    } else {
        view.forward
    };
    let r = if view.per_vertex {
        Vec3::from(v)
    } else {
        Vec3::from(v * n.dot(n) - n * (2.0 * n.dot(v)))
    };
    match view.rot {
        Some(rot) => rot * r,
        None => r,
    }
}

/// Columns a call of [`mirror_dirs`] handles at most.
pub(crate) const SPAN: usize = 16;

/// [`mirror_dir`] for the pixels of a row segment: pixel `i` of `ids` (setup ids; at most
/// [`SPAN`]) sits at column `x0 + i` of the sample row whose centre is `fy`; where bit `i`
/// of `lanes` is set (its setup is a mirror), `dirs[·][i]` receives its direction. The
/// other entries are left as they are.
pub(crate) fn mirror_dirs(
    ids: &[u32],
    lanes: u32,
    x0: usize,
    fy: f32,
    setups: &[MirrorSetup],
    view: &MirrorView,
    dirs: &mut [[f32; SPAN]; 3],
) {
    debug_assert!(ids.len() <= SPAN);
    #[cfg(target_arch = "x86_64")]
    if crate::cpu::avx2() {
        // SAFETY: the processor has AVX2 (checked just above).
        unsafe { mirror_dirs_avx2(ids, lanes, x0, fy, setups, view, dirs) };
        return;
    }
    mirror_dirs_portable(ids, lanes, x0, fy, setups, view, dirs);
}

/// [`mirror_dirs`] one pixel at a time.
pub(crate) fn mirror_dirs_portable(
    ids: &[u32],
    lanes: u32,
    x0: usize,
    fy: f32,
    setups: &[MirrorSetup],
    view: &MirrorView,
    dirs: &mut [[f32; SPAN]; 3],
) {
    for (i, &id) in ids.iter().enumerate() {
        if lanes & (1 << i) != 0 {
            let r = mirror_dir(&setups[id as usize], (x0 + i) as f32 + 0.5, fy, view);
            dirs[0][i] = r.x;
            dirs[1][i] = r.y;
            dirs[2][i] = r.z;
        }
    }
}

/// [`mirror_dirs`] eight pixels a step ([`v8::reflect`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn mirror_dirs_avx2(
    ids: &[u32],
    lanes: u32,
    x0: usize,
    fy: f32,
    setups: &[MirrorSetup],
    view: &MirrorView,
    dirs: &mut [[f32; SPAN]; 3],
) {
    use std::arch::x86_64::*;
    let n = ids.len().min(SPAN);
    let mut g = 0;
    while g < n {
        let glanes = (lanes >> g) & 0xff;
        if glanes == 0 {
            g += 8;
            continue;
        }
        let cnt = (n - g).min(8);
        let mut idb = [crate::raster::NO_HIT; 8];
        idb[..cnt].copy_from_slice(&ids[g..g + cnt]);
        let ev = v8::reflect(&idb, glanes, x0 + g, fy, setups, view);
        let keep = v8::lane_mask(glanes);
        for (d, r) in dirs.iter_mut().zip(ev.r) {
            // g + 8 ≤ SPAN: the eight entries are in the array whatever `cnt` is.
            let p = d[g..g + 8].as_mut_ptr();
            _mm256_storeu_ps(p, _mm256_blendv_ps(_mm256_loadu_ps(p), r, keep));
        }
        g += 8;
    }
}

/// The whole per-pixel mirror of a row segment of a frame without background, eight pixels
/// a step (AVX2): reflected directions ([`mirror_dirs`]'s arithmetic), the cube face and
/// texel of each ([`CubeFaces::locate`](crate::fast::CubeFaces::locate)'s arithmetic, face chosen by masks), then each
/// pixel's bilinear read ([`CubeFaces::fetch_tinted`](crate::fast::CubeFaces::fetch_tinted))
/// written to `out` (four floats a pixel). Pixels that see nothing are written transparent black. Returns
/// the lanes whose setup is not a mirror, left for the caller to shade; `None` where the
/// processor lacks AVX2 (or [`set_portable`](crate::set_portable) said so), having done nothing.
#[allow(clippy::too_many_arguments)]
pub(crate) fn mirror_row(
    ids: &[u32],
    x0: usize,
    fy: f32,
    setups: &[MirrorSetup],
    view: &MirrorView,
    cf: &crate::fast::CubeFaces,
    out: &mut [f32],
) -> Option<u32> {
    #[cfg(target_arch = "x86_64")]
    if crate::cpu::avx2() {
        // SAFETY: the processor has AVX2 (checked just above).
        return Some(unsafe { mirror_row_avx2(ids, x0, fy, setups, view, cf, out) });
    }
    let _ = (ids, x0, fy, setups, view, cf, out);
    None
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn mirror_row_avx2(
    ids: &[u32],
    x0: usize,
    fy: f32,
    setups: &[MirrorSetup],
    view: &MirrorView,
    cf: &crate::fast::CubeFaces,
    out: &mut [f32],
) -> u32 {
    use crate::fast::{CubeLoc, SEAM};
    use crate::raster::NO_HIT;
    let n = ids.len().min(SPAN);
    let mut left = 0u32;
    let mut g = 0;
    while g < n {
        let cnt = (n - g).min(8);
        let mut idb = [NO_HIT; 8];
        idb[..cnt].copy_from_slice(&ids[g..g + cnt]);
        let orow = &mut out[g * 4..(g + cnt) * 4];
        let none = v8::equal_lanes(&idb, NO_HIT);
        let hit = !none & ((1u32 << cnt) - 1);
        if hit == 0 {
            orow.fill(0.0);
            g += 8;
            continue;
        }
        let ev = v8::reflect(&idb, hit, x0 + g, fy, setups, view);
        left |= ev.left << g;
        let at = v8::locate(&ev.r, cf);
        let tint = v8::pixels(&ev.tint);
        let stride = cf.n as usize * cf.c;
        // Mirror lanes whose four texels lie inside one face and within reach of four-lane
        // reads: straight to the blend, no further test.
        let direct = ev.mirror & at.ok & at.inside & at.reach & ((1u32 << cnt) - 1);
        let mut m = direct;
        while m != 0 {
            let lane = m.trailing_zeros() as usize;
            m &= m - 1;
            let data = cf.faces[at.layer[lane] as usize];
            // SAFETY: `reach` says `index + stride + c + 4 ≤ data.len()`; lane < cnt, so the
            // pixel's four floats are in `orow`.
            unsafe {
                crate::fast::bilinear_tinted_unchecked(
                    data.as_ptr().add(at.index[lane] as usize),
                    stride,
                    cf.c,
                    at.fx[lane],
                    at.fy[lane],
                    &tint[lane],
                    orow.as_mut_ptr().add(4 * lane),
                );
            }
        }
        let mut rest = ((1u32 << cnt) - 1) & !direct;
        while rest != 0 {
            let lane = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            let bit = 1 << lane;
            let o = &mut orow[4 * lane..4 * lane + 4];
            if ev.mirror & bit == 0 {
                if none & bit != 0 {
                    o.fill(0.0);
                }
                continue; // not a mirror: the caller's
            }
            // A mirror lane not blended above: no face, across a seam, or too near a face's
            // end for four-lane reads; `fetch_tinted` sorts out which.
            let t = tint[lane];
            let loc = if at.ok & bit == 0 {
                CubeLoc::NONE
            } else if at.inside & bit == 0 {
                CubeLoc {
                    layer: at.layer[lane] as u32,
                    i: SEAM,
                    a: at.u[lane],
                    b: at.v[lane],
                }
            } else {
                CubeLoc {
                    layer: at.layer[lane] as u32,
                    i: at.index[lane] as u32,
                    a: at.fx[lane],
                    b: at.fy[lane],
                }
            };
            o.copy_from_slice(&cf.fetch_tinted(&loc, t));
        }
        g += 8;
    }
    left
}

/// Eight-lane building blocks (AVX2), each lane doing the scalar code's operations in its
/// order (no fused multiply-add), so that every result is the scalar result to the bit.
/// Functions rather than closures, so that they inherit the caller's target feature and
/// inline.
#[cfg(target_arch = "x86_64")]
mod v8 {
    use super::{MirrorSetup, MirrorView};
    use crate::fast::CubeFaces;
    use glam::Vec3A;
    use std::arch::x86_64::*;

    /// Reflected directions and tints of eight pixels.
    pub struct Reflected {
        pub r: [__m256; 3],
        pub tint: [__m256; 3],
        /// Lanes whose setup is a mirror (directions and tints set).
        pub mirror: u32,
        /// Lanes whose setup is not a mirror.
        pub left: u32,
    }

    /// Where eight cube lookups read, as `CubeFaces::locate` computes it.
    pub struct Located {
        pub ok: u32,
        pub inside: u32,
        /// Lanes whose `index + stride + c + 4` is within a face (four-lane reads of the
        /// second texel of the lower row stay inside).
        pub reach: u32,
        pub layer: [i32; 8],
        pub index: [i32; 8],
        pub fx: [f32; 8],
        pub fy: [f32; 8],
        pub u: [f32; 8],
        pub v: [f32; 8],
    }

    #[inline]
    #[target_feature(enable = "avx2")]
    fn splat(v: f32) -> __m256 {
        _mm256_set1_ps(v)
    }

    /// `(x·x' + y·y') + z·z'`, as glam's `Vec3A::dot`.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn dot(a: &[__m256; 3], b: &[__m256; 3]) -> __m256 {
        _mm256_add_ps(
            _mm256_add_ps(_mm256_mul_ps(a[0], b[0]), _mm256_mul_ps(a[1], b[1])),
            _mm256_mul_ps(a[2], b[2]),
        )
    }

    /// `m ? a : b`, lane by lane.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn sel(m: __m256, a: __m256, b: __m256) -> __m256 {
        _mm256_blendv_ps(b, a, m)
    }

    /// All-ones in the lanes whose bit is set in `bits`.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub fn lane_mask(bits: u32) -> __m256 {
        let b = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
        _mm256_castsi256_ps(_mm256_cmpeq_epi32(
            _mm256_and_si256(_mm256_set1_epi32(bits as i32), b),
            b,
        ))
    }

    /// The lanes of `ids` equal to `id`, as bits.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub fn equal_lanes(ids: &[u32; 8], id: u32) -> u32 {
        // SAFETY: `ids` holds eight u32, read unaligned.
        let v = unsafe { _mm256_loadu_si256(ids.as_ptr() as *const __m256i) };
        let eq = _mm256_cmpeq_epi32(v, _mm256_set1_epi32(id as i32));
        _mm256_movemask_ps(_mm256_castsi256_ps(eq)) as u32
    }

    /// Eight `(r, g, b, 1)` of three vectors of lanes `r`, `g`, `b`.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub fn pixels(v: &[__m256; 3]) -> [[f32; 4]; 8] {
        let one = splat(1.0);
        let (rg_lo, rg_hi) = (
            _mm256_unpacklo_ps(v[0], v[1]),
            _mm256_unpackhi_ps(v[0], v[1]),
        );
        let (ba_lo, ba_hi) = (_mm256_unpacklo_ps(v[2], one), _mm256_unpackhi_ps(v[2], one));
        // Pixels 0|4, 1|5, 2|6, 3|7, then their halves put in order.
        let p04 = _mm256_shuffle_ps::<0x44>(rg_lo, ba_lo);
        let p15 = _mm256_shuffle_ps::<0xEE>(rg_lo, ba_lo);
        let p26 = _mm256_shuffle_ps::<0x44>(rg_hi, ba_hi);
        let p37 = _mm256_shuffle_ps::<0xEE>(rg_hi, ba_hi);
        let mut out = [[0.0f32; 4]; 8];
        let o = out.as_mut_ptr() as *mut f32;
        // SAFETY: `out` holds 32 floats.
        unsafe {
            _mm256_storeu_ps(o, _mm256_permute2f128_ps::<0x20>(p04, p15));
            _mm256_storeu_ps(o.add(8), _mm256_permute2f128_ps::<0x20>(p26, p37));
            _mm256_storeu_ps(o.add(16), _mm256_permute2f128_ps::<0x31>(p04, p15));
            _mm256_storeu_ps(o.add(24), _mm256_permute2f128_ps::<0x31>(p26, p37));
        }
        out
    }

    /// `mirror_dir` of the pixels at columns `x0 ..` of `idb` whose bit is set in `lanes`,
    /// once per distinct setup among them (its values broadcast, its pixels blended in).
    #[inline]
    #[target_feature(enable = "avx2")]
    pub fn reflect(
        idb: &[u32; 8],
        lanes: u32,
        x0: usize,
        fy: f32,
        setups: &[MirrorSetup],
        view: &MirrorView,
    ) -> Reflected {
        // SAFETY: `idb` holds eight u32, read unaligned.
        let idv = unsafe { _mm256_loadu_si256(idb.as_ptr() as *const __m256i) };
        let fx = _mm256_add_ps(
            splat(x0 as f32),
            _mm256_setr_ps(0.5, 1.5, 2.5, 3.5, 4.5, 5.5, 6.5, 7.5),
        );
        let zero = _mm256_setzero_ps();
        let mut out = Reflected {
            r: [zero; 3],
            tint: [zero; 3],
            mirror: 0,
            left: 0,
        };
        let mut todo = lanes;
        while todo != 0 {
            let id = idb[todo.trailing_zeros() as usize];
            let same = _mm256_castsi256_ps(_mm256_cmpeq_epi32(idv, _mm256_set1_epi32(id as i32)));
            let bits = _mm256_movemask_ps(same) as u32 & lanes;
            todo &= !bits;
            let m = &setups[id as usize];
            if !m.mirror {
                out.left |= bits;
                continue;
            }
            out.mirror |= bits;
            // The planes as `mirror_dir` evaluates them: the row's part once (as a Vec3A),
            // then eight columns.
            let dy = fy - m.origin[1];
            let dx = _mm256_sub_ps(fx, splat(m.origin[0]));
            let plane = |a: &[Vec3A; 3]| {
                let row = a[0] + a[2] * dy;
                [0, 1, 2].map(|c| _mm256_add_ps(splat(row[c]), _mm256_mul_ps(splat(a[1][c]), dx)))
            };
            let v = if view.persp || view.per_vertex {
                plane(&m.v)
            } else {
                [
                    splat(view.forward.x),
                    splat(view.forward.y),
                    splat(view.forward.z),
                ]
            };
            let r = if view.per_vertex {
                v // mode 2: the interpolated reflected vector itself
            } else {
                let n = plane(&m.n);
                let nn = dot(&n, &n);
                let t = _mm256_mul_ps(dot(&n, &v), splat(2.0));
                let mut r = [zero; 3];
                for ((rc, vc), nc) in r.iter_mut().zip(v).zip(n) {
                    *rc = _mm256_sub_ps(_mm256_mul_ps(vc, nn), _mm256_mul_ps(nc, t));
                }
                r
            };
            for (c, rc) in r.into_iter().enumerate() {
                out.r[c] = sel(same, rc, out.r[c]);
                out.tint[c] = sel(same, splat(m.tint[c]), out.tint[c]);
            }
        }
        if let Some(rot) = view.rot {
            let col = [rot.x_axis, rot.y_axis, rot.z_axis];
            let r = out.r;
            for (c, rc) in out.r.iter_mut().enumerate() {
                *rc = _mm256_add_ps(
                    _mm256_add_ps(
                        _mm256_mul_ps(splat(col[0][c]), r[0]),
                        _mm256_mul_ps(splat(col[1][c]), r[1]),
                    ),
                    _mm256_mul_ps(splat(col[2][c]), r[2]),
                );
            }
        }
        out
    }

    /// `bilinear_corner` of one coordinate: the texel below (truncate, then step down
    /// where that rounded up) and the fraction.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn corner(t: __m256, n: __m256) -> (__m256i, __m256) {
        let c = _mm256_sub_ps(_mm256_mul_ps(t, n), splat(0.5));
        let ti = _mm256_cvttps_epi32(c);
        let up = _mm256_cmp_ps::<_CMP_GT_OQ>(_mm256_cvtepi32_ps(ti), c);
        let t0 = _mm256_add_epi32(ti, _mm256_castps_si256(up));
        (t0, _mm256_sub_ps(c, _mm256_cvtepi32_ps(t0)))
    }

    /// `CubeFace::select_f32` and `CubeFaces::locate` of eight directions, the face chosen
    /// by masks (as `CubeFaces::locate4`).
    #[inline]
    #[target_feature(enable = "avx2")]
    pub fn locate(r: &[__m256; 3], cf: &CubeFaces) -> Located {
        let [x, y, z] = *r;
        let sign = splat(-0.0);
        let zero = _mm256_setzero_ps();
        let half = splat(0.5);
        let (ax, ay, az) = (
            _mm256_andnot_ps(sign, x),
            _mm256_andnot_ps(sign, y),
            _mm256_andnot_ps(sign, z),
        );
        let (nx, ny, nz) = (
            _mm256_xor_ps(sign, x),
            _mm256_xor_ps(sign, y),
            _mm256_xor_ps(sign, z),
        );
        let is_x = _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_GE_OQ>(ax, ay),
            _mm256_cmp_ps::<_CMP_GE_OQ>(ax, az),
        );
        let is_y = _mm256_andnot_ps(is_x, _mm256_cmp_ps::<_CMP_GE_OQ>(ay, az));
        let px = _mm256_cmp_ps::<_CMP_GE_OQ>(x, zero);
        let py = _mm256_cmp_ps::<_CMP_GE_OQ>(y, zero);
        let pz = _mm256_cmp_ps::<_CMP_GE_OQ>(z, zero);
        let sc = sel(is_x, sel(px, nz, z), sel(is_y, x, sel(pz, x, nx)));
        let tc = sel(is_x, ny, sel(is_y, sel(py, z, nz), ny));
        let ma = sel(is_x, ax, sel(is_y, ay, az));
        let pos = sel(is_x, px, sel(is_y, py, pz));
        let layer = _mm256_add_epi32(
            _mm256_or_si256(
                _mm256_and_si256(_mm256_castps_si256(is_y), _mm256_set1_epi32(2)),
                _mm256_andnot_si256(
                    _mm256_castps_si256(_mm256_or_ps(is_x, is_y)),
                    _mm256_set1_epi32(4),
                ),
            ),
            _mm256_andnot_si256(_mm256_castps_si256(pos), _mm256_set1_epi32(1)),
        );
        let valid = _mm256_cmp_ps::<_CMP_GT_OQ>(ma, zero);
        let k = _mm256_div_ps(half, ma);
        let u = _mm256_add_ps(_mm256_mul_ps(sc, k), half);
        let v = _mm256_add_ps(_mm256_mul_ps(tc, k), half);
        let inf = splat(f32::INFINITY);
        let finite = _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_andnot_ps(sign, u), inf),
            _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_andnot_ps(sign, v), inf),
        );
        let nf = splat(cf.n as f32);
        let (x0, fx) = corner(u, nf);
        let (y0, fy) = corner(v, nf);
        let lo = _mm256_set1_epi32(-1);
        let hi = _mm256_set1_epi32(cf.n - 1);
        let inside = _mm256_and_si256(
            _mm256_and_si256(_mm256_cmpgt_epi32(x0, lo), _mm256_cmpgt_epi32(hi, x0)),
            _mm256_and_si256(_mm256_cmpgt_epi32(y0, lo), _mm256_cmpgt_epi32(hi, y0)),
        );
        let stride = cf.n * cf.c as i32;
        let index = _mm256_add_epi32(
            _mm256_mullo_epi32(y0, _mm256_set1_epi32(stride)),
            _mm256_mullo_epi32(x0, _mm256_set1_epi32(cf.c as i32)),
        );
        let mut out = Located {
            ok: _mm256_movemask_ps(_mm256_and_ps(valid, finite)) as u32,
            inside: _mm256_movemask_ps(_mm256_castsi256_ps(inside)) as u32,
            reach: _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(
                _mm256_set1_epi32(cf.n * stride - stride - cf.c as i32 - 3),
                index,
            ))) as u32,
            layer: [0; 8],
            index: [0; 8],
            fx: [0.0; 8],
            fy: [0.0; 8],
            u: [0.0; 8],
            v: [0.0; 8],
        };
        // SAFETY: each destination holds eight lanes.
        unsafe {
            _mm256_storeu_si256(out.layer.as_mut_ptr() as *mut __m256i, layer);
            _mm256_storeu_si256(out.index.as_mut_ptr() as *mut __m256i, index);
            _mm256_storeu_ps(out.fx.as_mut_ptr(), fx);
            _mm256_storeu_ps(out.fy.as_mut_ptr(), fy);
            _mm256_storeu_ps(out.u.as_mut_ptr(), u);
            _mm256_storeu_ps(out.v.as_mut_ptr(), v);
        }
        out
    }
}
