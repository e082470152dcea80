//! The rasteriser: clip-space triangles into a visibility buffer, one entry per sample.
//!
//! Triangles are clipped against the near plane in homogeneous coordinates (`z + w ≥ 0`,
//! Sutherland–Hodgman), divided by `w` and mapped to the sample grid (OpenGL's viewport
//! transform, row 0 at the top). Coverage uses edge functions (half-spaces) evaluated at
//! sample centres with a top-left fill rule, so a sample on an edge shared by two triangles
//! is drawn exactly once. Depth is `z_ndc`, linear in screen space, tested with `<` and
//! limited to `[−1, 1]` (the far plane).
//!
//! Attributes are not interpolated here. The scan is a depth pass: each sample keeps only its
//! depth and the *setup* (clipped, projected triangle) it sees, four samples a SIMD step,
//! with no per-sample branch. What a visible sample needs afterwards is computed once, from
//! its setup ([`Binned::sample`]): the original triangle and its **perspective-correct**
//! barycentric coordinates with respect to the *original* (unclipped) triangle, evaluated
//! with exactly the operations the scan used, so depth and weights agree to the bit. With
//! screen-space barycentrics `λᵢ` and clip `wᵢ`, the weights
//! `bᵢ = (λᵢ/wᵢ) / Σⱼ(λⱼ/wⱼ)` are those under which any attribute that is linear on the
//! triangle in eye space interpolates exactly (the hyperbolic interpolation of OpenGL 4.6
//! §14.6.1, eq. 14.9). Vertices that clipping creates carry their own barycentric coordinates
//! in the original triangle, so the result is unchanged by clipping. Shading happens
//! afterwards, once per visible sample (a deferred, "visibility buffer" design).
//!
//! Work is split into horizontal bands of sample rows, rendered in parallel with rayon; each
//! band walks the triangles binned to it.

use glam::{BVec4A, Vec3, Vec4};
use mirrorball_core::simd::{I32x4, M32x4, X8};
use rayon::prelude::*;

/// The triangle index of a sample that sees no triangle.
pub const NO_HIT: u32 = u32::MAX;

/// What one sample sees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Normalised device depth in `[−1, 1]` (1 where nothing was drawn).
    pub depth: f32,
    /// Index of the original triangle, or [`NO_HIT`].
    pub tri: u32,
    /// Perspective-correct barycentric weight of the triangle's second vertex.
    pub b1: f32,
    /// Perspective-correct barycentric weight of the triangle's third vertex.
    pub b2: f32,
}

impl Sample {
    /// Nothing drawn.
    pub const EMPTY: Sample = Sample {
        depth: 1.0,
        tri: NO_HIT,
        b1: 0.0,
        b2: 0.0,
    };

    /// The three weights `(b0, b1, b2)`.
    #[inline]
    pub fn weights(&self) -> Vec3 {
        Vec3::new(1.0 - self.b1 - self.b2, self.b1, self.b2)
    }
}

/// A grid of samples, row 0 at the top.
#[cfg(test)]
#[derive(Clone, Debug)]
pub struct VisBuffer {
    /// `width × height` samples, row by row.
    pub samples: Vec<Sample>,
}

/// A clipped, projected triangle ready to scan (a *setup*; a triangle that the near plane
/// cuts gives two).
#[derive(Clone, Copy, Debug)]
struct Setup {
    /// Screen positions in sample units.
    p: [[f32; 2]; 3],
    z: [f32; 3],
    inv_w: [f32; 3],
    /// Barycentric coordinates of each vertex in the original triangle.
    ob: [Vec3; 3],
    area: f32,
    tri: u32,
    y0: u32,
    y1: u32,
    x0: u32,
    x1: u32,
}

/// A band's depth and setup id per sample, reused band after band by one thread
/// ([`Binned::scan_band`] fills it).
#[derive(Clone, Debug, Default)]
pub struct BandBuffer {
    depth: Vec<f32>,
    ids: Vec<u32>,
    /// Columns the last scan may have written (everything else is far and [`NO_HIT`]).
    dirty: std::ops::Range<usize>,
}

