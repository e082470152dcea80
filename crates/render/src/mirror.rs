//! The per-pixel mirror's reflected direction, the renderer's commonest and hottest case,
//! computed from per-setup corner attributes: one pixel at a time ([`mirror_dir`]), or
//! eight at a time (AVX2 where the processor has it: [`mirror_dirs`]), to the same bits.
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
use mirrorball_core::simd::{F32x8, Taps, X8};

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
    if let Some(x8) = crate::cpu::x8() {
        mirror_dirs_x8(x8, ids, lanes, x0, fy, setups, view, dirs);
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

mirrorball_core::simd::x8_kernel! {
    /// [`mirror_dirs`] eight pixels a step ([`v8::reflect`]).
    fn mirror_dirs_x8(
        x8: X8,
        ids: &[u32],
        lanes: u32,
        x0: usize,
        fy: f32,
        setups: &[MirrorSetup],
        view: &MirrorView,
        dirs: &mut [[f32; SPAN]; 3],
    ) {
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
            let ev = v8::reflect(x8, &idb, glanes, x0 + g, fy, setups, view);
            let keep = x8.mask(glanes);
            for (d, r) in dirs.iter_mut().zip(ev.r) {
                // g + 8 ≤ SPAN: the eight entries are in the array whatever `cnt` is.
                let d = &mut d[g..g + 8];
                keep.select(r, x8.load(d)).store(d);
            }
            g += 8;
        }
    }
}

/// The whole per-pixel mirror of a row segment of a frame without background, eight pixels
/// a step: reflected directions ([`mirror_dirs`]'s arithmetic), the cube face and texel of
/// each ([`CubeFaces::locate`](crate::fast::CubeFaces::locate)'s arithmetic, face chosen by
/// masks), then each pixel's bilinear read
/// ([`CubeFaces::fetch_tinted`](crate::fast::CubeFaces::fetch_tinted)) written to `out`
/// (four floats a pixel). Pixels that see nothing are written transparent black. Returns
/// the lanes whose setup is not a mirror, left for the caller to shade; `None` where the
/// eight-lane paths are off (no AVX2, or [`set_portable`](crate::set_portable) said so) or
/// the faces are too small for footprint reads, having done nothing.
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
    let x8 = crate::cpu::x8()?;
    let taps = cf.taps.as_ref()?;
    Some(mirror_row_x8(x8, ids, x0, fy, setups, view, cf, taps, out))
}

mirrorball_core::simd::x8_kernel! {
    fn mirror_row_x8(
        x8: X8,
        ids: &[u32],
        x0: usize,
        fy: f32,
        setups: &[MirrorSetup],
        view: &MirrorView,
        cf: &crate::fast::CubeFaces,
        taps: &Taps<6>,
        out: &mut [f32],
    ) -> u32 {
        let n = ids.len().min(SPAN);
        let (px, _) = out.as_chunks_mut::<4>();
        let mut left = 0u32;
        let mut g = 0;
        while g < n {
            let cnt = (n - g).min(8);
            let mut idb = [crate::raster::NO_HIT; 8];
            idb[..cnt].copy_from_slice(&ids[g..g + cnt]);
            let px = &mut px[g..g + cnt];
            let row = Group { idb: &idb, cnt, x0: x0 + g, fy };
            left |= match <&mut [[f32; 4]; 8]>::try_from(&mut *px) {
                Ok(px8) => mirror_group(x8, &row, setups, view, cf, taps, px8),
                Err(_) => {
                    // The row's last, partial group: through eight pixels of scratch.
                    let mut px8 = [[0.0f32; 4]; 8];
                    px8[..cnt].copy_from_slice(px);
                    let left = mirror_group(x8, &row, setups, view, cf, taps, &mut px8);
                    px.copy_from_slice(&px8[..cnt]);
                    left
                }
            } << g;
            g += 8;
        }
        left
    }
}

/// Eight pixels of a row for [`mirror_group`]: setup ids (the first `cnt` real, the rest
/// `NO_HIT`), the first one's column, the row's centre.
struct Group<'a> {
    idb: &'a [u32; 8],
    cnt: usize,
    x0: usize,
    fy: f32,
}

