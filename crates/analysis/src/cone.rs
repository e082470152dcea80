//! The region of a projection one reflection cone covers (Greene 1986, figure 2).
//!
//! Greene reflects the four rays through a screen pixel's corners off a strongly curved
//! surface; the four reflected rays bound a *reflection cone*, whose sides are planes through
//! the world centre, so on the sphere it is a spherical quadrilateral with great-circle
//! edges. His figure shows one covering "about 3/8 of the world" drawn on a Mercator and on
//! a cube projection, and notes that on the cube the region is polygonal (great circles
//! project to straight lines on a cube face, since a plane through the cube's centre cuts a
//! face in a line) but split into several pieces ("five in the example of Figure 2"), while
//! on the Mercator it is one piece with curved edges.
//!
//! [`Cone::square`] builds a regular spherical quadrilateral of a given share of the sphere
//! about an axis (its corner radius is found by bisection on the exact polygon area). For
//! each projection [`cone_region`] classifies every texel by its centre (inside the cone or
//! not), counts the connected pieces (4-connected, per layer: a piece that crosses a cube
//! edge or the lat-long seam counts once on each side, as a filter must treat it), sums the
//! pieces' exact texel solid angles, and measures how straight the mapped edges are: each
//! edge is sampled along its great circle, mapped with `dir_to_uv`, cut where it changes
//! layer or jumps a seam, and the largest distance of a piece from its chord is reported in
//! texels (zero for the cube, to rounding: Greene's "polygonal regions").

use crate::geom::{basis, spherical_polygon_area};
use glam::{DVec2, DVec3};
use mirrorball_core::par::fold_in_order;
use mirrorball_core::{Projection, WorldProjection};
use rayon::prelude::*;
use serde::Serialize;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

/// A convex spherical quadrilateral: the reflection cone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    /// Corner directions (unit), in order around the cone.
    pub corners: [DVec3; 4],
    /// The axis it was built around.
    pub axis: DVec3,
}

impl Cone {
    /// The regular spherical quadrilateral about unit `axis` covering `share` of the sphere
    /// (`0 < share < ½`), turned by `twist` radians about the axis.
    pub fn square(axis: DVec3, share: f64, twist: f64) -> Cone {
        let axis = axis.normalize();
        let (right, up) = basis(axis);
        let corners_at = |beta: f64| {
            let mut c = [DVec3::ZERO; 4];
            for (k, ck) in c.iter_mut().enumerate() {
                let phi = twist + FRAC_PI_4 + k as f64 * FRAC_PI_2;
                *ck = (axis * beta.cos() + (right * phi.cos() + up * phi.sin()) * beta.sin())
                    .normalize();
            }
            c
        };
        let target = share.clamp(1e-9, 0.5 - 1e-9) * 4.0 * PI;
        let (mut lo, mut hi) = (0.0, FRAC_PI_2);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if spherical_polygon_area(&corners_at(mid)) < target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Cone {
            corners: corners_at(0.5 * (lo + hi)),
            axis,
        }
    }

    /// Exact solid angle, sr.
    pub fn solid_angle(&self) -> f64 {
        spherical_polygon_area(&self.corners)
    }

    /// The angle from the axis to a corner, radians.
    pub fn corner_radius(&self) -> f64 {
        self.axis.dot(self.corners[0]).clamp(-1.0, 1.0).acos()
    }

    /// Whether unit direction `d` is inside (or on the boundary).
    pub fn contains(&self, d: DVec3) -> bool {
        let s = self
            .axis
            .dot(self.corners[0].cross(self.corners[1]))
            .signum();
        (0..4).all(|i| s * d.dot(self.corners[i].cross(self.corners[(i + 1) % 4])) >= 0.0)
    }

    /// Points along edge `i` (corner `i` to corner `i+1`), `n + 1` of them, by slerp.
    pub fn edge_points(&self, i: usize, n: usize) -> Vec<DVec3> {
        let (a, b) = (self.corners[i], self.corners[(i + 1) % 4]);
        let omega = a.angle_between(b);
        let s = omega.sin();
        (0..=n)
            .map(|k| {
                let t = k as f64 / n as f64;
                (a * ((1.0 - t) * omega).sin() / s + b * (t * omega).sin() / s).normalize()
            })
            .collect()
    }
}

/// Greene's figure 2 set-up: a cone covering 3/8 of the world, its axis 25° above the
/// horizon and 5° to the right of straight ahead (−Z), turned 30° about itself. Like his,
/// it falls on five cube faces and in one piece on the Mercator (whose upper part it
/// fills).
pub fn greene_cone() -> Cone {
    let el = 25f64.to_radians();
    let az = 5f64.to_radians();
    let axis = DVec3::new(az.sin() * el.cos(), el.sin(), -az.cos() * el.cos());
    Cone::square(axis, 3.0 / 8.0, 30f64.to_radians())
}

/// Texel classes in a [`ConeRegion`] mask.
pub mod class {
    /// Outside the covered domain.
    pub const UNUSED: u8 = 0;
    /// Covered, outside the cone.
    pub const OUTSIDE: u8 = 1;
    /// Inside the cone.
    pub const INSIDE: u8 = 2;
    /// On a mapped edge of the cone.
    pub const EDGE: u8 = 3;
}