impl BandBuffer {
    /// Depth per sample (`z_ndc`; 1 where nothing was hit), row by row.
    pub fn depth(&self) -> &[f32] {
        &self.depth
    }

    /// Setup id per sample ([`NO_HIT`] where nothing was hit), row by row.
    pub fn ids(&self) -> &[u32] {
        &self.ids
    }
}

/// Which triangles the rasteriser leaves out, by their winding on screen (in OpenGL's window
/// coordinates, y up), as `glCullFace` does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cull {
    /// Every triangle is drawn.
    None,
    /// Triangles running clockwise on screen are left out (back faces of a mesh whose
    /// triangles run counter-clockwise seen from outside).
    Clockwise,
    /// Triangles running counter-clockwise on screen are left out.
    CounterClockwise,
}

/// A clip-space vertex with its barycentric coordinates in the original triangle.
#[derive(Clone, Copy, Debug)]
struct ClipVert {
    c: Vec4,
    ob: Vec3,
}

/// Triangles clipped, projected and binned into horizontal bands of sample rows, ready to
/// be scanned band by band (in parallel, and fused with shading by the renderer).
#[derive(Clone, Debug)]
pub struct Binned {
    setups: Vec<Setup>,
    bins: Vec<Vec<u32>>,
    width: u32,
    height: u32,
    band: u32,
}

impl Binned {
    /// Sets up triangles `tris` over clip-space vertices `clip` for a `width × height`
    /// sample grid cut into bands of `band` rows, leaving out triangle `i` where its winding
    /// on screen is the one `cull(i)` names.
    pub fn new(
        clip: &[Vec4],
        tris: &[[u32; 3]],
        width: u32,
        height: u32,
        band: u32,
        cull: impl Fn(u32) -> Cull + Sync,
    ) -> Binned {
        let band = band.max(1);
        let setups: Vec<Setup> = tris
            .par_iter()
            .enumerate()
            .fold(Vec::new, |mut acc, (i, t)| {
                let i = i as u32;
                setup_triangle(clip, *t, i, width, height, cull(i), &mut acc);
                acc
            })
            .flat_map_iter(|v| v.into_iter())
            .collect();
        let bands = height.div_ceil(band) as usize;
        let mut bins: Vec<Vec<u32>> = vec![Vec::new(); bands];
        for (i, s) in setups.iter().enumerate() {
            for bin in &mut bins[(s.y0 / band) as usize..=(s.y1 / band) as usize] {
                bin.push(i as u32);
            }
        }
        Binned {
            setups,
            bins,
            width,
            height,
            band,
        }
    }

    /// Scans band `b` into `buf` (its samples row by row, `width ×` the band's rows): each
    /// sample keeps the nearest depth and the setup seen there, which [`Binned::sample`]
    /// resolves, or far (1) and [`NO_HIT`]. Returns the columns `c0..c1` outside which the
    /// band has no hit; only those, and the ones the buffer's previous band may have
    /// written, are reset first (an object covering a quarter of the frame's width leaves
    /// three quarters of each band untouched).
    pub fn scan_band(&self, b: usize, buf: &mut BandBuffer) -> std::ops::Range<usize> {
        let y_start = b as u32 * self.band;
        let rows = self.band.min(self.height.saturating_sub(y_start));
        let w = self.width as usize;
        let n = rows as usize * w;
        if buf.depth.len() != n {
            buf.depth.clear();
            buf.depth.resize(n, 1.0);
            buf.ids.clear();
            buf.ids.resize(n, NO_HIT);
            buf.dirty = 0..0;
        }
        let cols = self.bins[b]
            .iter()
            .map(|&si| &self.setups[si as usize])
            .fold(None, |r: Option<(u32, u32)>, s| {
                Some(r.map_or((s.x0, s.x1), |(a, b)| (a.min(s.x0), b.max(s.x1))))
            })
            .map_or(0..0, |(a, b)| a as usize..b as usize + 1);
        // Reset what the last scan may have written and what this one will read: their
        // hull where they overlap, else each.
        let (d, c) = (buf.dirty.clone(), cols.clone());
        let spans = if d.is_empty() || c.is_empty() || (d.start <= c.end && c.start <= d.end) {
            [d.start.min(c.start)..d.end.max(c.end), 0..0]
        } else {
            [d, c]
        };
        for span in spans.into_iter().filter(|r| !r.is_empty()) {
            for r in 0..rows as usize {
                buf.depth[r * w + span.start..r * w + span.end].fill(1.0);
                buf.ids[r * w + span.start..r * w + span.end].fill(NO_HIT);
            }
        }
        buf.dirty = cols.clone();
        let (depth, ids) = (&mut buf.depth[..], &mut buf.ids[..]);
        if let Some(x8) = crate::cpu::x8() {
            scan_bin_x8(
                x8,
                &self.bins[b],
                &self.setups,
                depth,
                ids,
                y_start,
                self.width,
            );
            return cols;
        }
        for &si in &self.bins[b] {
            scan(
                &self.setups[si as usize],
                si,
                depth,
                ids,
                y_start,
                self.width,
            );
        }
        cols
    }

