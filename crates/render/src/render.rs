//! Rendering a [`Scene`] through a [`Camera`]: rasterise, then shade each visible sample
//! with the chosen [`Indexing`] mode, resolve the supersamples, and collect the diagnostic
//! channels.
//!
//! Reflection: for a unit view vector `v` (from the eye towards the surface) and unit normal
//! `n`, `r = v − 2(n·v)n` (the mirror direction, pointing away from the surface, towards
//! what is seen in it). Environment directions point *towards* what is seen, so `r` is
//! looked up as it is.

use crate::camera::Camera;
use crate::camera::Rays;
use crate::raster::{Binned, Cull, NO_HIT};
use crate::scene::{Attach, Filter, Indexing, Material, Scene, Settings};
use glam::{DVec2, DVec3, Mat3, Mat4, Vec2, Vec3, Vec3A, Vec4};
use mirrorball_core::{Fault, Image, Projection, SphereMap, WorldProjection};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// A rendered picture and, when asked, its diagnostic channels.
#[derive(Clone, Debug)]
pub struct Frame {
    /// Linear RGBA; alpha is the fraction of the pixel covered by objects, or 1 where the
    /// background was drawn.
    pub color: Image,
    /// The diagnostic channels, when [`Settings::aovs`] was set.
    pub aovs: Option<Aovs>,
}

/// Diagnostic channels ("arbitrary output variables"), taken at the sample nearest each
/// pixel's centre.
#[derive(Clone, Debug)]
pub struct Aovs {
    /// `(u, v, layer)` actually read from the environment (for mode 1 with a sphere map, the
    /// interpolated GL `(s, 1 − t)`); layer −1 where the object reads no environment, −2 on
    /// the background (whose own coordinates are still given).
    pub st_face: Image,
    /// The reflected direction used, in world space (the view ray on the background).
    pub reflected: Image,
    /// The unit world-space normal (0 on the background).
    pub normal: Image,
    /// R: eye-space depth (distance along the view axis), G: window depth in `[0, 1]` as
    /// OpenGL's depth buffer holds it, B: coverage of the pixel by objects. 0, 1, 0 on the
    /// background.
    pub depth: Image,
}

/// Why a scene cannot be rendered, and whose fault it is: the request's (the camera, the
/// settings, what is asked of the scene) or the input's (the scene's meshes and matrices).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct RenderError {
    fault: Fault,
    message: String,
}

impl RenderError {
    /// The request's fault.
    pub fn request(message: impl Into<String>) -> RenderError {
        RenderError {
            fault: Fault::Request,
            message: message.into(),
        }
    }
    /// The input's fault (the scene's data).
    pub fn input(message: impl Into<String>) -> RenderError {
        RenderError {
            fault: Fault::Input,
            message: message.into(),
        }
    }
    /// The system's fault (a failure of the renderer itself).
    pub fn system(message: impl Into<String>) -> RenderError {
        RenderError {
            fault: Fault::System,
            message: message.into(),
        }
    }
    /// Whose fault it is.
    pub fn fault(&self) -> Fault {
        self.fault
    }
    /// What went wrong.
    pub fn message(&self) -> &str {
        &self.message
    }
}

/// What mode 1 generates per vertex for the environment's projection.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Texgen {
    /// `GL_SPHERE_MAP`: `(s, 1 − t)` of the sphere-map texture.
    SphereSt,
    /// `GL_REFLECTION_MAP`: the direction, face chosen per pixel.
    Vector,
    /// A single-layer map's own `(u, v)`.
    Uv,
}

/// Everything the shader needs, prepared once per frame.
struct Prepared<'a> {
    scene: &'a Scene,
    cam: Camera,
    settings: Settings,
    /// World → eye rotation.
    view_rot: Mat3,
    forward: Vec3,
    pos: Vec<Vec3>,
    nrm: Vec<Vec3>,
    /// Mode 2: per-vertex reflected vector (world), true eye vector.
    r_vert: Vec<Vec3>,
    /// Mode 1: per-vertex texgen output (uv in .xy, or a direction).
    texgen: Vec<Vec3>,
    /// Mode 1: per-vertex GL reflection vector in world space (for materials).
    r_gl: Vec<Vec3>,
    texgen_kind: Texgen,
    tris: Vec<[u32; 3]>,
    /// Material index per triangle.
    tri_mat: Vec<u32>,
    materials: Vec<Material>,
    /// Its footprint sampler (trilinear, EWA), from the environment's cache.
    sampler: Option<std::sync::Arc<mirrorball_filter::Sampler>>,
    /// Per material: Greene's prefiltered maps, or the Phong-intensity sphere map.
    extra: Vec<crate::shading::MaterialMaps>,
    /// Mode 1 with a Phong-map material: per-vertex `GL_SPHERE_MAP` `(s, 1 − t)` in eye space.
    texgen_eye: Vec<Vec3>,
    rays: Rays,
    /// Rays of the previous frame's camera (motion blur).
    prev_rays: Option<Rays>,
    /// Supersample grid size.
    sw: u32,
    sh: u32,
}

/// What one sample shows.
#[derive(Clone, Copy, Debug, Default)]
struct Shaded {
    color: [f32; 3],
    covered: bool,
    /// `(u, v, layer)` read.
    st: [f32; 3],
    r: Vec3,
    n: Vec3,
    eye_depth: f32,
    win_depth: f32,
}