/// The cone on one projection.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ConeRegion {
    /// Projection name.
    pub projection: String,
    /// Edge size.
    pub size: u32,
    /// Connected pieces (summed over layers).
    pub pieces: usize,
    /// Layers the cone touches.
    pub layers_touched: usize,
    /// Texels whose centre is inside.
    pub texels: u64,
    /// Their summed exact solid angle, sr.
    pub solid_angle: f64,
    /// The cone's exact solid angle, sr.
    pub exact_solid_angle: f64,
    /// The part of the cone the projection covers at all (Mercator stops short of the pole),
    /// estimated from edge samples: `true` if every edge sample maps.
    pub fully_covered: bool,
    /// Largest distance of a mapped edge piece from its chord, texels (0 = straight edges,
    /// a polygonal region).
    pub max_edge_bend_texels: f64,
    /// Per-layer texel classes (see [`class`]), row-major, top row first.
    #[serde(skip)]
    pub mask: Vec<Vec<u8>>,
    /// Layer width.
    pub width: u32,
    /// Layer height.
    pub height: u32,
}

fn count_pieces(mask: &[u8], w: usize, h: usize) -> usize {
    let mut seen = vec![false; mask.len()];
    let mut pieces = 0;
    let mut stack = Vec::new();
    for start in 0..mask.len() {
        if seen[start] || mask[start] < class::INSIDE {
            continue;
        }
        pieces += 1;
        seen[start] = true;
        stack.push(start);
        while let Some(i) = stack.pop() {
            let (x, y) = (i % w, i / w);
            let mut visit = |j: usize| {
                if !seen[j] && mask[j] >= class::INSIDE {
                    seen[j] = true;
                    stack.push(j);
                }
            };
            if x > 0 {
                visit(i - 1);
            }
            if x + 1 < w {
                visit(i + 1);
            }
            if y > 0 {
                visit(i - w);
            }
            if y + 1 < h {
                visit(i + w);
            }
        }
    }
    pieces
}

/// Largest distance (in texels) of `pts` from the chord through its ends.
fn bend(pts: &[DVec2]) -> f64 {
    if pts.len() < 3 {
        return 0.0;
    }
    let (a, b) = (pts[0], pts[pts.len() - 1]);
    let e = b - a;
    let len = e.length();
    if len < 1e-12 {
        return pts.iter().map(|p| (*p - a).length()).fold(0.0, f64::max);
    }
    pts.iter()
        .map(|p| (e.perp_dot(*p - a) / len).abs())
        .fold(0.0, f64::max)
}

/// Classifies the texels of `p` (edge `size`) against `cone` and measures the pieces.
///
/// ```
/// use mirrorball_analysis::cone::{cone_region, Cone};
/// use mirrorball_core::ProjectionKind;
/// use glam::DVec3;
/// // A cone straight ahead covering a sixth of the sphere lands in one piece on a
/// // lat-long map, and its texels add up to its solid angle.
/// let cone = Cone::square(DVec3::NEG_Z, 1.0 / 6.0, 0.0);
/// let r = cone_region(&ProjectionKind::LatLong.default_projection(), 256, &cone);
/// assert_eq!((r.pieces, r.layers_touched), (1, 1));
/// assert!((r.solid_angle / cone.solid_angle() - 1.0).abs() < 1e-3);
/// ```
pub fn cone_region(p: &Projection, size: u32, cone: &Cone) -> ConeRegion {
    let (w, h) = p.layer_extent(size);
    let n = p.layer_count();
    let mut mask = vec![vec![class::UNUSED; (w * h) as usize]; n];
    let mut texels = 0;
    let mut solid_angle = 0.0;
    for (l, m) in mask.iter_mut().enumerate() {
        let rows = m.par_chunks_mut(w as usize).enumerate().map(|(y, row)| {
            let y = y as u32;
            let (mut t, mut s) = (0u64, 0.0);
            for (x, c) in row.iter_mut().enumerate() {
                let x = x as u32;
                let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                if let Some(d) = p.uv_to_dir(l, uv) {
                    if cone.contains(d) {
                        *c = class::INSIDE;
                        t += 1;
                        s += p.texel_solid_angle(l, x, y, w, h);
                    } else {
                        *c = class::OUTSIDE;
                    }
                }
            }
            (t, s)
        });
        let (t, s) = fold_in_order(rows, (0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
        texels += t;
        solid_angle += s;
    }
    let pieces: usize = mask
        .iter()
        .map(|m| count_pieces(m, w as usize, h as usize))
        .sum();
    let layers_touched = mask.iter().filter(|m| m.contains(&class::INSIDE)).count();
    // Edges: sample, map, cut into pieces, measure the bend, and mark the texels they cross.
    let scale = DVec2::new(w as f64, h as f64);
    let mut max_bend: f64 = 0.0;
    let mut fully_covered = true;
    for e in 0..4 {
        let mut piece: Vec<DVec2> = Vec::new();
        let mut piece_layer = usize::MAX;
        for d in cone.edge_points(e, 2000) {
            match p.dir_to_uv(d) {
                Some((l, uv)) => {
                    let px = uv * scale;
                    let jump = piece
                        .last()
                        .is_some_and(|q| (*q - px).length() > 0.25 * scale.x.min(scale.y));
                    if l != piece_layer || jump {
                        max_bend = max_bend.max(bend(&piece));
                        piece.clear();
                        piece_layer = l;
                    }
                    piece.push(px);
                    let (x, y) = (
                        (px.x.floor() as i64).clamp(0, w as i64 - 1),
                        (px.y.floor() as i64).clamp(0, h as i64 - 1),
                    );
                    mask[l][(y as u32 * w + x as u32) as usize] = class::EDGE;
                }
                None => {
                    fully_covered = false;
                    max_bend = max_bend.max(bend(&piece));
                    piece.clear();
                    piece_layer = usize::MAX;
                }
            }
        }
        max_bend = max_bend.max(bend(&piece));
    }
    ConeRegion {
        projection: p.name().to_string(),
        size,
        pieces,
        layers_touched,
        texels,
        solid_angle,
        exact_solid_angle: cone.solid_angle(),
        fully_covered,
        max_edge_bend_texels: max_bend,
        mask,
        width: w,
        height: h,
    }
}