    /// What the sample at `(x, y)` of the grid sees, given the setup `id` and `depth` the
    /// scan left there: the original triangle and its perspective-correct weights, computed
    /// with exactly the scan's operations.
    #[inline]
    pub fn sample(&self, id: u32, depth: f32, x: u32, y: u32) -> Sample {
        if id == NO_HIT {
            return Sample::EMPTY;
        }
        let s = &self.setups[id as usize];
        let l = self.edge_values(id, x, y).map(|f| f * (1.0 / s.area));
        let (q0, q1, q2) = (l[0] * s.inv_w[0], l[1] * s.inv_w[1], l[2] * s.inv_w[2]);
        let sum = q0 + q1 + q2;
        let b = (s.ob[0] * q0 + s.ob[1] * q1 + s.ob[2] * q2) / sum;
        Sample {
            depth,
            tri: s.tri,
            b1: b.y,
            b2: b.z,
        }
    }

    /// The three edge functions of setup `id` at the centre of sample `(x, y)`, as the scan
    /// computes them: `fₖ` is twice the area of the sub-triangle opposite the setup's corner
    /// `k`, so `fₖ / area` are the screen-space barycentrics `λₖ` (positive inside).
    #[inline]
    pub fn edge_values(&self, id: u32, x: u32, y: u32) -> [f32; 3] {
        let e = self.edges(id);
        let (qx, qy) = (x as f32 + 0.5, y as f32 + 0.5);
        e.map(|[dx, ay, dy, ax]| dx * (qy - ay) - dy * (qx - ax))
    }

    /// Setup `id`'s edges as `[b.x − a.x, a.y, b.y − a.y, a.x]` for the edge `a → b` opposite
    /// each corner: the edge function at `q` is `(b.x − a.x)(q.y − a.y) − (b.y − a.y)(q.x −
    /// a.x)`.
    #[inline]
    pub fn edges(&self, id: u32) -> [[f32; 4]; 3] {
        let [p0, p1, p2] = self.setups[id as usize].p;
        [(p1, p2), (p2, p0), (p0, p1)].map(|(a, b)| [b[0] - a[0], a[1], b[1] - a[1], a[0]])
    }

    /// Setup `id`'s original triangle, the barycentric coordinates of its three corners in
    /// that triangle, and for each corner the factor `1 / (w · area)` that turns an edge
    /// value of [`Binned::edge_values`] into the corner's perspective weight up to one
    /// common positive factor per sample: attributes linear on the triangle in eye space
    /// interpolate as `Σₖ fₖ·scaleₖ·Aₖ / Σₖ fₖ·scaleₖ`.
    pub fn corners(&self, id: u32) -> (u32, [Vec3; 3], [f32; 3]) {
        let s = &self.setups[id as usize];
        let inv_area = 1.0 / s.area;
        (s.tri, s.ob, s.inv_w.map(|w| w * inv_area))
    }

    /// Number of setups (ids run from 0).
    pub fn setup_count(&self) -> usize {
        self.setups.len()
    }

    /// Whether band `b` has any triangle.
    pub fn band_is_empty(&self, b: usize) -> bool {
        self.bins[b].is_empty()
    }
}