/// Columns of the square tiles the hot loop walks (a band is as many rows).
const TILE: usize = crate::mirror::SPAN;

/// A band's visibility, as the fast loop reads it.
struct BandVis<'a> {
    binned: &'a Binned,
    /// Depth and setup id per sample.
    depth: &'a [f32],
    ids: &'a [u32],
    /// The columns outside which the band has no hit.
    cols: std::ops::Range<usize>,
    /// Per setup, when the per-pixel mirror applies.
    mirrors: Option<&'a [crate::mirror::MirrorSetup]>,
}

/// Renders `scene` through `cam`.
pub fn render(scene: &Scene, cam: &Camera, settings: &Settings) -> Result<Frame, RenderError> {
    let mut frame = Frame {
        color: Image::new(0, 0, 4),
        aovs: None,
    };
    render_into(scene, cam, settings, &mut frame)?;
    Ok(frame)
}

/// [`render`] into `frame`, reusing its colour image when it already has the camera's size
/// (as a GPU renders into the same framebuffer frame after frame: no fresh memory to fault
/// in and zero for every frame of an animation). Each band of pixel rows is cleared by the
/// thread that renders it.
pub fn render_into(
    scene: &Scene,
    cam: &Camera,
    settings: &Settings,
    frame: &mut Frame,
) -> Result<(), RenderError> {
    render_counting(scene, cam, settings, frame, None)
}

/// [`render`], adding to `rows_done` the pixel rows of each band as it is finished (for a
/// progress bar: `cam.height` in all).
pub fn render_with_progress(
    scene: &Scene,
    cam: &Camera,
    settings: &Settings,
    rows_done: &AtomicU64,
) -> Result<Frame, RenderError> {
    let mut frame = Frame {
        color: Image::new(0, 0, 4),
        aovs: None,
    };
    render_counting(scene, cam, settings, &mut frame, Some(rows_done))?;
    Ok(frame)
}

