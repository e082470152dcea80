//! Per-vertex indexing studies: how far a reflected vector (or texture coordinate) computed
//! at the vertices and interpolated across a primitive strays from the one computed exactly
//! at every point.
//!
//! This is the arithmetic of a rasteriser without the raster, so that a future renderer can
//! reuse or replace it. Conventions:
//!
//! * **Reflection.** `r = i − 2(i·n)n`, with `i` the unit direction from the eye to the
//!   surface point and `n` the unit normal (OpenGL's `reflect`; the same `r` as Zimmons'
//!   `R = 2(N·U)N − U` with `U = −i`).
//! * **Exact (per pixel).** At a point `P` of a primitive, `i = normalize(P − E)` and
//!   `n = normalize(Σ bⱼ nⱼ)`, the normal interpolated with the point's barycentric
//!   coordinates `bⱼ` (per-pixel "Phong" reflection, what a fragment shader computes). On a
//!   flat mirror all `nⱼ` agree and this is the true mirror direction.
//! * **Per vertex.** `rⱼ` is computed exactly at each vertex and the point gets
//!   `Σ bⱼ rⱼ`. Interpolation is in object space (`bⱼ` are the point's barycentric
//!   coordinates on the primitive), i.e. *perspective-correct*, as OpenGL requires of
//!   varyings; affine screen-space interpolation would add its own error on top.
//! * **Two ways to use it.** *Vector* indexing interpolates `rⱼ` and looks the interpolated
//!   vector up per pixel (cube-map hardware, `GL_REFLECTION_MAP`; Heidrich & Seidel's
//!   paraboloid texgen, whose projective texture coordinates `(d + r)` interpolate to the
//!   same thing). *Texgen* indexing computes texture coordinates `uvⱼ = dir_to_uv(rⱼ)` at the
//!   vertices and interpolates those (`GL_SPHERE_MAP`, whose map is taken in the current
//!   camera's eye space). The angle error of vector indexing does not depend on the map; the
//!   texel error of either does.
//! * **Texel error** is the distance between the interpolated and the exact texture
//!   coordinates in texels of the map's layer (`|Δu·w, Δv·h|`), counted only where both land
//!   on the same layer (a sample whose two lookups fall on different cube faces is counted
//!   separately).
//!
//! Three set-ups:
//!
//! 1. [`LineStudy`]: Zimmons' figures 34–36 exactly as his text states them: a flat mirror
//!    along the x axis from −10 to +10 (normal +y), the viewer one unit above it at
//!    `(x_e, 1, 0)`, reflected vectors computed at the two ends and interpolated linearly
//!    (optionally with the line cut into more segments).
//! 2. [`QuadStudy`]: the two-dimensional version, a square mirror `[−10, 10]²` in the plane
//!    `y = 0` cut into `n×n` cells of two triangles, the viewer at height `h` moving along x.
//! 3. [`SphereStudy`]: a UV sphere of radius 1 (`stacks × slices`, vertex normals = the true
//!    normals), the viewer at distance `D` from its centre moving from the equator to the
//!    pole, looking at the centre.

use crate::geom::{angle_between, reflect};
use glam::{DVec2, DVec3};
use mirrorball_core::{Frame, Projection, SphereMap, WorldProjection};
use rayon::prelude::*;
use serde::Serialize;

/// The worst error found and where.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Worst {
    /// Angle between the interpolated and the exact reflected vector, degrees.
    pub degrees: f64,
    /// Where (x along the line; for the quad `x`, `z`; for the sphere latitude, longitude in
    /// degrees).
    pub at: [f64; 2],
    /// Angle between the view ray and the normal there, degrees (90 = grazing).
    pub incidence_deg: f64,
}

/// Zimmons' line set-up.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LineStudy {
    /// Left end of the mirror.
    pub x0: f64,
    /// Right end.
    pub x1: f64,
    /// The viewer's height above it.
    pub height: f64,
    /// Equal segments the line is cut into (Zimmons: 1).
    pub segments: u32,
}

impl LineStudy {
    /// Zimmons' set-up: −10 to +10, viewer one unit above, one segment.
    pub const ZIMMONS: LineStudy = LineStudy {
        x0: -10.0,
        x1: 10.0,
        height: 1.0,
        segments: 1,
    };