/// Sample rows per band of [`rasterize`].
#[cfg(test)]
const BAND: u32 = 8;

/// Rasterises triangles `tris` over clip-space vertices `clip` into a `width × height`
/// sample grid: the whole scan, for tests.
#[cfg(test)]
fn rasterize(clip: &[Vec4], tris: &[[u32; 3]], width: u32, height: u32) -> VisBuffer {
    let binned = Binned::new(clip, tris, width, height, BAND, |_| Cull::None);
    let mut samples = vec![Sample::EMPTY; width as usize * height as usize];
    samples
        .par_chunks_mut(width as usize * BAND as usize)
        .enumerate()
        .for_each(|(b, rows)| {
            let mut buf = BandBuffer::default();
            binned.scan_band(b, &mut buf);
            let y0 = b as u32 * BAND;
            for (i, cell) in rows.iter_mut().enumerate() {
                let (x, y) = (i as u32 % width, y0 + i as u32 / width);
                *cell = binned.sample(buf.ids[i], buf.depth[i], x, y);
            }
        });
    VisBuffer { samples }
}

/// Clips triangle `t` against the near plane and pushes what is left (a fan of up to two
/// triangles) as setups.
fn setup_triangle(
    clip: &[Vec4],
    t: [u32; 3],
    tri: u32,
    width: u32,
    height: u32,
    cull: Cull,
    out: &mut Vec<Setup>,
) {
    let v = t.map(|i| clip[i as usize]);
    if v.iter().any(|c| !c.is_finite()) {
        return;
    }
    // Trivial rejection against each frustum plane.
    let outside = |f: &dyn Fn(Vec4) -> bool| v.iter().all(|&c| f(c));
    if outside(&|c| c.x > c.w)
        || outside(&|c| c.x < -c.w)
        || outside(&|c| c.y > c.w)
        || outside(&|c| c.y < -c.w)
        || outside(&|c| c.z > c.w)
        || outside(&|c| c.z < -c.w)
    {
        return;
    }
    let verts = [
        ClipVert {
            c: v[0],
            ob: Vec3::X,
        },
        ClipVert {
            c: v[1],
            ob: Vec3::Y,
        },
        ClipVert {
            c: v[2],
            ob: Vec3::Z,
        },
    ];
    let d = |c: Vec4| c.z + c.w; // ≥ 0 inside the near plane

    // At most four vertices survive one plane; kept on the stack (no allocation per
    // triangle).
    let mut poly = [verts[0]; 4];
    let mut len = 0;
    if verts.iter().all(|p| d(p.c) >= 0.0) {
        poly[..3].copy_from_slice(&verts);
        len = 3;
    } else {
        for i in 0..3 {
            let a = verts[i];
            let b = verts[(i + 1) % 3];
            let (da, db) = (d(a.c), d(b.c));
            if da >= 0.0 {
                poly[len] = a;
                len += 1;
            }
            if (da >= 0.0) != (db >= 0.0) {
                let s = da / (da - db);
                poly[len] = ClipVert {
                    c: a.c + (b.c - a.c) * s,
                    ob: a.ob + (b.ob - a.ob) * s,
                };
                len += 1;
            }
        }
    }
    for k in 1..len.saturating_sub(1) {
        if let Some(s) = project([poly[0], poly[k], poly[k + 1]], tri, width, height, cull) {
            out.push(s);
        }
    }
}

