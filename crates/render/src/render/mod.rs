//! Rendering a [`Scene`] through a [`Camera`]: rasterise, then shade each visible sample
//! with the chosen [`Indexing`] mode, resolve the supersamples, and collect the diagnostic
//! channels.
//!
//! One module a mode or pass: [`prepare`] (once a frame), [`texgen`] (mode 1), [`vertex`]
//! (mode 2), [`pixel`] (the one-sample hot loop, modes 2 and 3), [`cone`] (mode 4),
//! [`shade`] (a sample and its material), [`background`], [`blur`], [`aov`], [`diagram`].

mod aov;
mod background;
mod blur;
mod cone;
mod diagram;
mod pixel;
mod prepare;
mod shade;
mod texgen;
mod vertex;

pub use aov::Aovs;
pub use diagram::{sphere_map_texcoords, texture_space_diagram};

use crate::camera::Camera;
use crate::raster::{BandBuffer, Binned, Cull, NO_HIT};
use crate::scene::{Scene, Settings};
use aov::AovBand;
use glam::Vec4;
use mirrorball_core::{Fault, Image};
use prepare::{prepare, Prepared};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};

/// What [`render`] returns: the picture and, when asked, its diagnostic channels (one
/// frame of an animation; not the core's `Frame`, a projection's orientation).
#[derive(Clone, Debug)]
pub struct Rendered {
    /// Linear RGBA; alpha is the fraction of the pixel covered by objects, or 1 where the
    /// background was drawn.
    pub color: Image,
    /// The diagnostic channels, when [`Settings::aovs`] was set.
    pub aovs: Option<Aovs>,
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

/// Renders `scene` through `cam`.
///
/// ```
/// use glam::{Mat4, Vec3};
/// use mirrorball_core::{EnvMap, ProjectionKind};
/// use mirrorball_render::{mesh, render, Camera, Environment, Material, Object, Scene, Settings};
/// use std::sync::Arc;
/// // A mirror in a uniform environment shows that colour wherever it covers the picture.
/// let cube = ProjectionKind::Cube.default_projection();
/// let env = EnvMap::from_fn(cube, 8, 3, |_| [0.25, 0.5, 0.75, 1.0]);
/// let scene = Scene {
///     objects: vec![Object {
///         mesh: Arc::new(mesh::sphere(24)),
///         model: Mat4::IDENTITY,
///         material: Material::mirror(),
///     }],
///     environment: Some(Environment::new(env)),
///     background: false,
/// };
/// let cam = Camera::perspective(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, 40.0, 24, 24);
/// let frame = render(&scene, &cam, &Settings::default()).unwrap();
/// let centre = frame.color.get(12, 12);
/// assert!((centre[0] - 0.25).abs() < 1e-5 && (centre[2] - 0.75).abs() < 1e-5);
/// assert_eq!(centre[3], 1.0);
/// // Without a background, where nothing is drawn stays transparent.
/// assert_eq!(frame.color.get(0, 0)[3], 0.0);
/// ```
pub fn render(scene: &Scene, cam: &Camera, settings: &Settings) -> Result<Rendered, RenderError> {
    let mut frame = Rendered {
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
    frame: &mut Rendered,
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
) -> Result<Rendered, RenderError> {
    let mut frame = Rendered {
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
    frame: &mut Rendered,
    rows_done: Option<&AtomicU64>,
) -> Result<(), RenderError> {
    validate(scene, cam, settings)?;
    let p = prepare(scene, cam, settings);
    let vp = cam.projection() * cam.view();
    let clip: Vec<Vec4> = p.pos.par_iter().map(|&x| vp * x.extend(1.0)).collect();
    let (w, h, ss) = (cam.width, cam.height, settings.supersample);
    // Bands of pixel rows: each is rasterised into a small visibility buffer and shaded at
    // once, in parallel, so the samples stay in cache.
    let band_px = (16 / ss).max(1);
    let culls = cull_modes(scene, settings, &clip);
    let binned = Binned::new(&clip, &p.tris, p.sw, p.sh, band_px * ss, |t| {
        culls[p.tri_mat[t as usize] as usize]
    });
    let color = &mut frame.color;
    if (color.width(), color.height(), color.channels()) != (w, h, 4) {
        *color = Image::new(w, h, 4);
    }
    let row_len = w as usize * 4;
    // The per-pixel mirror's corner attributes, once per setup, when the fast loop applies.
    let mirrors = (ss == 1 && !settings.aovs)
        .then(|| p.mirror_setups(&binned))
        .flatten();
    let bands = Bands {
        binned: &binned,
        mirrors: mirrors.as_deref(),
        band_px,
    };
    let aov_bands: Vec<Option<AovBand>> = color
        .data_mut()
        .par_chunks_mut(row_len * band_px as usize)
        .enumerate()
        .map_init(
            BandBuffer::default,
            |buf: &mut BandBuffer, (b, out): (usize, &mut [f32])| {
                let rows = (out.len() / row_len) as u32;
                let band = p.shade_band(&bands, buf, b, out, rows);
                if let Some(done) = rows_done {
                    done.fetch_add(rows as u64, Ordering::Relaxed);
                }
                band
            },
        )
        .collect();
    frame.aovs = settings
        .aovs
        .then(|| aov::assemble(aov_bands.iter().flatten(), w, h));
    Ok(())
}

/// The request's and the scene's checks before anything is prepared.
fn validate(scene: &Scene, cam: &Camera, settings: &Settings) -> Result<(), RenderError> {
    cam.validate()?;
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
    Ok(())
}

/// Per object, which faces the rasteriser may leave out (`clip`: every object's vertices
/// in clip space, in order). Back faces of a closed solid facing out that lies wholly
/// beyond the near plane are hidden by its front faces (a ray from the near plane starts
/// outside the solid, so it enters before it can leave). With a model matrix of positive
/// determinant its outside runs counter-clockwise on screen, as OpenGL's default front face.
fn cull_modes(scene: &Scene, settings: &Settings, clip: &[Vec4]) -> Vec<Cull> {
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
    culls
}

/// What every band of a frame shares.
struct Bands<'a> {
    binned: &'a Binned,
    /// Per setup, when the per-pixel mirror applies.
    mirrors: Option<&'a [crate::mirror::MirrorSetup]>,
    /// Pixel rows a band.
    band_px: u32,
}

impl Prepared<'_> {
    /// Band `b` (`rows` pixel rows): rasterised into `buf`, shaded into `out`; its
    /// diagnostic channels when asked for.
    fn shade_band(
        &self,
        bands: &Bands,
        buf: &mut BandBuffer,
        b: usize,
        out: &mut [f32],
        rows: u32,
    ) -> Option<AovBand> {
        let y0 = b as u32 * bands.band_px;
        let w = self.cam.width;
        let mut aov = self
            .settings
            .aovs
            .then(|| AovBand::new((w * rows) as usize));
        if bands.binned.band_is_empty(b) && !self.scene.background && aov.is_none() {
            out.fill(0.0); // transparent black
            return None;
        }
        let cols = bands.binned.scan_band(b, buf);
        let (depth, ids) = (buf.depth(), buf.ids());
        if self.settings.supersample == 1 && aov.is_none() {
            let vis = pixel::BandVis {
                binned: bands.binned,
                depth,
                ids,
                cols,
                mirrors: bands.mirrors,
            };
            self.shade_band_fast(y0, &vis, out);
            return None;
        }
        self.shade_band_samples(bands.binned, (depth, ids), y0, rows, out, aov.as_mut());
        aov
    }

    /// [`Prepared::shade_band`] sample by sample: each pixel the mean of its `n×n`
    /// samples, its diagnostic channels from the centre one.
    fn shade_band_samples(
        &self,
        binned: &Binned,
        (depth, ids): (&[f32], &[u32]),
        y0: u32,
        rows: u32,
        out: &mut [f32],
        mut aov: Option<&mut AovBand>,
    ) {
        let (w, ss) = (self.cam.width, self.settings.supersample);
        let centre = ss / 2;
        let inv = 1.0 / (ss * ss) as f32;
        let fast_empty = !self.scene.background && !self.settings.aovs;
        for ly in 0..rows {
            for x in 0..w {
                let mut acc = [0.0f32; 3];
                let mut hits = 0u32;
                for j in 0..ss {
                    for i in 0..ss {
                        let (sx, lsy) = (x * ss + i, ly * ss + j);
                        let sy = y0 * ss + lsy;
                        let k = (lsy * self.sw + sx) as usize;
                        if ids[k] == NO_HIT && fast_empty {
                            continue; // transparent black, nothing to record
                        }
                        let s = binned.sample(ids[k], depth[k], sx, sy);
                        let sh = self.shade(sx, sy, s);
                        hits += sh.covered as u32;
                        for (a, c) in acc.iter_mut().zip(sh.color) {
                            *a += c;
                        }
                        if let (Some(aov), true) = (aov.as_mut(), i == centre && j == centre) {
                            aov.record((ly * w + x) as usize, &sh);
                        }
                    }
                }
                let cov = hits as f32 * inv;
                let k = ((ly * w + x) * 4) as usize;
                for c in 0..3 {
                    out[k + c] = acc[c] * inv;
                }
                out[k + 3] = if self.scene.background { 1.0 } else { cov };
                if let Some(aov) = aov.as_mut() {
                    aov.coverage((ly * w + x) as usize, cov);
                }
            }
        }
    }
}
