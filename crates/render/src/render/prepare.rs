//! What a frame's shading needs, prepared once: the objects flattened into world space,
//! the per-vertex data of modes 1 and 2, the environment's samplers and material maps; and
//! the environment reads every mode shares.

use super::texgen::Texgen;
use crate::camera::{Camera, Rays};
use crate::scene::{Attach, Filter, Indexing, Material, Scene, Settings};
use glam::{DVec2, DVec3, Mat3, Vec3};
use mirrorball_core::WorldProjection;

/// Everything the shader needs, prepared once per frame.
pub(super) struct Prepared<'a> {
    pub(super) scene: &'a Scene,
    pub(super) cam: Camera,
    pub(super) settings: Settings,
    /// World → eye rotation.
    pub(super) view_rot: Mat3,
    pub(super) forward: Vec3,
    pub(super) pos: Vec<Vec3>,
    pub(super) nrm: Vec<Vec3>,
    /// Mode 2: per-vertex reflected vector (world), true eye vector.
    pub(super) r_vert: Vec<Vec3>,
    /// Mode 1: per-vertex texgen output (uv in .xy, or a direction).
    pub(super) texgen: Vec<Vec3>,
    /// Mode 1: per-vertex GL reflection vector in world space (for materials).
    pub(super) r_gl: Vec<Vec3>,
    pub(super) texgen_kind: Texgen,
    pub(super) tris: Vec<[u32; 3]>,
    /// Material index per triangle.
    pub(super) tri_mat: Vec<u32>,
    pub(super) materials: Vec<Material>,
    /// Its footprint sampler (trilinear, EWA), from the environment's cache.
    pub(super) sampler: Option<std::sync::Arc<mirrorball_filter::Sampler>>,
    /// Per material: Greene's prefiltered maps, or the Phong-intensity sphere map.
    pub(super) extra: Vec<crate::shading::MaterialMaps>,
    /// Mode 1 with a Phong-map material: per-vertex `GL_SPHERE_MAP` `(s, 1 − t)` in eye space.
    pub(super) texgen_eye: Vec<Vec3>,
    pub(super) rays: Rays,
    /// Rays of the previous frame's camera (motion blur).
    pub(super) prev_rays: Option<Rays>,
    /// Supersample grid size.
    pub(super) sw: u32,
    pub(super) sh: u32,
}

/// What one sample shows.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Shaded {
    pub(super) color: [f32; 3],
    pub(super) covered: bool,
    /// `(u, v, layer)` read.
    pub(super) st: [f32; 3],
    pub(super) r: Vec3,
    pub(super) n: Vec3,
    pub(super) eye_depth: f32,
    pub(super) win_depth: f32,
}

/// Flattens the objects into world space and computes the per-vertex data of modes 1 and 2.
pub(super) fn prepare<'a>(scene: &'a Scene, cam: &Camera, settings: &Settings) -> Prepared<'a> {
    let view = cam.view();
    let view_rot = Mat3::from_mat4(view);
    let (_, _, forward) = cam.basis();
    let (pos, nrm, tris, tri_mat, materials) = flatten(scene);
    let proj = scene.environment.as_ref().map(|e| *e.map.projection());
    let texgen_kind = Texgen::of(proj.as_ref());
    let attach = scene
        .environment
        .as_ref()
        .map_or(Attach::World, |e| e.attach);
    let persp = cam.is_perspective();
    let eye = cam.eye;
    let mode = settings.indexing;
    let (r_vert, texgen, r_gl) = match mode {
        Indexing::PerVertexReflection => (
            super::vertex::reflections(&pos, &nrm, persp.then_some(eye), forward),
            Vec::new(),
            Vec::new(),
        ),
        Indexing::PerVertexTexgen => {
            let (g, r) = super::texgen::per_vertex(&pos, &nrm, &view, texgen_kind, proj, attach);
            (Vec::new(), g, r)
        }
        _ => (Vec::new(), Vec::new(), Vec::new()),
    };
    let filter = scene.environment.as_ref().map_or(Filter::Bilinear, |e| {
        crate::lookup::effective(e.filter, mode)
    });
    let sampler = match scene.environment.as_ref() {
        Some(e) if filter.uses_footprint() => Some(e.cache.sampler(&e.map, filter)),
        _ => None,
    };
    let extra: Vec<crate::shading::MaterialMaps> = materials
        .iter()
        .map(|m| crate::shading::MaterialMaps::new(m, scene.environment.as_ref()))
        .collect();
    let texgen_eye = if mode == Indexing::PerVertexTexgen
        && materials
            .iter()
            .any(|m| matches!(m, Material::PhongMap { .. }))
    {
        crate::shading::eye_sphere_texgen(&pos, &nrm, &view)
    } else {
        Vec::new()
    };
    let ss = settings.supersample;
    Prepared {
        scene,
        cam: *cam,
        settings: *settings,
        view_rot,
        forward,
        pos,
        nrm,
        r_vert,
        texgen,
        r_gl,
        texgen_kind,
        tris,
        tri_mat,
        materials,
        sampler,
        extra,
        texgen_eye,
        rays: cam.rays(),
        prev_rays: settings.motion_from.map(|c| c.rays()),
        sw: cam.width * ss,
        sh: cam.height * ss,
    }
}