/// Divides by `w`, maps to the sample grid and prepares the edge functions.
fn project(v: [ClipVert; 3], tri: u32, width: u32, height: u32, cull: Cull) -> Option<Setup> {
    let (fw, fh) = (width as f32, height as f32);
    let mut p = [[0.0f32; 2]; 3];
    let mut z = [0.0f32; 3];
    let mut inv_w = [0.0f32; 3];
    for i in 0..3 {
        let w = v[i].c.w;
        if w.is_nan() || w <= 0.0 {
            return None;
        }
        let iw = 1.0 / w;
        p[i] = [
            (v[i].c.x * iw + 1.0) * 0.5 * fw,
            (1.0 - v[i].c.y * iw) * 0.5 * fh,
        ];
        z[i] = v[i].c.z * iw;
        inv_w[i] = iw;
    }
    let mut ob = [v[0].ob, v[1].ob, v[2].ob];
    // Signed area in the y-down grid; make it positive (both faces are drawn).
    let mut area =
        (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]);
    if !area.is_finite() || area == 0.0 {
        return None;
    }
    // Counter-clockwise in OpenGL's y-up window coordinates is a negative area here.
    match cull {
        Cull::CounterClockwise if area < 0.0 => return None,
        Cull::Clockwise if area > 0.0 => return None,
        _ => {}
    }
    if area < 0.0 {
        p.swap(1, 2);
        z.swap(1, 2);
        inv_w.swap(1, 2);
        ob.swap(1, 2);
        area = -area;
    }
    let minx = p.iter().map(|q| q[0]).fold(f32::INFINITY, f32::min);
    let maxx = p.iter().map(|q| q[0]).fold(f32::NEG_INFINITY, f32::max);
    let miny = p.iter().map(|q| q[1]).fold(f32::INFINITY, f32::min);
    let maxy = p.iter().map(|q| q[1]).fold(f32::NEG_INFINITY, f32::max);
    // Samples at x + ½ inside [minx, maxx].
    let x0 = (minx - 0.5).ceil().max(0.0);
    let x1 = (maxx - 0.5).floor().min(fw - 1.0);
    let y0 = (miny - 0.5).ceil().max(0.0);
    let y1 = (maxy - 0.5).floor().min(fh - 1.0);
    if x0 > x1 || y0 > y1 {
        return None;
    }
    Some(Setup {
        p,
        z,
        inv_w,
        ob,
        area,
        tri,
        x0: x0 as u32,
        x1: x1 as u32,
        y0: y0 as u32,
        y1: y1 as u32,
    })
}

/// Whether a sample exactly on edge `a → b` belongs to the triangle (top-left rule, for
/// y-down coordinates and positive area).
#[inline]
fn top_left(a: [f32; 2], b: [f32; 2]) -> bool {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    // Positive area with y down means the vertices run clockwise on screen: the top edge
    // runs to the right (dy = 0, dx > 0) and left edges run upwards (dy < 0).
    (dy == 0.0 && dx > 0.0) || dy < 0.0
}