fn render_counting(
    scene: &Scene,
    cam: &Camera,
    settings: &Settings,
    frame: &mut Frame,
    rows_done: Option<&AtomicU64>,
) -> Result<(), RenderError> {
    cam.validate().map_err(RenderError::request)?;
    if let Some(prev) = &settings.motion_from {
        prev.validate()
            .map_err(|e| RenderError::request(format!("the previous frame's camera: {e}")))?;
    }
    if !(1..=16).contains(&settings.supersample) {
        return Err(RenderError::request(format!(
            "supersampling {} is outside 1..=16",
            settings.supersample
        )));
    }
    let needs_env = scene.background || scene.objects.iter().any(|o| o.material.uses_environment());
    if needs_env && scene.environment.is_none() {
        return Err(RenderError::request(
            "the scene reflects or shows an environment but has none",
        ));
    }
    for (i, o) in scene.objects.iter().enumerate() {
        o.mesh
            .validate()
            .map_err(|e| RenderError::input(format!("object {i}: {e}")))?;
        if !o.model.is_finite() || o.model.determinant() == 0.0 {
            return Err(RenderError::input(format!(
                "object {i}: the model matrix is singular or not finite"
            )));
        }
    }
    let p = prepare(scene, cam, settings);
    let vp = cam.projection() * cam.view();
    let clip: Vec<Vec4> = p.pos.par_iter().map(|&x| vp * x.extend(1.0)).collect();
    let (w, h, ss) = (cam.width, cam.height, settings.supersample);
    // Bands of pixel rows: each is rasterised into a small visibility buffer and shaded at
    // once, in parallel, so the samples stay in cache.
    let band_px = (16 / ss).max(1);
    // Back faces of a closed solid facing out that lies wholly beyond the near plane: hidden
    // by its front faces (a ray from the near plane starts outside the solid, so it enters
    // before it can leave). With a model matrix of positive determinant its outside runs
    // counter-clockwise on screen, as OpenGL's default front face.
    let mut culls = Vec::with_capacity(scene.objects.len());
    let mut base = 0;
    for o in &scene.objects {
        let n = o.mesh.positions.len();
        let beyond_near = clip[base..base + n]
            .iter()
            .all(|c| c.w > 0.0 && c.z + c.w > 0.0);
        culls.push(
            if settings.cull_hidden_faces && beyond_near && o.mesh.is_closed_outward() {
                if o.model.determinant() > 0.0 {
                    Cull::Clockwise
                } else {
                    Cull::CounterClockwise
                }
            } else {
                Cull::None
            },
        );
        base += n;
    }
    let binned = Binned::new(&clip, &p.tris, p.sw, p.sh, band_px * ss, |t| {
        culls[p.tri_mat[t as usize] as usize]
    });
    let color = &mut frame.color;
    if (color.width(), color.height(), color.channels()) != (w, h, 4) {
        *color = Image::new(w, h, 4);
    }
    let centre = ss / 2;
    let inv = 1.0 / (ss * ss) as f32;
    let row_len = w as usize * 4;
    let fast_empty = !scene.background && !settings.aovs;
    // The per-pixel mirror's corner attributes, once per setup, when the fast loop applies.
    let mirrors = (ss == 1 && !settings.aovs)
        .then(|| p.mirror_setups(&binned))
        .flatten();
    // One band of pixel rows: rasterised into `buf`, shaded into `out`; its diagnostic
    // channels when asked for.
    let shade_band = |buf: &mut crate::raster::BandBuffer,
                      b: usize,
                      out: &mut [f32],
                      rows: u32|
     -> Option<[Vec<f32>; 4]> {
        let y0 = b as u32 * band_px;
        let mut aov: Option<[Vec<f32>; 4]> = settings
            .aovs
            .then(|| std::array::from_fn(|_| vec![0.0f32; (w * rows * 3) as usize]));
        if binned.band_is_empty(b) && !scene.background && aov.is_none() {
            out.fill(0.0); // transparent black
            return None;
        }
        let cols = binned.scan_band(b, buf);
        let (depth, ids) = (buf.depth(), buf.ids());
        if ss == 1 && aov.is_none() {
            let vis = BandVis {
                binned: &binned,
                depth,
                ids,
                cols,
                mirrors: mirrors.as_deref(),
            };
            p.shade_band_fast(y0, &vis, out);
            return None;
        }
        for ly in 0..rows {
            for x in 0..w {
                let mut acc = [0.0f32; 3];
                let mut hits = 0u32;
                for j in 0..ss {
                    for i in 0..ss {
                        let (sx, lsy) = (x * ss + i, ly * ss + j);
                        let sy = y0 * ss + lsy;
                        let k = (lsy * p.sw + sx) as usize;
                        if ids[k] == NO_HIT && fast_empty {
                            continue; // transparent black, nothing to record
                        }
                        let s = binned.sample(ids[k], depth[k], sx, sy);
                        let sh = p.shade(sx, sy, s);
                        hits += sh.covered as u32;
                        for (a, c) in acc.iter_mut().zip(sh.color) {
                            *a += c;
                        }
                        if let (Some(aov), true) = (aov.as_mut(), i == centre && j == centre) {
                            let k = ((ly * w + x) * 3) as usize;
                            aov[0][k..k + 3].copy_from_slice(&sh.st);
                            aov[1][k..k + 3].copy_from_slice(&sh.r.to_array());
                            aov[2][k..k + 3].copy_from_slice(&sh.n.to_array());
                            aov[3][k] = sh.eye_depth;
                            aov[3][k + 1] = sh.win_depth;
                        }
                    }
                }
                let cov = hits as f32 * inv;
                let k = ((ly * w + x) * 4) as usize;
                for c in 0..3 {
                    out[k + c] = acc[c] * inv;
                }
                out[k + 3] = if scene.background { 1.0 } else { cov };
                if let Some(aov) = aov.as_mut() {
                    aov[3][((ly * w + x) * 3 + 2) as usize] = cov;
                }
            }
        }
        aov
    };
    let aov_bands: Vec<Option<[Vec<f32>; 4]>> = color
        .data_mut()
        .par_chunks_mut(row_len * band_px as usize)
        .enumerate()
        .map_init(
            crate::raster::BandBuffer::default,
            |buf: &mut crate::raster::BandBuffer, (b, out): (usize, &mut [f32])| {
                let rows = (out.len() / row_len) as u32;
                let band = shade_band(buf, b, out, rows);
                if let Some(done) = rows_done {
                    done.fetch_add(rows as u64, Ordering::Relaxed);
                }
                band
            },
        )
        .collect();
    let aovs = settings.aovs.then(|| {
        let mut imgs: [Image; 4] = std::array::from_fn(|_| Image::new(w, h, 3));
        let mut offset = 0usize;
        for band in aov_bands.iter().flatten() {
            let n = band[0].len();
            for (img, r) in imgs.iter_mut().zip(band.iter()) {
                img.data_mut()[offset..offset + n].copy_from_slice(r);
            }
            offset += n;
        }
        let [st_face, reflected, normal, depth] = imgs;
        Aovs {
            st_face,
            reflected,
            normal,
            depth,
        }
    });
    frame.aovs = aovs;
    Ok(())
}