/// The objects' positions and normals in world space, triangles (indices into them), each
/// triangle's object (its material's index), and the materials.
#[allow(clippy::type_complexity)]
fn flatten(scene: &Scene) -> (Vec<Vec3>, Vec<Vec3>, Vec<[u32; 3]>, Vec<u32>, Vec<Material>) {
    let mut pos = Vec::new();
    let mut nrm = Vec::new();
    let mut tris = Vec::new();
    let mut tri_mat = Vec::new();
    let mut materials = Vec::new();
    for (k, o) in scene.objects.iter().enumerate() {
        let base = pos.len() as u32;
        let nm = Mat3::from_mat4(o.model).inverse().transpose();
        pos.extend(
            o.mesh
                .positions
                .iter()
                .map(|&q| o.model.transform_point3(q)),
        );
        nrm.extend(
            o.mesh
                .normals
                .iter()
                .map(|&n| (nm * n).try_normalize().unwrap_or(Vec3::Y)),
        );
        tris.extend(o.mesh.triangles.iter().map(|t| t.map(|i| i + base)));
        tri_mat.extend(std::iter::repeat_n(k as u32, o.mesh.triangles.len()));
        materials.push(o.material.clone());
    }
    (pos, nrm, tris, tri_mat, materials)
}

impl Prepared<'_> {
    /// The environment direction for world direction `r` (attachment applied).
    #[inline]
    pub(super) fn attach(&self, r: Vec3) -> DVec3 {
        self.attach32(r).as_dvec3()
    }

    /// [`Prepared::attach`] in `f32`.
    #[inline]
    pub(super) fn attach32(&self, r: Vec3) -> Vec3 {
        let d = match self.scene.environment.as_ref().map(|e| e.attach) {
            Some(Attach::Eye) => self.view_rot * r,
            _ => r,
        };
        d.normalize_or_zero()
    }

    /// Reads the environment at `(layer, uv)` with the environment's filter.
    #[inline]
    pub(super) fn read_uv(&self, layer: usize, uv: DVec2) -> [f32; 3] {
        self.read_uv32(layer, uv.x as f32, uv.y as f32)
    }

    #[inline]
    pub(super) fn read_uv32(&self, layer: usize, u: f32, v: f32) -> [f32; 3] {
        let Some(env) = self.scene.environment.as_ref() else {
            return [0.0; 3];
        };
        if !(u.is_finite() && v.is_finite()) {
            return [0.0; 3];
        }
        let out = match env.filter {
            // Footprint filters without a footprint (motion-blur sweeps) read bilinearly.
            Filter::Bilinear | Filter::Trilinear | Filter::Ewa | Filter::SummedArea => {
                crate::fast::bilinear(&env.map, layer, u, v)
            }
            Filter::Nearest => {
                let img = &env.map.layers()[layer];
                let (w, h) = (img.width(), img.height());
                let x = ((u * w as f32).floor() as i64).clamp(0, w as i64 - 1) as u32;
                let y = ((v * h as f32).floor() as i64).clamp(0, h as i64 - 1) as u32;
                let t = img.get(x, y);
                [t[0], t[1], t[2]]
            }
        };
        if env.intensity == 1.0 {
            out
        } else {
            out.map(|c| c * env.intensity)
        }
    }

    /// The direction of layer 0's `uv` in the environment (mode 1's texgen coordinates).
    pub(super) fn uv_dir(&self, uv: DVec2) -> Option<DVec3> {
        let env = self.scene.environment.as_ref()?;
        if !uv.is_finite() {
            return None;
        }
        env.map
            .projection()
            .uv_to_dir(0, uv.clamp(DVec2::ZERO, DVec2::ONE))
    }

    /// Reads the environment in direction `d` (already attached); returns the colour and
    /// the `(u, v, layer)` read.
    #[inline]
    pub(super) fn read_dir(&self, d: DVec3) -> ([f32; 3], [f32; 3]) {
        self.read_dir32(d.as_vec3())
    }

    #[inline]
    pub(super) fn read_dir32(&self, d: Vec3) -> ([f32; 3], [f32; 3]) {
        let Some(env) = self.scene.environment.as_ref() else {
            return ([0.0; 3], [0.0, 0.0, -1.0]);
        };
        match crate::fast::dir_to_uv(&env.map, d) {
            Some((l, u, v)) => (self.read_uv32(l, u, v), [u, v, l as f32]),
            None => ([0.0; 3], [0.0, 0.0, -1.0]),
        }
    }

    /// NDC of the centre of sample `(sx, sy)`.
    #[inline]
    pub(super) fn ndc(&self, sx: f32, sy: f32) -> (f32, f32) {
        (
            2.0 * sx / self.sw as f32 - 1.0,
            1.0 - 2.0 * sy / self.sh as f32,
        )
    }
}