/// Scans one setup (number `id`) over the rows of a band: the depth test, four samples a
/// step.
fn scan(s: &Setup, id: u32, depth: &mut [f32], ids: &mut [u32], y_start: u32, width: u32) {
    let band_rows = depth.len() as u32 / width;
    let ya = s.y0.max(y_start);
    let yb = s.y1.min(y_start + band_rows - 1);
    if ya > yb {
        return;
    }
    let [p0, p1, p2] = s.p;
    let tl = [top_left(p1, p2), top_left(p2, p0), top_left(p0, p1)];
    let inv_area = 1.0 / s.area;
    // Edge functions are evaluated afresh at every sample (not accumulated), so that two
    // triangles sharing an edge compute bit-identical values there and the fill rule holds.
    let tl4 = tl.map(BVec4A::splat);
    let z4 = s.z.map(Vec4::splat);
    let x_end = Vec4::splat(s.x1 as f32 + 1.0);
    let edges = [(p1, p2), (p2, p0), (p0, p1)];
    for y in ya..=yb {
        let qy = y as f32 + 0.5;
        let xs = row_start(s, &edges, qy);
        if xs > s.x1 {
            continue;
        }
        let r0 = ((y - y_start) * width) as usize;
        let drow = &mut depth[r0..r0 + width as usize];
        let irow = &mut ids[r0..r0 + width as usize];
        // The edge function of a → b at sample centre q, positive inside a triangle whose
        // [`project`] made the area positive, is (b.x − a.x)(q.y − a.y) − (b.y − a.y)(q.x −
        // a.x) = c − d·(q.x − a.x), with c constant along the row: each sample (one SIMD
        // lane of four) forms the same products and differences, whichever its neighbours,
        // and [`Binned::edge_values`] the same again.
        let ec = edges.map(|(a, b)| ((b[0] - a[0]) * (qy - a[1]), b[1] - a[1], a[0]));
        let ev = ec.map(|(c, d, ax)| (Vec4::splat(c), Vec4::splat(d), Vec4::splat(ax)));
        // The covered samples of a row are contiguous (the triangle is convex, and each
        // edge function is monotonic along the row even in floating point): once past
        // them, the rest of the row is outside.
        let mut entered = false;
        let mut x4 = xs;
        while x4 <= s.x1 {
            let qx = Vec4::splat(x4 as f32) + LANES;
            let f = ev.map(|(c, d, ax)| c - d * (qx - ax));
            let mut mask = BVec4A::splat(true);
            for (fk, t) in f.iter().zip(tl4) {
                mask &= fk.cmpgt(Vec4::ZERO) | (fk.cmpeq(Vec4::ZERO) & t);
            }
            // Lanes past the bounding box do not count.
            mask &= qx.cmplt(x_end);
            let bits = mask.bitmask();
            if bits == 0 {
                if entered {
                    break;
                }
                x4 += 4;
                continue;
            }
            entered = true;
            // Depth for the four lanes at once (the same operations per lane, and as
            // [`Binned::sample`]), tested against the samples' depths: z < depth and z ≥ −1
            // (NaN fails both).
            let l = f.map(|v| v * inv_area);
            let z = l[0] * z4[0] + l[1] * z4[1] + l[2] * z4[2];
            let x = x4 as usize;
            if x + 4 <= drow.len() {
                let old = Vec4::from_slice(&drow[x..x + 4]);
                let m = mask & z.cmplt(old) & z.cmpge(Vec4::NEG_ONE);
                let keep = m.bitmask();
                if keep == 0 {
                    x4 += 4;
                    continue;
                }
                Vec4::select(m, z, old).write_to_slice(&mut drow[x..x + 4]);
                blend_ids(&mut irow[x..x + 4], keep, id);
            } else {
                let z = z.to_array();
                for lane in 0..drow.len() - x {
                    if bits & (1 << lane) != 0 && z[lane] < drow[x + lane] && z[lane] >= -1.0 {
                        drow[x + lane] = z[lane];
                        irow[x + lane] = id;
                    }
                }
            }
            x4 += 4;
        }
    }
}

/// Where the scan of sample row `qy` (its centre) starts: each edge a → b whose function
/// grows with x bounds the row's covered span on the left (inside needs x ≥ a.x + (b.x −
/// a.x)(y − a.y)/(b.y − a.y)); the scan starts a sample before the rightmost such bound
/// (rounding cannot move it that far) and tests exactly from there. Past `s.x1` where the
/// row is empty.
#[inline(always)]
fn row_start(s: &Setup, edges: &[([f32; 2], [f32; 2]); 3], qy: f32) -> u32 {
    let mut xs = s.x0;
    for &(a, b) in edges {
        let dy = b[1] - a[1];
        if dy < 0.0 {
            let bound = a[0] + (b[0] - a[0]) * (qy - a[1]) / dy - 1.5;
            if bound.is_finite() && bound > xs as f32 {
                xs = (bound as u32).min(s.x1 + 1);
            }
        }
    }
    xs
}

mirrorball_core::simd::x8_kernel! {
    /// [`scan_x8`] of every setup in a band's bin.
    fn scan_bin_x8(
        x8: X8,
        bin: &[u32],
        setups: &[Setup],
        depth: &mut [f32],
        ids: &mut [u32],
        y_start: u32,
        width: u32,
    ) {
        for &si in bin {
            scan_x8(x8, &setups[si as usize], si, depth, ids, y_start, width);
        }
    }
}