    fn exact(&self, viewer_x: f64, x: f64) -> DVec3 {
        let e = DVec3::new(viewer_x, self.height, 0.0);
        reflect((DVec3::new(x, 0.0, 0.0) - e).normalize(), DVec3::Y)
    }

    /// The angle error (degrees) at `x` for a viewer at `viewer_x`.
    pub fn error_at(&self, viewer_x: f64, x: f64) -> f64 {
        let len = (self.x1 - self.x0) / self.segments as f64;
        let k = (((x - self.x0) / len).floor() as i64).clamp(0, self.segments as i64 - 1);
        let a = self.x0 + k as f64 * len;
        let t = (x - a) / len;
        let ri = self.exact(viewer_x, a) * (1.0 - t) + self.exact(viewer_x, a + len) * t;
        angle_between(ri, self.exact(viewer_x, x)).to_degrees()
    }

    /// `(x, error°)` at `n + 1` evenly spaced points.
    pub fn errors(&self, viewer_x: f64, n: usize) -> Vec<[f64; 2]> {
        (0..=n)
            .map(|i| {
                let x = self.x0 + (self.x1 - self.x0) * i as f64 / n as f64;
                [x, self.error_at(viewer_x, x)]
            })
            .collect()
    }

    /// The worst error for a viewer at `viewer_x`: a dense scan refined by golden-section
    /// search around the best sample.
    pub fn worst(&self, viewer_x: f64) -> Worst {
        let n = 4000;
        let pts = self.errors(viewer_x, n);
        let (mut bi, mut be) = (0, -1.0);
        for (i, p) in pts.iter().enumerate() {
            if p[1] > be {
                (bi, be) = (i, p[1]);
            }
        }
        let step = (self.x1 - self.x0) / n as f64;
        let (mut lo, mut hi) = (
            (pts[bi][0] - step).max(self.x0),
            (pts[bi][0] + step).min(self.x1),
        );
        let g = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..80 {
            let (m1, m2) = (hi - g * (hi - lo), lo + g * (hi - lo));
            if self.error_at(viewer_x, m1) < self.error_at(viewer_x, m2) {
                lo = m1;
            } else {
                hi = m2;
            }
        }
        let x = 0.5 * (lo + hi);
        let e = self.error_at(viewer_x, x).max(be);
        let e_pos = DVec3::new(viewer_x, self.height, 0.0);
        let inc = angle_between(e_pos - DVec3::new(x, 0.0, 0.0), DVec3::Y).to_degrees();
        Worst {
            degrees: e,
            at: [x, 0.0],
            incidence_deg: inc,
        }
    }

    /// The worst error for each viewer position.
    pub fn sweep(&self, viewers: &[f64]) -> Vec<(f64, Worst)> {
        viewers.par_iter().map(|&v| (v, self.worst(v))).collect()
    }
}

/// A triangle with per-vertex positions and unit normals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// Vertex positions.
    pub p: [DVec3; 3],
    /// Unit vertex normals.
    pub n: [DVec3; 3],
}

/// Which per-vertex quantity a study interpolates across a triangle: the renderer's
/// modes 2 (`PerVertexReflection`) and 1 (`PerVertexTexgen`) of its `Indexing`, measured
/// exactly and without rendering. Its other two modes (per pixel, Greene's cones)
/// interpolate nothing a study could measure, so this is its own type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum VertexIndexing {
    /// Interpolate the reflected vector, look it up per pixel.
    Vector,
    /// Interpolate per-vertex texture coordinates (`GL_SPHERE_MAP`-style texgen).
    Texgen,
}

/// A map to measure texture-coordinate error on, and how it is indexed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapSpec {
    /// The projection (for [`VertexIndexing::Texgen`] on a sphere map, its frame is replaced by the
    /// camera's for every viewer: `GL_SPHERE_MAP` works in eye space).
    pub projection: Projection,
    /// Layer edge size, texels.
    pub size: u32,
    /// How it is indexed.
    pub indexing: VertexIndexing,
}

