//! Mode 4, Greene's reflection cones (Greene 1986, §5–6): the rays through a pixel's four
//! corners, reflected off the surface, bound a region of the world projection; that region
//! is filtered rather than point-sampled, so a highly curved surface (where a pixel's
//! reflected rays fan out over much of the sphere) does not alias. The background is filtered
//! the same way over the pixel's primary-ray footprint.
//!
//! The corner rays are found on the hit triangle's plane extended to the pixel's corners,
//! with the normal interpolated there (the triangle's barycentric coordinates
//! extrapolated). Their spread is the pixel's footprint as ray differentials,
//! `∂d/∂x = ½((c₁ − c₀) + (c₂ − c₃))` and `∂d/∂y = ½((c₃ − c₀) + (c₂ − c₁))` for corners in
//! pixel order `(−,−) (+,−) (+,+) (−,+)` ([`crate::lookup::footprint`]), and the region is
//! filtered by `mirrorball_filter::Sampler` over the filter crate's solid-angle-weighted mip
//! pyramid, built once per environment ([`crate::EnvCache`]): Heckbert's EWA by default,
//! or trilinear when the environment's filter is [`crate::Filter::Trilinear`]. The footprint
//! is carried to texture space through the projection's Jacobian, so the same cone filters
//! the same piece of sphere whatever the projection.
//!
//! Modes 1–3 with a footprint filter read through the same cone.

use super::prepare::{Prepared, Shaded};
use glam::{DVec3, Vec3};

impl Prepared<'_> {
    /// Mode 4's environment colour at sample `s` along `r` (world space), recording what
    /// its centre reads in `out.st`.
    #[inline]
    pub(super) fn cone_color(
        &self,
        s: crate::raster::Sample,
        fx: f32,
        fy: f32,
        r: Vec3,
        out: &mut Shaded,
    ) -> [f32; 3] {
        let corners = self.corner_reflections(s, fx, fy);
        let d = self.attach(r);
        let (_, st) = self.read_dir(d);
        out.st = st;
        let dirs = corners.map(|c| self.attach(c));
        self.cone_read(d, &dirs)
    }

    /// The environment filtered over the footprint of the reflected rays through the
    /// corners of sample `s`'s pixel, about the attached direction `d`.
    #[inline(never)]
    pub(super) fn footprint_read(
        &self,
        s: crate::raster::Sample,
        fx: f32,
        fy: f32,
        d: DVec3,
    ) -> [f32; 3] {
        let corners = self.corner_reflections(s, fx, fy);
        let dirs = corners.map(|c| self.attach(c));
        self.cone_read(d, &dirs)
    }

    /// Greene's pixel cone: the reflected directions at the four corners of the sample's
    /// footprint, from the hit triangle's plane extended to the corners (its barycentric
    /// coordinates extrapolated) with the normal interpolated there.
    pub(super) fn corner_reflections(
        &self,
        s: crate::raster::Sample,
        fx: f32,
        fy: f32,
    ) -> [Vec3; 4] {
        let t = self.tris[s.tri as usize];
        let [a, b, c] = t.map(|i| self.pos[i as usize]);
        let [na, nb, nc] = t.map(|i| self.nrm[i as usize]);
        let plane_n = (b - a).cross(c - a);
        let h = 0.5;
        [(-h, -h), (h, -h), (h, h), (-h, h)].map(|(dx, dy)| {
            let (x, y) = self.ndc(fx + dx, fy + dy);
            let (o, d) = self.rays.ray(x, y);
            let denom = plane_n.dot(d);
            if denom.abs() < 1e-12 {
                // Edge-on: fall back to the sample's own direction.
                let n = (na * (1.0 - s.b1 - s.b2) + nb * s.b1 + nc * s.b2).normalize_or_zero();
                return d - 2.0 * n.dot(d) * n;
            }
            let tt = plane_n.dot(a - o) / denom;
            let p = o + d * tt;
            let w = barycentric(a, b, c, p);
            let n = (na * w.x + nb * w.y + nc * w.z).normalize_or_zero();
            d - 2.0 * n.dot(d) * n
        })
    }

    /// Filters the environment over the footprint of the corner directions `dirs` around
    /// `d` with the footprint sampler (trilinear or EWA; see [`crate::lookup`]).
    pub(super) fn cone_read(&self, d: DVec3, dirs: &[DVec3; 4]) -> [f32; 3] {
        let (Some(sampler), Some(env)) = (&self.sampler, self.scene.environment.as_ref()) else {
            return self.read_dir(d).0;
        };
        let v = sampler.sample(d, &crate::lookup::footprint(dirs));
        [v[0], v[1], v[2]].map(|c| c * env.intensity)
    }
}

/// Barycentric coordinates of `p` (in the plane of `abc`).
fn barycentric(a: Vec3, b: Vec3, c: Vec3, p: Vec3) -> Vec3 {
    let (v0, v1, v2) = (b - a, c - a, p - a);
    let d00 = v0.dot(v0);
    let d01 = v0.dot(v1);
    let d11 = v1.dot(v1);
    let d20 = v2.dot(v0);
    let d21 = v2.dot(v1);
    let den = d00 * d11 - d01 * d01;
    if den.abs() < 1e-30 {
        return Vec3::new(1.0, 0.0, 0.0);
    }
    let v = (d11 * d20 - d01 * d21) / den;
    let w = (d00 * d21 - d01 * d20) / den;
    Vec3::new(1.0 - v - w, v, w)
}
