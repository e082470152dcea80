//! Shading one sample: the mode's reflected direction, then the material (mirror,
//! Fresnel, cheap chrome, diffuse, Greene's prefiltered maps, Phong sphere maps).
//!
//! Reflection: for a unit view vector `v` (from the eye towards the surface) and unit
//! normal `n`, `r = v − 2(n·v)n` (the mirror direction, pointing away from the surface,
//! towards what is seen in it). Environment directions point *towards* what is seen, so `r`
//! is looked up as it is.

use super::prepare::{Prepared, Shaded};
use super::texgen::Texgen;
use crate::raster::NO_HIT;
use crate::scene::{Indexing, Material};
use glam::Vec3;

/// Per-vertex data interpolated at a sample: the triangle's vertices and the sample's
/// perspective-correct weights.
pub(super) struct Lerp {
    i: [usize; 3],
    b: Vec3,
}

impl Lerp {
    #[inline(always)]
    fn new(t: [u32; 3], b: Vec3) -> Lerp {
        Lerp {
            i: t.map(|i| i as usize),
            b,
        }
    }

    /// `a` at the sample: `a₀·b.x + a₁·b.y + a₂·b.z`.
    #[inline(always)]
    pub(super) fn of(&self, a: &[Vec3]) -> Vec3 {
        let [i0, i1, i2] = self.i;
        a[i0] * self.b.x + a[i1] * self.b.y + a[i2] * self.b.z
    }
}

impl Prepared<'_> {
    /// Shades one sample.
    pub(super) fn shade(&self, sx: u32, sy: u32, s: crate::raster::Sample) -> Shaded {
        let (fx, fy) = (sx as f32 + 0.5, sy as f32 + 0.5);
        if s.tri == NO_HIT {
            return self.background(fx, fy);
        }
        let at = Lerp::new(self.tris[s.tri as usize], s.weights());
        let lerp3 = |a: &[Vec3]| at.of(a);
        let q = lerp3(&self.pos);
        let n = lerp3(&self.nrm).normalize_or_zero();
        let v = if self.cam.is_perspective() {
            (q - self.cam.eye).normalize_or_zero()
        } else {
            self.forward
        };
        let r_pixel = v - 2.0 * n.dot(v) * n;
        let material = &self.materials[self.tri_mat[s.tri as usize] as usize];
        let pe = self.view_rot * (q - self.cam.eye);
        let mut out = Shaded {
            covered: true,
            n,
            eye_depth: -pe.z,
            win_depth: s.depth * 0.5 + 0.5,
            st: [0.0, 0.0, -1.0],
            ..Default::default()
        };
        let mode = self.settings.indexing;
        // The reflected direction this mode uses (world space).
        let r = match mode {
            Indexing::PerVertexTexgen => lerp3(&self.r_gl).normalize_or_zero(),
            Indexing::PerVertexReflection => lerp3(&self.r_vert).normalize_or_zero(),
            Indexing::PerPixel | Indexing::Cone => r_pixel,
        };
        out.r = r;
        let env_color = |out: &mut Shaded| self.env_color(s, fx, fy, r, &at, out);
        out.color = match material {
            Material::Mirror { tint } => {
                let e = env_color(&mut out);
                [0, 1, 2].map(|c| e[c] * tint[c])
            }
            Material::Fresnel { f0, base } => {
                let e = env_color(&mut out);
                let cos = (-n.dot(v)).clamp(0.0, 1.0);
                let f = f0 + (1.0 - f0) * (1.0 - cos).powi(5);
                [0, 1, 2].map(|c| f * e[c] + (1.0 - f) * base[c])
            }
            Material::CheapChrome { ramp } => ramp.at((r.y + 1.0) * 0.5),
            Material::Diffuse {
                colour,
                light,
                ambient,
            } => {
                let l = Vec3::from_array(*light).normalize_or_zero();
                let k = ambient + n.dot(l).max(0.0);
                colour.map(|c| c * k)
            }
            Material::Greene { .. } | Material::PhongMap { .. } => {
                self.shade_maps(material, s, n, r, &mut out)
            }
        };
        out
    }

    /// The environment's colour for a mirror-like material at sample `s` along the mode's
    /// reflected direction `r` (world space), recording what it read in `out.st`.
    #[inline(always)]
    fn env_color(
        &self,
        s: crate::raster::Sample,
        fx: f32,
        fy: f32,
        r: Vec3,
        at: &Lerp,
        out: &mut Shaded,
    ) -> [f32; 3] {
        match self.settings.indexing {
            Indexing::PerVertexTexgen => self.texgen_read(s, fx, fy, at, out),
            Indexing::Cone => self.cone_color(s, fx, fy, r, out),
            _ if self.sampler.is_some() => {
                // Modes 2 and 3 with a footprint filter: the reflected rays at the pixel's
                // corners give the footprint.
                let d = self.attach(r);
                let (_, st) = self.read_dir(d);
                out.st = st;
                self.footprint_read(s, fx, fy, d)
            }
            _ => {
                let (c, st) = self.read_dir32(self.attach32(r));
                out.st = st;
                c
            }
        }
    }

    /// Greene's and the Phong-map materials (out of line: the mirror path stays small).
    #[inline(never)]
    fn shade_maps(
        &self,
        material: &Material,
        s: crate::raster::Sample,
        n: Vec3,
        r: Vec3,
        out: &mut Shaded,
    ) -> [f32; 3] {
        let at = Lerp::new(self.tris[s.tri as usize], s.weights());
        let lerp3 = |a: &[Vec3]| at.of(a);
        let mode = self.settings.indexing;
        let k = self.tri_mat[s.tri as usize] as usize;
        match (material, &self.extra[k]) {
            (Material::Greene { dc, sc, .. }, crate::shading::MaterialMaps::Greene(maps)) => {
                let uv = match (mode, self.texgen_kind) {
                    (Indexing::PerVertexTexgen, Texgen::SphereSt | Texgen::Uv) => {
                        Some(lerp3(&self.texgen))
                    }
                    _ => None,
                };
                let k = self.scene.environment.as_ref().map_or(1.0, |e| e.intensity);
                let (c, st) = crate::shading::greene(
                    maps,
                    [*dc, *sc],
                    self.attach32(n),
                    self.attach32(r),
                    uv,
                );
                out.st = st;
                c.map(|x| x * k)
            }
            (
                Material::PhongMap {
                    colour,
                    light,
                    ambient,
                    ..
                },
                crate::shading::MaterialMaps::Phong(map),
            ) => {
                let st = (mode == Indexing::PerVertexTexgen).then(|| lerp3(&self.texgen_eye));
                let l = Vec3::from_array(*light).normalize_or_zero();
                let diffuse = ambient + (self.view_rot * n).dot(l).max(0.0);
                let (h, uv) = crate::shading::phong_highlight(map, self.view_rot * r, st);
                out.st = [uv[0], uv[1], 0.0];
                [0, 1, 2].map(|c| colour[c] * diffuse + h[c])
            }
            _ => [0.0; 3],
        }
    }
}