/// Texture-coordinate error on one map.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct MapError {
    /// Projection name.
    pub projection: String,
    /// `Vector` or `Texgen`.
    pub indexing: String,
    /// Edge size.
    pub size: u32,
    /// Largest texel error.
    pub max_texels: f64,
    /// Mean texel error over the samples measured.
    pub mean_texels: f64,
    /// Largest angle between the direction actually looked up and the exact one, degrees
    /// (for vector indexing this is the vector's own error).
    pub max_degrees: f64,
    /// Samples whose two lookups landed on different layers (or across a seam): not in the
    /// texel statistics.
    pub seam_samples: u64,
    /// Samples measured.
    pub samples: u64,
}

#[derive(Clone, Debug, Default)]
struct MapAcc {
    max_texels: f64,
    sum_texels: f64,
    n: u64,
    max_deg: f64,
    seam: u64,
}

/// Texel distance between two texture coordinates on a `w×h` layer; the u coordinate wraps
/// for the cylindrical maps (whose seam is a wrap, not an edge).
fn texel_distance(p: &Projection, a: DVec2, b: DVec2, w: u32, h: u32) -> f64 {
    let mut du = (a.x - b.x).abs();
    if matches!(p, Projection::LatLong(_) | Projection::Mercator(_)) {
        du = du.min(1.0 - du);
    }
    DVec2::new(du * w as f64, (a.y - b.y) * h as f64).length()
}

/// Measures one sample on one map.
#[allow(clippy::too_many_arguments)]
fn measure(
    acc: &mut MapAcc,
    spec: &MapSpec,
    proj: &Projection,
    exact: DVec3,
    interp: DVec3,
    vertex_r: &[DVec3; 3],
    b: [f64; 3],
) {
    let (w, h) = proj.layer_extent(spec.size);
    let Some((le, uve)) = proj.dir_to_uv(exact) else {
        return;
    };
    match spec.indexing {
        VertexIndexing::Vector => {
            let Some((li, uvi)) = proj.dir_to_uv(interp) else {
                return;
            };
            acc.max_deg = acc.max_deg.max(angle_between(interp, exact).to_degrees());
            if li != le {
                acc.seam += 1;
                return;
            }
            let t = texel_distance(proj, uvi, uve, w, h);
            acc.max_texels = acc.max_texels.max(t);
            acc.sum_texels += t;
            acc.n += 1;
        }
        VertexIndexing::Texgen => {
            let mut uv = DVec2::ZERO;
            let mut layer = None;
            let mut first = DVec2::ZERO;
            for (j, r) in vertex_r.iter().enumerate() {
                let Some((l, t)) = proj.dir_to_uv(*r) else {
                    return;
                };
                if j == 0 {
                    first = t;
                }
                // Different layers, or across the wrap of a cylindrical map: a seam.
                let wraps = matches!(proj, Projection::LatLong(_) | Projection::Mercator(_))
                    && (t.x - first.x).abs() > 0.5;
                if layer.is_some_and(|l0| l0 != l) || wraps {
                    acc.seam += 1;
                    return;
                }
                layer = Some(l);
                uv += t * b[j];
            }
            let l = layer.expect("three vertices");
            if l != le {
                acc.seam += 1;
                return;
            }
            if let Some(d) = proj.uv_to_dir(l, uv) {
                acc.max_deg = acc.max_deg.max(angle_between(d, exact).to_degrees());
            }
            let t = texel_distance(proj, uv, uve, w, h);
            acc.max_texels = acc.max_texels.max(t);
            acc.sum_texels += t;
            acc.n += 1;
        }
    }
}

/// One viewer position's results on a mesh.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ViewResult {
    /// The viewer parameter (x for the quad, elevation in degrees for the sphere).
    pub viewer: f64,
    /// The eye position.
    pub eye: [f64; 3],
    /// Worst angle between interpolated and exact reflected vectors.
    pub worst: Worst,
    /// Mean angle error over the visible samples, degrees.
    pub mean_degrees: f64,
    /// Visible samples.
    pub samples: u64,
    /// Texture-coordinate error on each map.
    pub maps: Vec<MapError>,
}

