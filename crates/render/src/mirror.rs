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

/// What the per-pixel mirror needs of one setup, prepared once a frame: the setup's edges
/// (`[b.x − a.x, a.y, b.y − a.y, a.x]` for the edge `a → b` opposite each corner, as
/// `Binned::edges` gives them) and, at its three corners, the normal and the vector from
/// the eye, each scaled by the corner's `1 / (w · area)` (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub(crate) struct MirrorSetup {
    pub edges: [[f32; 4]; 3],
    pub n: [Vec3A; 3],
    pub v: [Vec3A; 3],
    pub tint: [f32; 3],
    /// Whether the setup's material is a mirror (else it is shaded in full).
    pub mirror: bool,
}

/// What all pixels of a frame share.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MirrorView {
    /// Perspective (the eye vector varies) or orthographic (it is `forward`).
    pub persp: bool,
    pub forward: Vec3A,
    /// World → eye rotation, for an environment attached to the eye.
    pub rot: Option<Mat3>,
}

/// The reflected direction (any positive length) at the pixel centre `(fx, fy)` of setup
/// `m`: the reference for [`mirror_dirs`], which gives the same bits.
#[inline(always)]
pub(crate) fn mirror_dir(m: &MirrorSetup, fx: f32, fy: f32, view: &MirrorView) -> Vec3 {
    // Edge values exactly as `Binned::edge_values` computes them.
    let f = m
        .edges
        .map(|[dx, ay, dy, ax]| dx * (fy - ay) - dy * (fx - ax));
    let n = m.n[0] * f[0] + m.n[1] * f[1] + m.n[2] * f[2];
    let v = if view.persp {
        m.v[0] * f[0] + m.v[1] * f[1] + m.v[2] * f[2]
    } else {
        view.forward
    };
    let r = Vec3::from(v * n.dot(n) - n * (2.0 * n.dot(v)));
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

/// [`mirror_dirs`] eight pixels a step. Pixels of one setup share its attributes, so each
/// step runs once per distinct setup among its eight pixels, with the setup's values
/// broadcast and its pixels blended in; every lane does [`mirror_dir`]'s operations in its
/// order (no fused multiply-add), so the bits are the same.
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
    let bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    let fyv = _mm256_set1_ps(fy);
    let two = _mm256_set1_ps(2.0);
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
        let idv = _mm256_loadu_si256(idb.as_ptr() as *const __m256i);
        let fx = _mm256_add_ps(
            _mm256_set1_ps((x0 + g) as f32),
            _mm256_setr_ps(0.5, 1.5, 2.5, 3.5, 4.5, 5.5, 6.5, 7.5),
        );
        let mut r = [_mm256_setzero_ps(); 3];
        let mut todo = glanes;
        while todo != 0 {
            let id = idb[todo.trailing_zeros() as usize];
            let same = _mm256_castsi256_ps(_mm256_cmpeq_epi32(idv, _mm256_set1_epi32(id as i32)));
            todo &= !(_mm256_movemask_ps(same) as u32);
            let m = &setups[id as usize];
            let b = _mm256_set1_ps;
            let f = m.edges.map(|[dx, ay, dy, ax]| {
                _mm256_sub_ps(
                    _mm256_mul_ps(b(dx), _mm256_sub_ps(fyv, b(ay))),
                    _mm256_mul_ps(b(dy), _mm256_sub_ps(fx, b(ax))),
                )
            });
            let interp = |a: &[Vec3A; 3], c: usize| {
                _mm256_add_ps(
                    _mm256_add_ps(
                        _mm256_mul_ps(b(a[0][c]), f[0]),
                        _mm256_mul_ps(b(a[1][c]), f[1]),
                    ),
                    _mm256_mul_ps(b(a[2][c]), f[2]),
                )
            };
            let nv = [0, 1, 2].map(|c| interp(&m.n, c));
            let vv = if view.persp {
                [0, 1, 2].map(|c| interp(&m.v, c))
            } else {
                [0, 1, 2].map(|c| b(view.forward[c]))
            };
            let dot = |a: &[__m256; 3], c: &[__m256; 3]| {
                _mm256_add_ps(
                    _mm256_add_ps(_mm256_mul_ps(a[0], c[0]), _mm256_mul_ps(a[1], c[1])),
                    _mm256_mul_ps(a[2], c[2]),
                )
            };
            let nn = dot(&nv, &nv);
            let t = _mm256_mul_ps(dot(&nv, &vv), two);
            for c in 0..3 {
                let rc = _mm256_sub_ps(_mm256_mul_ps(vv[c], nn), _mm256_mul_ps(nv[c], t));
                r[c] = _mm256_blendv_ps(r[c], rc, same);
            }
        }
        if let Some(rot) = view.rot {
            let b = _mm256_set1_ps;
            let col = [rot.x_axis, rot.y_axis, rot.z_axis];
            r = [0, 1, 2].map(|c| {
                _mm256_add_ps(
                    _mm256_add_ps(
                        _mm256_mul_ps(b(col[0][c]), r[0]),
                        _mm256_mul_ps(b(col[1][c]), r[1]),
                    ),
                    _mm256_mul_ps(b(col[2][c]), r[2]),
                )
            });
        }
        let keep = _mm256_castsi256_ps(_mm256_cmpeq_epi32(
            _mm256_and_si256(_mm256_set1_epi32(glanes as i32), bits),
            bits,
        ));
        for (d, rc) in dirs.iter_mut().zip(r) {
            // g + 8 ≤ SPAN: the eight entries are in the array whatever `cnt` is.
            let p = d[g..g + 8].as_mut_ptr();
            _mm256_storeu_ps(p, _mm256_blendv_ps(_mm256_loadu_ps(p), rc, keep));
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
#[allow(clippy::too_many_arguments)]
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
    use std::arch::x86_64::*;
    let n = ids.len().min(SPAN);
    let b = |v: f32| _mm256_set1_ps(v);
    let fyv = b(fy);
    let two = b(2.0);
    let zero = _mm256_setzero_ps();
    let half = b(0.5);
    let sign = b(-0.0);
    let nf = b(cf.n as f32);
    let stride = cf.n as usize * cf.c;
    let mut left = 0u32;
    let mut g = 0;
    while g < n {
        let cnt = (n - g).min(8);
        let mut idb = [NO_HIT; 8];
        idb[..cnt].copy_from_slice(&ids[g..g + cnt]);
        let orow = &mut out[g * 4..(g + cnt) * 4];
        let idv = _mm256_loadu_si256(idb.as_ptr() as *const __m256i);
        let none = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(
            idv,
            _mm256_set1_epi32(NO_HIT as i32),
        ))) as u32;
        let mut todo = !none & ((1u32 << cnt) - 1);
        if todo == 0 {
            orow.fill(0.0);
            g += 8;
            continue;
        }
        let fx = _mm256_add_ps(
            b((x0 + g) as f32),
            _mm256_setr_ps(0.5, 1.5, 2.5, 3.5, 4.5, 5.5, 6.5, 7.5),
        );
        // Reflected directions and tints, one pass per distinct setup of the eight.
        let mut r = [zero; 3];
        let mut tint = [zero; 3];
        let mut mirror = 0u32;
        while todo != 0 {
            let id = idb[todo.trailing_zeros() as usize];
            let same = _mm256_castsi256_ps(_mm256_cmpeq_epi32(idv, _mm256_set1_epi32(id as i32)));
            let lanes = _mm256_movemask_ps(same) as u32;
            todo &= !lanes;
            let m = &setups[id as usize];
            if !m.mirror {
                left |= lanes << g;
                continue;
            }
            mirror |= lanes;
            let f = m.edges.map(|[dx, ay, dy, ax]| {
                _mm256_sub_ps(
                    _mm256_mul_ps(b(dx), _mm256_sub_ps(fyv, b(ay))),
                    _mm256_mul_ps(b(dy), _mm256_sub_ps(fx, b(ax))),
                )
            });
            let interp = |a: &[Vec3A; 3], c: usize| {
                _mm256_add_ps(
                    _mm256_add_ps(
                        _mm256_mul_ps(b(a[0][c]), f[0]),
                        _mm256_mul_ps(b(a[1][c]), f[1]),
                    ),
                    _mm256_mul_ps(b(a[2][c]), f[2]),
                )
            };
            let nv = [0, 1, 2].map(|c| interp(&m.n, c));
            let vv = if view.persp {
                [0, 1, 2].map(|c| interp(&m.v, c))
            } else {
                [0, 1, 2].map(|c| b(view.forward[c]))
            };
            let dot = |a: &[__m256; 3], c: &[__m256; 3]| {
                _mm256_add_ps(
                    _mm256_add_ps(_mm256_mul_ps(a[0], c[0]), _mm256_mul_ps(a[1], c[1])),
                    _mm256_mul_ps(a[2], c[2]),
                )
            };
            let nn = dot(&nv, &nv);
            let t = _mm256_mul_ps(dot(&nv, &vv), two);
            for c in 0..3 {
                let rc = _mm256_sub_ps(_mm256_mul_ps(vv[c], nn), _mm256_mul_ps(nv[c], t));
                r[c] = _mm256_blendv_ps(r[c], rc, same);
                tint[c] = _mm256_blendv_ps(tint[c], b(m.tint[c]), same);
            }
        }
        if let Some(rot) = view.rot {
            let col = [rot.x_axis, rot.y_axis, rot.z_axis];
            r = [0, 1, 2].map(|c| {
                _mm256_add_ps(
                    _mm256_add_ps(
                        _mm256_mul_ps(b(col[0][c]), r[0]),
                        _mm256_mul_ps(b(col[1][c]), r[1]),
                    ),
                    _mm256_mul_ps(b(col[2][c]), r[2]),
                )
            });
        }
        // CubeFace::select_f32 and CubeFaces::locate, eight lanes (as CubeFaces::locate4).
        let sel = |m: __m256, a: __m256, c: __m256| _mm256_blendv_ps(c, a, m);
        let [x, y, z] = r;
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
        let (px, py, pz) = (
            _mm256_cmp_ps::<_CMP_GE_OQ>(x, zero),
            _mm256_cmp_ps::<_CMP_GE_OQ>(y, zero),
            _mm256_cmp_ps::<_CMP_GE_OQ>(z, zero),
        );
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
        let inf = b(f32::INFINITY);
        let finite = _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_andnot_ps(sign, u), inf),
            _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_andnot_ps(sign, v), inf),
        );
        let ok = _mm256_movemask_ps(_mm256_and_ps(valid, finite)) as u32;
        let corner = |t: __m256| {
            let c = _mm256_sub_ps(_mm256_mul_ps(t, nf), half);
            let ti = _mm256_cvttps_epi32(c);
            let t0 = _mm256_add_epi32(
                ti,
                _mm256_castps_si256(_mm256_cmp_ps::<_CMP_GT_OQ>(_mm256_cvtepi32_ps(ti), c)),
            );
            (t0, _mm256_sub_ps(c, _mm256_cvtepi32_ps(t0)))
        };
        let (x0i, fxs) = corner(u);
        let (y0i, fys) = corner(v);
        let lo = _mm256_set1_epi32(-1);
        let hi = _mm256_set1_epi32(cf.n - 1);
        let inside = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_and_si256(
            _mm256_and_si256(_mm256_cmpgt_epi32(x0i, lo), _mm256_cmpgt_epi32(hi, x0i)),
            _mm256_and_si256(_mm256_cmpgt_epi32(y0i, lo), _mm256_cmpgt_epi32(hi, y0i)),
        ))) as u32;
        let index = _mm256_add_epi32(
            _mm256_mullo_epi32(y0i, _mm256_set1_epi32(stride as i32)),
            _mm256_mullo_epi32(x0i, _mm256_set1_epi32(cf.c as i32)),
        );
        let mut li = [[0i32; 8]; 2];
        let mut lf = [[0f32; 8]; 7];
        _mm256_storeu_si256(li[0].as_mut_ptr() as *mut __m256i, layer);
        _mm256_storeu_si256(li[1].as_mut_ptr() as *mut __m256i, index);
        for (o, t) in lf
            .iter_mut()
            .zip([fxs, fys, u, v, tint[0], tint[1], tint[2]])
        {
            _mm256_storeu_ps(o.as_mut_ptr(), t);
        }
        for (lane, o) in orow.chunks_exact_mut(4).enumerate() {
            let bit = 1 << lane;
            if mirror & bit == 0 {
                if none & bit != 0 {
                    o.fill(0.0);
                }
                continue; // not a mirror: the caller's
            }
            let loc = if ok & bit == 0 {
                CubeLoc::NONE
            } else if inside & bit == 0 {
                CubeLoc {
                    layer: li[0][lane] as u32,
                    i: SEAM,
                    a: lf[2][lane],
                    b: lf[3][lane],
                }
            } else {
                CubeLoc {
                    layer: li[0][lane] as u32,
                    i: li[1][lane] as u32,
                    a: lf[0][lane],
                    b: lf[1][lane],
                }
            };
            let t = [lf[4][lane], lf[5][lane], lf[6][lane], 1.0];
            o.copy_from_slice(&cf.fetch_tinted(&loc, t));
        }
        g += 8;
    }
    left
}