/// [`mirror_row`] of one group of eight pixels into `px`: pixels that see nothing are made
/// transparent black, mirror pixels are blended (straight from [`Taps`] where the four
/// texels lie in one face, else through `fetch_tinted`); returns the lanes left to shade.
#[inline(always)]
fn mirror_group(
    x8: X8,
    row: &Group,
    setups: &[MirrorSetup],
    view: &MirrorView,
    cf: &crate::fast::CubeFaces,
    taps: &Taps<6>,
    px: &mut [[f32; 4]; 8],
) -> u32 {
    use crate::fast::{tinted, CubeLoc, SEAM};
    let lanes = (1u32 << row.cnt) - 1;
    let none = x8
        .u32s(row.idb)
        .eq(x8.splat_i32(crate::raster::NO_HIT as i32))
        .bitmask();
    let hit = !none & lanes;
    if hit == 0 {
        *px = [[0.0; 4]; 8];
        return 0;
    }
    let ev = v8::reflect(x8, row.idb, hit, row.x0, row.fy, setups, view);
    let at = v8::locate(x8, &ev.r, cf, taps);
    let tint = F32x8::interleave4([ev.tint[0], ev.tint[1], ev.tint[2], x8.splat(1.0)]);
    // Mirror lanes whose four texels lie inside one face and within the taps' reach:
    // straight to the blend, no further test.
    let direct = ev.mirror & at.ok & at.inside & at.reach & lanes;
    let mut m = direct;
    while m != 0 {
        let lane = m.trailing_zeros() as usize;
        m &= m - 1;
        let q = taps.get(at.layer[lane] as usize, at.index[lane] as usize);
        tinted(q, at.fx[lane], at.fy[lane], &tint[lane], &mut px[lane]);
    }
    let mut rest = lanes & !direct;
    while rest != 0 {
        let lane = rest.trailing_zeros() as usize;
        rest &= rest - 1;
        let bit = 1 << lane;
        if ev.mirror & bit == 0 {
            if none & bit != 0 {
                px[lane] = [0.0; 4];
            }
            continue; // not a mirror: the caller's
        }
        // A mirror lane not blended above: no face, across a seam, or too near a face's
        // end for four-lane reads; `fetch_tinted` sorts out which.
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
        px[lane] = cf.fetch_tinted(&loc, tint[lane]);
    }
    ev.left
}

/// Eight-lane building blocks, each lane doing the scalar code's operations in its order
/// (no fused multiply-add), so that every result is the scalar result to the bit.
mod v8 {
    use super::{MirrorSetup, MirrorView};
    use crate::fast::CubeFaces;
    use glam::Vec3A;
    use mirrorball_core::simd::{F32x8, Taps, X8};
    use mirrorball_core::{bilinear_corner8, CubeMap};

    /// Reflected directions and tints of eight pixels.
    pub struct Reflected {
        pub r: [F32x8; 3],
        pub tint: [F32x8; 3],
        /// Lanes whose setup is a mirror (directions and tints set).
        pub mirror: u32,
        /// Lanes whose setup is not a mirror.
        pub left: u32,
    }

    /// Where eight cube lookups read, as `CubeFaces::locate` computes it.
    pub struct Located {
        pub ok: u32,
        pub inside: u32,
        /// Lanes whose index is at most `Taps::last` (four-lane reads of the second texel
        /// of the lower row stay inside the face).
        pub reach: u32,
        pub layer: [i32; 8],
        pub index: [i32; 8],
        pub fx: [f32; 8],
        pub fy: [f32; 8],
        pub u: [f32; 8],
        pub v: [f32; 8],
    }

    /// `(x·x' + y·y') + z·z'`, as glam's `Vec3A::dot`.
    #[inline(always)]
    fn dot(a: &[F32x8; 3], b: &[F32x8; 3]) -> F32x8 {
        (a[0] * b[0] + a[1] * b[1]) + a[2] * b[2]
    }