/// Samples every visible triangle of `mesh` seen from `eye` (camera looking at `target`),
/// with `m` subdivisions per edge (`(m+1)(m+2)/2` barycentric points per triangle).
/// `locate` names a point for the report; `worst_by_incidence` collects the largest error
/// per 1° bin of incidence angle.
pub fn study_mesh<L>(
    mesh: &[Triangle],
    eye: DVec3,
    target: DVec3,
    m: u32,
    maps: &[MapSpec],
    locate: L,
    worst_by_incidence: &mut [f64; 90],
) -> ViewResult
where
    L: Fn(DVec3) -> [f64; 2],
{
    let cam = Frame::looking_along(target - eye).unwrap_or_default();
    let projs: Vec<Projection> = maps
        .iter()
        .map(|s| match (s.projection, s.indexing) {
            (Projection::Sphere(_), VertexIndexing::Texgen) => {
                Projection::Sphere(SphereMap::new(cam))
            }
            (p, _) => p,
        })
        .collect();
    let mut accs = vec![MapAcc::default(); maps.len()];
    let mut worst = Worst::default();
    let (mut sum, mut n) = (0.0, 0u64);
    for tri in mesh {
        let face_n = (tri.p[1] - tri.p[0]).cross(tri.p[2] - tri.p[0]);
        let vr: [DVec3; 3] =
            std::array::from_fn(|j| reflect((tri.p[j] - eye).normalize(), tri.n[j]));
        for i in 0..=m {
            for j in 0..=(m - i) {
                let b = [
                    i as f64 / m as f64,
                    j as f64 / m as f64,
                    (m - i - j) as f64 / m as f64,
                ];
                let p = tri.p[0] * b[0] + tri.p[1] * b[1] + tri.p[2] * b[2];
                let view = p - eye;
                if view.dot(face_n) >= 0.0 {
                    continue; // back-facing where the flat triangle is
                }
                let nrm = (tri.n[0] * b[0] + tri.n[1] * b[1] + tri.n[2] * b[2]).normalize();
                let i_dir = view.normalize();
                if i_dir.dot(nrm) >= 0.0 {
                    continue; // the shading normal faces away: not a reflection
                }
                let exact = reflect(i_dir, nrm);
                let interp = vr[0] * b[0] + vr[1] * b[1] + vr[2] * b[2];
                let e = angle_between(interp, exact).to_degrees();
                let inc = angle_between(-i_dir, nrm).to_degrees();
                sum += e;
                n += 1;
                let bin = (inc.floor() as usize).min(89);
                worst_by_incidence[bin] = worst_by_incidence[bin].max(e);
                if e > worst.degrees {
                    worst = Worst {
                        degrees: e,
                        at: locate(p),
                        incidence_deg: inc,
                    };
                }
                for (k, spec) in maps.iter().enumerate() {
                    measure(&mut accs[k], spec, &projs[k], exact, interp, &vr, b);
                }
            }
        }
    }
    ViewResult {
        viewer: 0.0,
        eye: eye.to_array(),
        worst,
        mean_degrees: sum / n.max(1) as f64,
        samples: n,
        maps: maps
            .iter()
            .zip(accs)
            .map(|(s, a)| MapError {
                projection: s.projection.name().to_string(),
                indexing: format!("{:?}", s.indexing),
                size: s.size,
                max_texels: a.max_texels,
                mean_texels: a.sum_texels / a.n.max(1) as f64,
                max_degrees: a.max_deg,
                seam_samples: a.seam,
                samples: a.n,
            })
            .collect(),
    }
}

/// Splits per-viewer results from their incidence bins, merging the bins by maximum.
fn merge(per: Vec<(ViewResult, [f64; 90])>) -> (Vec<ViewResult>, Vec<f64>) {
    let mut bins = vec![0.0; 90];
    let res = per
        .into_iter()
        .map(|(r, b)| {
            for (m, v) in bins.iter_mut().zip(b) {
                *m = f64::max(*m, v);
            }
            r
        })
        .collect();
    (res, bins)
}

/// The square mirror set-up.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct QuadStudy {
    /// Half the mirror's edge (Zimmons' line runs from −10 to 10: 10).
    pub half: f64,
    /// Cells per edge (each two triangles).
    pub cells: u32,
    /// The viewer's height.
    pub height: f64,
    /// Subdivisions per triangle edge for sampling.
    pub samples: u32,
}