/// [`scan`] eight samples a step (AVX2 where the processor has it): each lane does the same
/// operations in the same order, so depths, ids and the fill rule come out the same to the
/// bit.
#[inline(always)]
fn scan_x8(
    x8: X8,
    s: &Setup,
    id: u32,
    depth: &mut [f32],
    ids: &mut [u32],
    y_start: u32,
    width: u32,
) {
    let band_rows = depth.len() as u32 / width;
    let ya = s.y0.max(y_start);
    let yb = s.y1.min(y_start + band_rows - 1);
    if ya > yb {
        return;
    }
    let [p0, p1, p2] = s.p;
    let edges = [(p1, p2), (p2, p0), (p0, p1)];
    // Written out rather than mapped: a closure would be compiled without the kernel's AVX2.
    let tl_bits = |(a, c)| if top_left(a, c) { 0xFF } else { 0 };
    let tl = [
        x8.mask(tl_bits(edges[0])),
        x8.mask(tl_bits(edges[1])),
        x8.mask(tl_bits(edges[2])),
    ];
    let inv_area = x8.splat(1.0 / s.area);
    let z4 = [x8.splat(s.z[0]), x8.splat(s.z[1]), x8.splat(s.z[2])];
    let x_end = x8.splat(s.x1 as f32 + 1.0);
    let lanes = x8.f32s([0.5, 1.5, 2.5, 3.5, 4.5, 5.5, 6.5, 7.5]);
    let zero = x8.splat(0.0);
    let idv = x8.splat_i32(id as i32);
    let neg_one = x8.splat(-1.0);
    for y in ya..=yb {
        let qy = y as f32 + 0.5;
        let xs = row_start(s, &edges, qy);
        if xs > s.x1 {
            continue;
        }
        let r0 = ((y - y_start) * width) as usize;
        let drow = &mut depth[r0..r0 + width as usize];
        let irow = &mut ids[r0..r0 + width as usize];
        let ev = edges.map(|(a, c)| {
            (
                x8.splat((c[0] - a[0]) * (qy - a[1])),
                x8.splat(c[1] - a[1]),
                x8.splat(a[0]),
            )
        });
        let mut entered = false;
        let mut xq = xs;
        while xq <= s.x1 {
            let qx = x8.splat(xq as f32) + lanes;
            let mut f = [zero; 3];
            let mut mask = qx.lt(x_end);
            for k in 0..3 {
                let (c, d, ax) = ev[k];
                f[k] = c - d * (qx - ax);
                mask = mask & (f[k].gt(zero) | (f[k].eq(zero) & tl[k]));
            }
            if !mask.any() {
                if entered {
                    break;
                }
                xq += 8;
                continue;
            }
            entered = true;
            let z =
                ((f[0] * inv_area) * z4[0] + (f[1] * inv_area) * z4[1]) + (f[2] * inv_area) * z4[2];
            let x = xq as usize;
            if x + 8 <= drow.len() {
                let old = x8.load(&drow[x..]);
                let m = mask & z.lt(old) & z.ge(neg_one);
                if m.any() {
                    m.select(z, old).store(&mut drow[x..]);
                    let io: &mut [u32; 8] = (&mut irow[x..x + 8]).try_into().unwrap();
                    let new = m.select_i32(idv, x8.u32s(io)).to_array();
                    *io = new.map(|v| v as u32);
                }
            } else {
                let (zs, ms) = (z.to_array(), mask.bitmask());
                for lane in 0..drow.len() - x {
                    let z = zs[lane];
                    if ms & (1 << lane) != 0 && z < drow[x + lane] && z >= -1.0 {
                        drow[x + lane] = z;
                        irow[x + lane] = id;
                    }
                }
            }
            xq += 8;
        }
    }
}

/// Sets the lanes of `ids` (four) selected by the low four bits of `keep` to `id`.
#[inline(always)]
fn blend_ids(ids: &mut [u32], keep: u32, id: u32) {
    let ids: &mut [u32; 4] = (&mut ids[..4]).try_into().unwrap();
    let old = I32x4::from_array(ids.map(|v| v as i32));
    let new = M32x4::from_bitmask(keep).select_i32(I32x4::splat(id as i32), old);
    *ids = new.to_array().map(|v| v as u32);
}

/// Offsets of the four samples a SIMD step of [`scan`] tests (sample centres).
const LANES: Vec4 = Vec4::new(0.5, 1.5, 2.5, 3.5);

#[cfg(test)]
mod tests;