    /// `mirror_dir` of the pixels at columns `x0 ..` of `idb` whose bit is set in `lanes`,
    /// once per distinct setup among them (its values broadcast, its pixels blended in).
    #[inline(always)]
    pub fn reflect(
        x8: X8,
        idb: &[u32; 8],
        lanes: u32,
        x0: usize,
        fy: f32,
        setups: &[MirrorSetup],
        view: &MirrorView,
    ) -> Reflected {
        let idv = x8.u32s(idb);
        let fx = x8.splat(x0 as f32) + x8.f32s([0.5, 1.5, 2.5, 3.5, 4.5, 5.5, 6.5, 7.5]);
        let zero = x8.splat(0.0);
        let mut out = Reflected {
            r: [zero; 3],
            tint: [zero; 3],
            mirror: 0,
            left: 0,
        };
        let mut todo = lanes;
        while todo != 0 {
            let id = idb[todo.trailing_zeros() as usize];
            let same = idv.eq(x8.splat_i32(id as i32));
            let bits = same.bitmask() & lanes;
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
            let dx = fx - x8.splat(m.origin[0]);
            // A macro, not a closure: a closure would be compiled without the kernel's AVX2.
            macro_rules! plane {
                ($a:expr) => {{
                    let a: &[Vec3A; 3] = $a;
                    let row = a[0] + a[2] * dy;
                    [
                        x8.splat(row[0]) + x8.splat(a[1][0]) * dx,
                        x8.splat(row[1]) + x8.splat(a[1][1]) * dx,
                        x8.splat(row[2]) + x8.splat(a[1][2]) * dx,
                    ]
                }};
            }
            let v = if view.persp || view.per_vertex {
                plane!(&m.v)
            } else {
                [
                    x8.splat(view.forward.x),
                    x8.splat(view.forward.y),
                    x8.splat(view.forward.z),
                ]
            };
            let r = if view.per_vertex {
                v // mode 2: the interpolated reflected vector itself
            } else {
                let n = plane!(&m.n);
                let nn = dot(&n, &n);
                let t = dot(&n, &v) * x8.splat(2.0);
                [
                    v[0] * nn - n[0] * t,
                    v[1] * nn - n[1] * t,
                    v[2] * nn - n[2] * t,
                ]
            };
            for (c, rc) in r.into_iter().enumerate() {
                out.r[c] = same.select(rc, out.r[c]);
                out.tint[c] = same.select(x8.splat(m.tint[c]), out.tint[c]);
            }
        }
        if let Some(rot) = view.rot {
            let col = [rot.x_axis, rot.y_axis, rot.z_axis];
            let r = out.r;
            for (c, rc) in out.r.iter_mut().enumerate() {
                *rc = (x8.splat(col[0][c]) * r[0] + x8.splat(col[1][c]) * r[1])
                    + x8.splat(col[2][c]) * r[2];
            }
        }
        out
    }

    /// `CubeFaces::locate` of eight directions: [`CubeMap::uv8`] and
    /// [`bilinear_corner8`] (as `CubeFaces::locate4` with four); `reach`: the index is
    /// within `taps.last()`.
    #[inline(always)]
    pub fn locate(x8: X8, r: &[F32x8; 3], cf: &CubeFaces, taps: &Taps<6>) -> Located {
        let f = CubeMap::uv8(x8, r[0], r[1], r[2]);
        let (u, v) = (f.sc, f.tc);
        let inf = x8.splat(f32::INFINITY);
        let ok = f.ma.gt(x8.splat(0.0)) & u.abs().lt(inf) & v.abs().lt(inf);
        let c = bilinear_corner8(x8, u, v, cf.n as u32, cf.n as u32);
        let stride = cf.n * cf.c as i32;
        let index = c.y0 * x8.splat_i32(stride) + c.x0 * x8.splat_i32(cf.c as i32);
        let last = i32::try_from(taps.last()).unwrap_or(i32::MAX);
        let beyond = index.gt(x8.splat_i32(last));
        Located {
            ok: ok.bitmask(),
            inside: c.inside.bitmask(),
            reach: !beyond.bitmask() & 0xff,
            layer: f.layer.to_array(),
            index: index.to_array(),
            fx: c.fx.to_array(),
            fy: c.fy.to_array(),
            u: u.to_array(),
            v: v.to_array(),
        }
    }
}