impl QuadStudy {
    /// The mirror quad's triangles (normal +Y).
    pub fn mesh(&self) -> Vec<Triangle> {
        let n = self.cells.max(1);
        let step = 2.0 * self.half / n as f64;
        let mut out = Vec::with_capacity((2 * n * n) as usize);
        let pt = |i: u32, j: u32| {
            DVec3::new(
                -self.half + i as f64 * step,
                0.0,
                -self.half + j as f64 * step,
            )
        };
        for i in 0..n {
            for j in 0..n {
                let (a, b, c, d) = (pt(i, j), pt(i + 1, j), pt(i + 1, j + 1), pt(i, j + 1));
                // Counter-clockwise seen from above (+Y): a, d, c and a, c, b.
                out.push(Triangle {
                    p: [a, d, c],
                    n: [DVec3::Y; 3],
                });
                out.push(Triangle {
                    p: [a, c, b],
                    n: [DVec3::Y; 3],
                });
            }
        }
        out
    }

    /// Runs the study for viewers at `(x, height, 0)`, camera looking at the quad's centre.
    /// Returns the per-viewer results and the largest error per 1° incidence bin over all.
    pub fn run(&self, viewers: &[f64], maps: &[MapSpec]) -> (Vec<ViewResult>, Vec<f64>) {
        let mesh = self.mesh();
        let per: Vec<(ViewResult, [f64; 90])> = viewers
            .par_iter()
            .map(|&x| {
                let mut bins = [0.0; 90];
                let eye = DVec3::new(x, self.height, 0.0);
                let mut r = study_mesh(
                    &mesh,
                    eye,
                    DVec3::ZERO,
                    self.samples,
                    maps,
                    |p| [p.x, p.z],
                    &mut bins,
                );
                r.viewer = x;
                (r, bins)
            })
            .collect();
        merge(per)
    }
}

/// The tessellated sphere set-up.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SphereStudy {
    /// Latitude bands.
    pub stacks: u32,
    /// Longitude segments.
    pub slices: u32,
    /// The viewer's distance from the centre (radii).
    pub distance: f64,
    /// The viewer's azimuth, degrees (0: on +Z; a half-slice offset puts it between two
    /// meridians).
    pub azimuth_deg: f64,
    /// Subdivisions per triangle edge for sampling.
    pub samples: u32,
}

impl SphereStudy {
    /// The UV sphere's triangles (vertex normals = positions).
    pub fn mesh(&self) -> Vec<Triangle> {
        let (s, l) = (self.stacks.max(2), self.slices.max(3));
        let v = |i: u32, j: u32| {
            let lat = std::f64::consts::FRAC_PI_2 - std::f64::consts::PI * i as f64 / s as f64;
            let lon = std::f64::consts::TAU * j as f64 / l as f64;
            DVec3::new(lat.cos() * lon.sin(), lat.sin(), lat.cos() * lon.cos())
        };
        let mut out = Vec::new();
        for i in 0..s {
            for j in 0..l {
                let (a, b, c, d) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
                if i > 0 {
                    out.push(Triangle {
                        p: [a, b, d],
                        n: [a, b, d],
                    });
                }
                if i + 1 < s {
                    out.push(Triangle {
                        p: [b, c, d],
                        n: [b, c, d],
                    });
                }
            }
        }
        out
    }

    /// Runs the study for viewers at elevations `elevations_deg`, looking at the centre.
    /// Returns the per-viewer results and the largest error per 1° incidence bin over all.
    pub fn run(&self, elevations_deg: &[f64], maps: &[MapSpec]) -> (Vec<ViewResult>, Vec<f64>) {
        let mesh = self.mesh();
        let az = self.azimuth_deg.to_radians();
        let per: Vec<(ViewResult, [f64; 90])> = elevations_deg
            .par_iter()
            .map(|&el| {
                let mut bins = [0.0; 90];
                let e = el.to_radians();
                let eye =
                    DVec3::new(e.cos() * az.sin(), e.sin(), e.cos() * az.cos()) * self.distance;
                let locate = |p: DVec3| {
                    let q = p.normalize();
                    [q.y.asin().to_degrees(), q.x.atan2(q.z).to_degrees()]
                };
                let mut r = study_mesh(
                    &mesh,
                    eye,
                    DVec3::ZERO,
                    self.samples,
                    maps,
                    locate,
                    &mut bins,
                );
                r.viewer = el;
                (r, bins)
            })
            .collect();
        merge(per)
    }
}