/// Flattens the objects into world space and computes the per-vertex data of modes 1 and 2.
fn prepare<'a>(scene: &'a Scene, cam: &Camera, settings: &Settings) -> Prepared<'a> {
    let view = cam.view();
    let view_rot = Mat3::from_mat4(view);
    let (_, _, forward) = cam.basis();
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
    let proj = scene.environment.as_ref().map(|e| *e.map.projection());
    let texgen_kind = match proj {
        Some(Projection::Sphere(_)) => Texgen::SphereSt,
        Some(p) if p.layer_count() == 1 => Texgen::Uv,
        _ => Texgen::Vector,
    };
    let attach = scene
        .environment
        .as_ref()
        .map_or(Attach::World, |e| e.attach);
    let persp = cam.is_perspective();
    let eye = cam.eye;
    let mode = settings.indexing;
    let (r_vert, texgen, r_gl): (Vec<Vec3>, Vec<Vec3>, Vec<Vec3>) = match mode {
        Indexing::PerVertexReflection => (
            pos.par_iter()
                .zip(nrm.par_iter())
                .map(|(&q, &n)| {
                    let v = if persp {
                        (q - eye).normalize_or_zero()
                    } else {
                        forward
                    };
                    v - 2.0 * n.dot(v) * n
                })
                .collect(),
            Vec::new(),
            Vec::new(),
        ),
        Indexing::PerVertexTexgen => {
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
                            let local =
                                DVec3::new(f.right.dot(dd), f.up.dot(dd), -f.forward.dot(dd));
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
            let (g, r): (Vec<Vec3>, Vec<Vec3>) = out.into_iter().unzip();
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

impl Prepared<'_> {
    /// The environment direction for world direction `r` (attachment applied).
    #[inline]
    fn attach(&self, r: Vec3) -> DVec3 {
        self.attach32(r).as_dvec3()
    }

    /// [`Prepared::attach`] in `f32`.
    #[inline]
    fn attach32(&self, r: Vec3) -> Vec3 {
        let d = match self.scene.environment.as_ref().map(|e| e.attach) {
            Some(Attach::Eye) => self.view_rot * r,
            _ => r,
        };
        d.normalize_or_zero()
    }

    /// Reads the environment at `(layer, uv)` with the environment's filter.
    #[inline]
    fn read_uv(&self, layer: usize, uv: DVec2) -> [f32; 3] {
        self.read_uv32(layer, uv.x as f32, uv.y as f32)
    }

    #[inline]
    fn read_uv32(&self, layer: usize, u: f32, v: f32) -> [f32; 3] {
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
    fn uv_dir(&self, uv: DVec2) -> Option<DVec3> {
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
    fn read_dir(&self, d: DVec3) -> ([f32; 3], [f32; 3]) {
        self.read_dir32(d.as_vec3())
    }

    #[inline]
    fn read_dir32(&self, d: Vec3) -> ([f32; 3], [f32; 3]) {
        let Some(env) = self.scene.environment.as_ref() else {
            return ([0.0; 3], [0.0, 0.0, -1.0]);
        };
        match crate::fast::dir_to_uv(&env.map, d) {
            Some((l, u, v)) => (self.read_uv32(l, u, v), [u, v, l as f32]),
            None => ([0.0; 3], [0.0, 0.0, -1.0]),
        }
    }

    /// The per-pixel mirror's [`MirrorSetup`](crate::mirror::MirrorSetup) of every setup of `binned`, or `None` where
    /// the fast loop does not read it (another mode, or a footprint sampler).
    fn mirror_setups(&self, binned: &Binned) -> Option<Vec<crate::mirror::MirrorSetup>> {
        // Mode 2 interpolates the per-vertex reflected vectors the same way (in `v`).
        let per_vertex = self.settings.indexing == Indexing::PerVertexReflection;
        if !(self.settings.indexing == Indexing::PerPixel || per_vertex) || self.sampler.is_some() {
            return None;
        }
        let persp = self.cam.is_perspective();
        let eye = self.cam.eye;
        Some(
            (0..binned.setup_count() as u32)
                .into_par_iter()
                .map(|id| {
                    let (tri, ob, scale) = binned.corners(id);
                    let material = &self.materials[self.tri_mat[tri as usize] as usize];
                    let [i0, i1, i2] = self.tris[tri as usize].map(|i| i as usize);
                    let at = |a: &[Vec3], k: usize| {
                        let b = ob[k];
                        Vec3A::from(a[i0] * b.x + a[i1] * b.y + a[i2] * b.z) * scale[k]
                    };
                    let rel: [Vec3; 3] = [i0, i1, i2].map(|i| self.pos[i] - eye);
                    let v = |k: usize| {
                        let b = ob[k];
                        Vec3A::from(rel[0] * b.x + rel[1] * b.y + rel[2] * b.z) * scale[k]
                    };
                    let (mirror, tint) = match material {
                        Material::Mirror { tint } => (true, *tint),
                        _ => (false, [0.0; 3]),
                    };
                    crate::mirror::MirrorSetup::new(
                        binned.edges(id),
                        [0, 1, 2].map(|k| at(&self.nrm, k)),
                        if per_vertex {
                            [0, 1, 2].map(|k| at(&self.r_vert, k))
                        } else if persp {
                            [0, 1, 2].map(v)
                        } else {
                            [Vec3A::ZERO; 3]
                        },
                        tint,
                        mirror,
                    )
                })
                .collect(),
        )
    }

    /// NDC of the centre of sample `(sx, sy)`.
    #[inline]
    fn ndc(&self, sx: f32, sy: f32) -> (f32, f32) {
        (
            2.0 * sx / self.sw as f32 - 1.0,
            1.0 - 2.0 * sy / self.sh as f32,
        )
    }

    /// The hot loop for one sample per pixel without diagnostic channels: colour and
    /// coverage of the band of pixel rows starting at row `y0` (`vis` holds its samples,
    /// `out` its RGBA pixels, every one written here). Background rays are computed a tile row at a
    /// time, and a per-pixel mirror reads a cube map directly; what this loop does not
    /// specialise goes through [`Prepared::shade`]. Allocates nothing.
    fn shade_band_fast(&self, y0: u32, vis: &BandVis, out: &mut [f32]) {
        use crate::fast::{CubeFaces, CubeLoc};
        let w = self.cam.width as usize;
        let env = self.scene.environment.as_ref();
        let cube = env
            .filter(|e| e.filter == Filter::Bilinear)
            .and_then(|e| CubeFaces::new(&e.map));
        let intensity = env.map_or(1.0, |e| e.intensity);
        let eye_attached = env.is_some_and(|e| e.attach == Attach::Eye);
        let background = self.scene.background;
        // The background is a plain lookup along the view ray unless it is blurred or
        // filtered over the pixel's footprint (a footprint sampler: trilinear, EWA, mode 4).
        let plain_bg = background && self.prev_rays.is_none() && self.sampler.is_none();
        // A per-pixel mirror is one lookup along the reflected ray unless a footprint
        // sampler filters it over the pixel's corners: then `vis.mirrors` holds its setups.
        let view = crate::mirror::MirrorView {
            persp: self.cam.is_perspective(),
            forward: Vec3A::from(self.forward),
            rot: eye_attached.then_some(self.view_rot),
            per_vertex: self.settings.indexing == Indexing::PerVertexReflection,
        };
        let rows = vis.ids.len() / w;
        // What a pixel of a segment needs: nothing (transparent black, as `out` holds), an
        // environment lookup in `dirs` times `tint`, or a colour already in `tint`.
        const SKIP: u8 = 0;
        const LOOKUP: u8 = 1;
        const DONE: u8 = 2;
        let mut kind = [SKIP; TILE];
        // Directions, a component array at a time.
        let mut dirs = [[0.0f32; TILE]; 3];
        let mut tint = [[1.0f32; 3]; TILE];
        let mut locs = [CubeLoc::NONE; TILE];
        // Background rays of a segment, as `background` computes them (normalised, then
        // attached and normalised again: a blurred frame of a still camera must equal the
        // sharp one bit for bit), but a component array at a time, so the square roots and
        // divisions vectorise.
        let batch_bg = match self.rays.perspective_parts() {
            Some(parts) if plain_bg && !eye_attached => Some(parts),
            _ => None,
        };
        let (sw, sh) = (self.sw as f32, self.sh as f32);
        let mut bg = [[0.0f32; TILE]; 3];
        // Square tiles of the band, column block by column block: neighbouring pixels read
        // neighbouring texels. Each row of a tile is shaded in three passes: directions,
        // then every texel address (prefetched, so the cache misses of a minified mirror
        // overlap instead of queueing one after the other), then the bilinear reads.
        for xb in (0..w).step_by(TILE) {
            let xe = (xb + TILE).min(w);
            for ly in 0..rows {
                let sy = y0 + ly as u32;
                let fy = sy as f32 + 0.5;
                let vrow = &vis.ids[ly * w + xb..ly * w + xe];
                let orow = &mut out[(ly * w + xb) * 4..(ly * w + xe) * 4];
                let beside = xe <= vis.cols.start || vis.cols.end <= xb;
                if !background && (beside || vrow.iter().all(|&id| id == NO_HIT)) {
                    orow.fill(0.0); // transparent black
                    continue;
                }
                // A mirror-only row without background, eight pixels a step where it can.
                if let (Some(m), Some(cf), false, true) =
                    (vis.mirrors, &cube, background, intensity == 1.0)
                {
                    if let Some(mut left) =
                        crate::mirror::mirror_row(vrow, xb, fy, m, &view, cf, orow)
                    {
                        while left != 0 {
                            let i = left.trailing_zeros() as usize;
                            left &= left - 1;
                            let x = xb + i;
                            let s = vis
                                .binned
                                .sample(vrow[i], vis.depth[ly * w + x], x as u32, sy);
                            let c = self.shade(x as u32, sy, s).color;
                            orow[i * 4..i * 4 + 4].copy_from_slice(&[c[0], c[1], c[2], 1.0]);
                        }
                        continue;
                    }
                }
                if let Some((f, r, u)) = batch_bg {
                    let yn = 1.0 - 2.0 * fy / sh;
                    let uy = u * yn;
                    let [bx, by, bz] = &mut bg;
                    for (i, ((bx, by), bz)) in bx.iter_mut().zip(by).zip(bz).enumerate() {
                        let xn = 2.0 * ((xb + i) as f32 + 0.5) / sw - 1.0;
                        let x = f.x + r.x * xn + uy.x;
                        let y = f.y + r.y * xn + uy.y;
                        let z = f.z + r.z * xn + uy.z;
                        let k = 1.0 / (x * x + y * y + z * z).sqrt();
                        let (x, y, z) = (x * k, y * k, z * k);
                        let k = 1.0 / (x * x + y * y + z * z).sqrt();
                        let ok = k.is_finite() && k > 0.0;
                        *bx = if ok { x * k } else { 0.0 };
                        *by = if ok { y * k } else { 0.0 };
                        *bz = if ok { z * k } else { 0.0 };
                    }
                }
                // Pixels whose setup is a mirror: their directions come after this loop.
                let mut mirror_lanes = 0u32;
                for (i, &id) in vrow.iter().enumerate() {
                    let x = xb + i;
                    let fx = x as f32 + 0.5;
                    kind[i] = LOOKUP;
                    if id == NO_HIT {
                        tint[i] = [1.0; 3];
                        if !background {
                            kind[i] = SKIP;
                        } else if batch_bg.is_some() {
                            for (d, b) in dirs.iter_mut().zip(&bg) {
                                d[i] = b[i];
                            }
                        } else if plain_bg {
                            // Exactly as `background` computes it (a blurred frame of a still
                            // camera must equal the sharp one bit for bit).
                            let (x, y) = self.ndc(fx, fy);
                            let r = self.attach32(self.rays.ray(x, y).1);
                            (dirs[0][i], dirs[1][i], dirs[2][i]) = (r.x, r.y, r.z);
                        } else {
                            kind[i] = DONE;
                            tint[i] = self.background(fx, fy).color;
                        }
                        continue;
                    }
                    match vis.mirrors.map(|m| &m[id as usize]) {
                        Some(m) if m.mirror => {
                            mirror_lanes |= 1 << i;
                            tint[i] = m.tint;
                        }
                        _ => {
                            kind[i] = DONE;
                            let k = ly * w + x;
                            let s = vis.binned.sample(id, vis.depth[k], x as u32, sy);
                            tint[i] = self.shade(x as u32, sy, s).color;
                        }
                    }
                }
                if let (Some(m), true) = (vis.mirrors, mirror_lanes != 0) {
                    crate::mirror::mirror_dirs(vrow, mirror_lanes, xb, fy, m, &view, &mut dirs);
                }
                let n = vrow.len();
                let dir = |i: usize| Vec3::new(dirs[0][i], dirs[1][i], dirs[2][i]);
                if let Some(cf) = &cube {
                    // Four at a time where a lane needs it (a lane that does not is located
                    // and ignored).
                    let mut i = 0;
                    while i + 4 <= n {
                        if kind[i..i + 4].contains(&LOOKUP) {
                            let d =
                                |c: usize| -> &[f32; 4] { dirs[c][i..i + 4].try_into().unwrap() };
                            locs[i..i + 4].copy_from_slice(&cf.locate4(d(0), d(1), d(2)));
                        }
                        i += 4;
                    }
                    for i in i..n {
                        if kind[i] == LOOKUP {
                            locs[i] = cf.locate(dir(i));
                        }
                    }
                }
                for (i, o) in orow.chunks_exact_mut(4).enumerate() {
                    let c = match kind[i] {
                        SKIP => [0.0; 4],
                        DONE => [tint[i][0], tint[i][1], tint[i][2], 1.0],
                        _ => {
                            let t = tint[i];
                            match &cube {
                                Some(cf) if intensity == 1.0 => {
                                    cf.fetch_tinted(&locs[i], [t[0], t[1], t[2], 1.0])
                                }
                                _ => {
                                    let e = match &cube {
                                        Some(cf) => cf.fetch(&locs[i]).map(|c| c * intensity),
                                        None => self.read_dir32(dir(i)).0,
                                    };
                                    [e[0] * t[0], e[1] * t[1], e[2] * t[2], 1.0]
                                }
                            }
                        }
                    };
                    o.copy_from_slice(&c);
                }
            }
        }
    }

    /// Shades one sample.
    fn shade(&self, sx: u32, sy: u32, s: crate::raster::Sample) -> Shaded {
        let (fx, fy) = (sx as f32 + 0.5, sy as f32 + 0.5);
        if s.tri == NO_HIT {
            return self.background(fx, fy);
        }
        let t = self.tris[s.tri as usize];
        let b = s.weights();
        let [i0, i1, i2] = t.map(|i| i as usize);
        let lerp3 = |a: &[Vec3]| a[i0] * b.x + a[i1] * b.y + a[i2] * b.z;
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
        let env_color = |out: &mut Shaded| -> [f32; 3] {
            match mode {
                Indexing::PerVertexTexgen => match self.texgen_kind {
                    Texgen::SphereSt | Texgen::Uv => {
                        let g = lerp3(&self.texgen);
                        let uv = DVec2::new(g.x as f64, g.y as f64);
                        out.st = [g.x, g.y, 0.0];
                        match self.uv_dir(uv) {
                            // A footprint filter: the texgen's direction, with the
                            // footprint of the pixel's reflected corner rays.
                            Some(d) if self.sampler.is_some() => self.footprint_read(s, fx, fy, d),
                            _ => self.read_uv(0, uv),
                        }
                    }
                    Texgen::Vector => {
                        let d = lerp3(&self.texgen).as_dvec3().normalize_or_zero();
                        let (c, st) = self.read_dir(d);
                        out.st = st;
                        if self.sampler.is_some() {
                            self.footprint_read(s, fx, fy, d)
                        } else {
                            c
                        }
                    }
                },
                Indexing::Cone => {
                    let corners = self.corner_reflections(s, fx, fy);
                    let d = self.attach(r);
                    let (_, st) = self.read_dir(d);
                    out.st = st;
                    let dirs = corners.map(|c| self.attach(c));
                    self.cone_read(d, &dirs)
                }
                _ if self.sampler.is_some() => {
                    // Modes 2 and 3 with a footprint filter: the reflected rays at the
                    // pixel's corners give the footprint.
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
        };
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
        let t = self.tris[s.tri as usize];
        let b = s.weights();
        let [i0, i1, i2] = t.map(|i| i as usize);
        let lerp3 = |a: &[Vec3]| a[i0] * b.x + a[i1] * b.y + a[i2] * b.z;
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

    /// The environment filtered over the footprint of the reflected rays through the
    /// corners of sample `s`'s pixel, about the attached direction `d`.
    #[inline(never)]
    fn footprint_read(&self, s: crate::raster::Sample, fx: f32, fy: f32, d: DVec3) -> [f32; 3] {
        let corners = self.corner_reflections(s, fx, fy);
        let dirs = corners.map(|c| self.attach(c));
        self.cone_read(d, &dirs)
    }

    /// The environment seen along the primary ray of a sample that hits nothing.
    fn background(&self, fx: f32, fy: f32) -> Shaded {
        if !self.scene.background && !self.settings.aovs {
            return Shaded::default();
        }
        let (x, y) = self.ndc(fx, fy);
        let (_, dir) = self.rays.ray(x, y);
        let mut out = Shaded {
            r: dir,
            win_depth: 1.0,
            st: [0.0, 0.0, -2.0],
            ..Default::default()
        };
        if !self.scene.background {
            return out;
        }
        let d = self.attach(dir);
        let (c, st) = match (&self.sampler, self.settings.indexing, &self.prev_rays) {
            (_, _, Some(prev)) => {
                // Greene §9: the path the pixel's ray sweeps between the two frames, sampled
                // about once per texel along its length (at most 64 samples) and averaged.
                let d0 = self.attach(prev.ray(x, y).1);
                let (_, st) = self.read_dir(d);
                (self.sweep(d0, d), st)
            }
            (Some(_), _, None) => {
                // A footprint filter: the pixel's cone of camera rays.
                let h = 0.5;
                let corners = [(-h, -h), (h, -h), (h, h), (-h, h)].map(|(dx, dy)| {
                    let (cx, cy) = self.ndc(fx + dx, fy + dy);
                    self.attach(self.rays.ray(cx, cy).1)
                });
                let (_, st) = self.read_dir(d);
                (self.cone_read(d, &corners), st)
            }
            _ => self.read_dir(d),
        };
        out.color = c;
        out.st = [st[0], st[1], -2.0];
        out
    }

    /// The average of the environment along the great-circle arc from `d0` to `d1`.
    fn sweep(&self, d0: DVec3, d1: DVec3) -> [f32; 3] {
        let Some(env) = self.scene.environment.as_ref() else {
            return [0.0; 3];
        };
        let angle = d0.angle_between(d1);
        let m = &env.map;
        let texel = (m.projection().density_of_dir(d1) / (m.width() as f64 * m.height() as f64))
            .sqrt()
            .max(1e-9);
        let n = ((angle / texel).ceil() as usize).clamp(1, 64);
        let mut acc = [0.0f32; 3];
        for k in 0..n {
            let t = (k as f64 + 0.5) / n as f64;
            let d = slerp(d0, d1, angle, t);
            let c = self.read_dir(d).0;
            for (a, v) in acc.iter_mut().zip(c) {
                *a += v;
            }
        }
        acc.map(|a| a / n as f32)
    }

    /// Greene's pixel cone: the reflected directions at the four corners of the sample's
    /// footprint, from the hit triangle's plane extended to the corners (its barycentric
    /// coordinates extrapolated) with the normal interpolated there.
    fn corner_reflections(&self, s: crate::raster::Sample, fx: f32, fy: f32) -> [Vec3; 4] {
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
    fn cone_read(&self, d: DVec3, dirs: &[DVec3; 4]) -> [f32; 3] {
        let (Some(sampler), Some(env)) = (&self.sampler, self.scene.environment.as_ref()) else {
            return self.read_dir(d).0;
        };
        let v = sampler.sample(d, &crate::lookup::footprint(dirs));
        [v[0], v[1], v[2]].map(|c| c * env.intensity)
    }
}

/// Spherical interpolation from unit `a` to unit `b`, `angle` apart, at `t`.
fn slerp(a: DVec3, b: DVec3, angle: f64, t: f64) -> DVec3 {
    if angle < 1e-9 {
        return a;
    }
    let s = angle.sin();
    if s.abs() < 1e-9 {
        return (a * (1.0 - t) + b * t).normalize_or_zero();
    }
    (a * ((1.0 - t) * angle).sin() / s + b * (t * angle).sin() / s).normalize_or_zero()
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

/// Per-vertex GL texgen `(s, t)` of mode 1 for a sphere map, for tests and the diagnostic
/// plot: for each vertex of `mesh` placed by `model` and seen by `cam`, the `GL_SPHERE_MAP`
/// coordinates in eye space, as `(s, t)` (OpenGL's `t` upwards).
pub fn sphere_map_texcoords(mesh: &crate::mesh::Mesh, model: Mat4, cam: &Camera) -> Vec<Vec2> {
    let view = cam.view();
    let mv = view * model;
    let nm = Mat3::from_mat4(mv).inverse().transpose();
    mesh.positions
        .iter()
        .zip(&mesh.normals)
        .map(|(&q, &n)| {
            let u = mv.transform_point3(q).normalize_or_zero();
            let ne = (nm * n).normalize_or_zero();
            let r = u - 2.0 * ne.dot(u) * ne;
            let st = SphereMap::gl_st(r.as_dvec3());
            Vec2::new(st.x as f32, st.y as f32)
        })
        .collect()
}

/// Zimmons' simulators as a picture: the environment map (its layers side by side, each in
/// a `cell`-pixel-wide panel, dimmed) with, drawn over it, the texels the frame read
/// (magenta: every pixel's `(u, v, layer)` from the diagnostic channels), and the per-vertex
/// texture coordinates of the objects' camera-facing triangles with their edges (yellow
/// edges, cyan vertices) — for mode 1 the texgen output itself, for the other modes the
/// coordinates of the per-vertex reflected vector. Straight edges in this plot are what
/// per-vertex interpolation does; where they cut across the map (a grazing quad's chord,
/// a rim-straddling triangle's bow tie) the picture goes wrong. Triangles spanning two
/// layers are not drawn; meshes over 50 000 triangles get vertices only.
///
/// `frame` must have been rendered with `aovs` on, with the same scene, camera and settings.
pub fn texture_space_diagram(
    scene: &Scene,
    cam: &Camera,
    settings: &Settings,
    frame: &Frame,
    cell: u32,
) -> Result<Image, RenderError> {
    let env = scene
        .environment
        .as_ref()
        .ok_or_else(|| RenderError::request("the diagram needs an environment"))?;
    let aovs = frame
        .aovs
        .as_ref()
        .ok_or_else(|| RenderError::request("the diagram needs a frame rendered with aovs"))?;
    let map = &env.map;
    let layers = map.layers().len() as u32;
    let cw = cell.max(8);
    let ch = ((cw as f64 * map.height() as f64 / map.width() as f64).round() as u32).max(1);
    let mut out = Image::new(cw * layers, ch, 3);
    // The map, dimmed and tone-mapped, nearest texel per plot pixel.
    for l in 0..layers {
        let img = &map.layers()[l as usize];
        for y in 0..ch {
            for x in 0..cw {
                let tx = (x * img.width() / cw).min(img.width() - 1);
                let ty = (y * img.height() / ch).min(img.height() - 1);
                let t = img.get(tx, ty);
                let c = [0, 1, 2].map(|k| 0.35 * crate::tone::Tone::Aces.apply(t[k]));
                out.set(l * cw + x, y, &c);
            }
        }
    }
    let plot = |out: &mut Image, layer: u32, u: f32, v: f32, c: [f32; 3]| {
        if !(u.is_finite() && v.is_finite()) || layer >= layers {
            return;
        }
        let x = (u.clamp(0.0, 0.9999) * cw as f32) as u32 + layer * cw;
        let y = (v.clamp(0.0, 0.9999) * ch as f32) as u32;
        out.set(x, y, &c);
    };
    // Texels read by the objects (layer ≥ 0; the background is −2).
    let st = &aovs.st_face;
    for y in 0..st.height() {
        for x in 0..st.width() {
            let p = st.get(x, y);
            if p[2] >= 0.0 {
                plot(&mut out, p[2] as u32, p[0], p[1], [1.0, 0.1, 0.9]);
            }
        }
    }
    // Per-vertex coordinates and edges.
    let p = prepare(scene, cam, settings);
    let coords: Vec<Option<(u32, f32, f32)>> = (0..p.pos.len())
        .map(|i| match (settings.indexing, p.texgen_kind) {
            (Indexing::PerVertexTexgen, Texgen::SphereSt | Texgen::Uv) => {
                let g = p.texgen[i];
                Some((0, g.x, g.y))
            }
            (Indexing::PerVertexTexgen, Texgen::Vector) => {
                crate::fast::dir_to_uv(map, p.texgen[i]).map(|(l, u, v)| (l as u32, u, v))
            }
            _ => {
                let v = if cam.is_perspective() {
                    (p.pos[i] - cam.eye).normalize_or_zero()
                } else {
                    p.forward
                };
                let n = p.nrm[i];
                let r = v - 2.0 * n.dot(v) * n;
                crate::fast::dir_to_uv(map, p.attach(r).as_vec3()).map(|(l, u, v)| (l as u32, u, v))
            }
        })
        .collect();
    let facing = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|i| p.pos[i as usize]);
        let n = (b - a).cross(c - a);
        let v = if cam.is_perspective() {
            a - cam.eye
        } else {
            p.forward
        };
        n.dot(v) < 0.0
    };
    if p.tris.len() <= 50_000 {
        for t in p.tris.iter().filter(|t| facing(t)) {
            let c = t.map(|i| coords[i as usize]);
            let (Some(a), Some(b), Some(cc)) = (c[0], c[1], c[2]) else {
                continue;
            };
            if a.0 != b.0 || b.0 != cc.0 {
                continue;
            }
            for (s, e) in [(a, b), (b, cc), (cc, a)] {
                let len = ((e.1 - s.1) * cw as f32).hypot((e.2 - s.2) * ch as f32);
                let n = (len.ceil() as u32).clamp(1, 4 * (cw + ch));
                for k in 0..=n {
                    let f = k as f32 / n as f32;
                    plot(
                        &mut out,
                        s.0,
                        s.1 + (e.1 - s.1) * f,
                        s.2 + (e.2 - s.2) * f,
                        [1.0, 0.9, 0.1],
                    );
                }
            }
        }
    }
    let used: std::collections::HashSet<u32> = p
        .tris
        .iter()
        .filter(|t| facing(t))
        .flat_map(|t| t.iter().copied())
        .collect();
    for i in used {
        if let Some((l, u, v)) = coords[i as usize] {
            let cx = u * cw as f32;
            let cy = v * ch as f32;
            for dy in -1i32..=1 {
                for dx in -1i32..=1 {
                    plot(
                        &mut out,
                        l,
                        (cx + dx as f32) / cw as f32,
                        (cy + dy as f32) / ch as f32,
                        [0.1, 0.9, 1.0],
                    );
                }
            }
        }
    }
    Ok(out)
}
