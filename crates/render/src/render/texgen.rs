//! Mode 1, fixed-function texture generation: per vertex, `GL_SPHERE_MAP`'s `(s, t)`, a
//! single-layer map's own `(u, v)`, or `GL_REFLECTION_MAP`'s direction (its face chosen per
//! pixel), interpolated across the triangle as the hardware did, chords and bow ties
//! included.

use super::prepare::{Prepared, Shaded};
use super::shade::Lerp;
use crate::scene::Attach;
use glam::{DVec2, DVec3, Mat4, Vec3};
use mirrorball_core::{Projection, SphereMap, WorldProjection};
use rayon::prelude::*;

/// What mode 1 generates per vertex for the environment's projection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Texgen {
    /// `GL_SPHERE_MAP`: `(s, 1 − t)` of the sphere-map texture.
    SphereSt,
    /// `GL_REFLECTION_MAP`: the direction, face chosen per pixel.
    Vector,
    /// A single-layer map's own `(u, v)`.
    Uv,
}

impl Texgen {
    /// What mode 1 generates for an environment in `proj`.
    pub(super) fn of(proj: Option<&Projection>) -> Texgen {
        match proj {
            Some(Projection::Sphere(_)) => Texgen::SphereSt,
            Some(p) if p.layer_count() == 1 => Texgen::Uv,
            _ => Texgen::Vector,
        }
    }
}

/// Per vertex (world positions `pos`, unit normals `nrm`, seen through `view`): the
/// texgen output (`(u, v)` in `.xy`, or a direction) and the GL reflection vector in world
/// space (for materials).
pub(super) fn per_vertex(
    pos: &[Vec3],
    nrm: &[Vec3],
    view: &Mat4,
    texgen_kind: Texgen,
    proj: Option<Projection>,
    attach: Attach,
) -> (Vec<Vec3>, Vec<Vec3>) {
    let view_rot = glam::Mat3::from_mat4(*view);
    let inv_rot = view_rot.transpose();
    let out: Vec<(Vec3, Vec3)> = pos
        .par_iter()
        .zip(nrm.par_iter())
        .map(|(&q, &n)| {
            // Eye space, exactly as the fixed-function pipeline: u = normalize(P_eye).
            let pe = view.transform_point3(q);
            let u = pe.normalize_or_zero();
            let ne = (view_rot * n).normalize_or_zero();
            let r_eye = u - 2.0 * ne.dot(u) * ne;
            let r_world = inv_rot * r_eye;
            let d = match attach {
                Attach::Eye => r_eye,
                Attach::World => r_world,
            };
            let g = match (texgen_kind, proj) {
                (Texgen::SphereSt, Some(Projection::Sphere(sm))) => {
                    let f = sm.eye();
                    let dd = d.as_dvec3();
                    let local = DVec3::new(f.right.dot(dd), f.up.dot(dd), -f.forward.dot(dd));
                    let st = SphereMap::gl_st(local);
                    Vec3::new(st.x as f32, (1.0 - st.y) as f32, 0.0)
                }
                (Texgen::Uv, Some(p)) => match p.dir_to_uv(d.as_dvec3().normalize()) {
                    Some((_, uv)) => Vec3::new(uv.x as f32, uv.y as f32, 0.0),
                    None => Vec3::NAN,
                },
                _ => d,
            };
            (g, r_world)
        })
        .collect();
    out.into_iter().unzip()
}

impl Prepared<'_> {
    /// Mode 1's environment colour at sample `s` (pixel centre `fx`, `fy`; `at`
    /// interpolates per-vertex data), recording what it read in `out.st`.
    #[inline]
    pub(super) fn texgen_read(
        &self,
        s: crate::raster::Sample,
        fx: f32,
        fy: f32,
        at: &Lerp,
        out: &mut Shaded,
    ) -> [f32; 3] {
        match self.texgen_kind {
            Texgen::SphereSt | Texgen::Uv => {
                let g = at.of(&self.texgen);
                let uv = DVec2::new(g.x as f64, g.y as f64);
                out.st = [g.x, g.y, 0.0];
                match self.uv_dir(uv) {
                    // A footprint filter: the texgen's direction, with the footprint of the
                    // pixel's reflected corner rays.
                    Some(d) if self.sampler.is_some() => self.footprint_read(s, fx, fy, d),
                    _ => self.read_uv(0, uv),
                }
            }
            Texgen::Vector => {
                let d: DVec3 = at.of(&self.texgen).as_dvec3().normalize_or_zero();
                let (c, st) = self.read_dir(d);
                out.st = st;
                if self.sampler.is_some() {
                    self.footprint_read(s, fx, fy, d)
                } else {
                    c
                }
            }
        }
    }
}
