//! Rendering environment-mapped objects, as each indexing mode truly behaves.
//!
//! [`RenderRequest`] `→` [`RenderPlan`] (every setting parsed and checked, the output's
//! folder and format checked, the scene file read: `plan.rs`, `schema.rs`, the crate's
//! `materials.rs`) `→` environment and
//! meshes loaded `→` `mirrorball_render::render` for each frame `→` PNG/JPEG (exposure,
//! tone curve, sRGB) or EXR/HDR (linear) `→` diagnostic channels as separate float EXRs
//! beside the image (`output.rs`).

mod output;
mod plan;
pub mod schema;

pub use plan::{MeshSource, ObjectPlan, RenderPlan};

pub use crate::budget;
use crate::error::Error;
use crate::hooks::Hooks;
use crate::load::{self, InputPlan};
use mirrorball_core::glam::Mat4;
use mirrorball_core::{resample, ResampleOptions, WorldProjection};
use mirrorball_render::tone;
use mirrorball_render::{Camera, Environment, Mesh, Object, Rendered, Scene, Settings};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// What to render, as plain values: the command line's `render` flags (each documented
/// there), their text as given. A scene file's values are taken where `given` does not
/// name the setting.
#[derive(Clone, Debug)]
pub struct RenderRequest {
    pub scene: Option<String>,
    pub output: String,
    pub object: String,
    pub tessellation: Option<u32>,
    pub env: Option<String>,
    pub input: InputPlan,
    pub env_as: Option<String>,
    pub env_size: Option<i64>,
    pub mode: String,
    pub attach: String,
    pub filter: String,
    pub material: String,
    pub tint: String,
    pub f0: f32,
    pub eye: String,
    pub target: String,
    pub up: String,
    pub fov: f32,
    pub ortho: Option<f32>,
    pub fisheye: Option<f64>,
    pub fisheye_lens: String,
    pub near: f32,
    pub far: f32,
    pub size: String,
    pub ss: u32,
    pub exposure: f32,
    pub tone: String,
    pub no_background: bool,
    pub pan_blur: Option<f32>,
    pub aovs: bool,
    pub diagnostics: bool,
    pub turntable: u32,
    /// The settings given by the caller (the command line's flag ids: `ss`, `size`, …),
    /// which win over the scene file's values.
    pub given: Vec<String>,
}

impl Default for RenderRequest {
    /// The command line's defaults.
    fn default() -> RenderRequest {
        RenderRequest {
            scene: None,
            output: "render.png".into(),
            object: "sphere".into(),
            tessellation: None,
            env: None,
            input: InputPlan::default(),
            env_as: None,
            env_size: None,
            mode: "pixel".into(),
            attach: "world".into(),
            filter: "bilinear".into(),
            material: "mirror".into(),
            tint: "1,1,1".into(),
            f0: 0.04,
            eye: "0,0,3.5".into(),
            target: "0,0,0".into(),
            up: "+y".into(),
            fov: 40.0,
            ortho: None,
            fisheye: None,
            fisheye_lens: "equidistant".into(),
            near: 0.05,
            far: 1000.0,
            size: "640x480".into(),
            ss: 2,
            exposure: 0.0,
            tone: "aces".into(),
            no_background: false,
            pan_blur: None,
            aovs: false,
            diagnostics: false,
            turntable: 1,
            given: Vec::new(),
        }
    }
}

/// Renders what `a` asks for and writes its files, saying what it does through `hooks`.
pub fn run(a: &RenderRequest, hooks: &dyn Hooks) -> Result<(), Error> {
    let plan = RenderPlan::new(a)?;
    let files = output::files(&plan);
    files.check()?;
    files.room(output::bytes(&plan))?;
    let scene = load_scene(&plan, hooks)?;
    let triangles: usize = scene.objects.iter().map(|o| o.mesh.triangles.len()).sum();
    let started = Instant::now();
    let results = render_frames(&plan, &scene, hooks);
    let secs = started.elapsed().as_secs_f64();
    let mut animation = Vec::new();
    for (i, f) in results.into_iter().enumerate() {
        let f = f?;
        if plan.animated() {
            animation.push(tone::to_display(&f.color, plan.exposure, plan.tone));
        }
        output::write_frame(&plan, &scene, i, &f, hooks)?;
    }
    output::write_animation(&plan, &animation, hooks)?;
    {
        let (w, h) = (plan.camera.width, plan.camera.height);
        hooks.note(&format!(
            "{} {w}x{h}, {}, mode {}, {}x{} samples per pixel: {:.3} s ({:.1} frames/s)",
            mirrorball_core::count(u64::from(plan.frames), "frame"),
            mirrorball_core::count(triangles as u64, "triangle"),
            plan.settings.indexing.name(),
            plan.settings.supersample,
            plan.settings.supersample,
            secs,
            plan.frames as f64 / secs.max(1e-9),
        ));
    }
    Ok(())
}

/// The plan's environment and objects, loaded.
fn load_scene(plan: &RenderPlan, hooks: &dyn Hooks) -> Result<Scene, Error> {
    // The meshes first: a missing or broken one is said before the environment, the longer
    // read, is read.
    let objects = plan
        .objects
        .iter()
        .map(load_object)
        .collect::<Result<Vec<_>, _>>()?;
    let environment = match &plan.env_file {
        Some(f) => Some(load_environment(plan, f, hooks)?),
        None => None,
    };
    Ok(Scene {
        objects,
        environment,
        background: plan.background,
    })
}

/// What [`run`] with `a` would draw, loaded, with its camera, settings,
/// exposure and tone curve, and per object the built-in and tessellation it was made from
/// (none for a mesh file): what `mirrorball studio` shows.
#[allow(clippy::type_complexity)]
pub fn studio_scene(
    a: &RenderRequest,
) -> Result<
    (
        Scene,
        Camera,
        Settings,
        f32,
        tone::Tone,
        Vec<Option<(mirrorball_render::Builtin, u32)>>,
    ),
    Error,
> {
    let plan = RenderPlan::new(a)?;
    let scene = load_scene(&plan, &crate::hooks::Quiet)?;
    let builtins = plan
        .objects
        .iter()
        .map(|o| match o.source {
            MeshSource::Builtin(b, l) => Some((b, l)),
            MeshSource::File(_) => None,
        })
        .collect();
    Ok((
        scene,
        plan.camera,
        plan.settings,
        plan.exposure,
        plan.tone,
        builtins,
    ))
}

/// The environment map `file`, sanitized unless asked not to, converted as `--env-as` says.
fn load_environment(
    plan: &RenderPlan,
    file: &str,
    hooks: &dyn Hooks,
) -> Result<Environment, Error> {
    let src = load::load(
        file,
        plan.input.from.as_ref(),
        plan.input.layout,
        &mirrorball_io::Limits::default(),
    )?;
    let mut env = src.env;
    if !plan.input.keep_invalid {
        env.sanitize();
    }
    hooks.note(&format!(
        "environment: {} {}x{} ({})",
        env.projection().name(),
        env.width(),
        env.height(),
        src.decided
    ));
    let env = match &plan.env_as {
        Some((spec, size)) => {
            let p = spec
                .build(None)
                .map_err(|e| Error::request(format!("--env-as: {e}")))?;
            let (w, h) = p.layer_extent(*size);
            budget::check(
                &format!("--env-as {} {w}x{h}x{}", p.name(), p.layer_count()),
                0,
                budget::f32_texels(
                    w as u64 * h as u64 * p.layer_count() as u64,
                    env.channels() as u64,
                ),
                "a smaller --env-size",
            )?;
            hooks.note(&format!("environment converted to {} {w}x{h}", p.name()));
            resample(&env, p, *size, &ResampleOptions::default())
        }
        None => env,
    };
    Ok(Environment {
        map: Arc::new(env),
        attach: plan.attach,
        filter: plan.filter,
        intensity: plan.intensity,
        cache: Default::default(),
    })
}

fn load_object(o: &ObjectPlan) -> Result<Object, Error> {
    let (mesh, fit) = match &o.source {
        MeshSource::Builtin(b, l) => (b.mesh(*l), Mat4::IDENTITY),
        MeshSource::File(p) => {
            let m: Mesh = mirrorball_render::load_mesh(p)?;
            let fit = if o.normalize {
                m.normalizing_transform()
            } else {
                Mat4::IDENTITY
            };
            (m, fit)
        }
    };
    Ok(Object {
        mesh: Arc::new(mesh),
        model: o.model * fit,
        material: o.material.clone(),
    })
}

impl RenderPlan {
    /// The camera of frame `i`: orbited `i/frames` of a turn about the target.
    fn frame_camera(&self, i: usize) -> Camera {
        let angle = std::f32::consts::TAU * i as f32 / self.frames as f32;
        self.camera.orbited(angle)
    }
}

/// Every frame, with a progress bar in pixel rows.
fn render_frames(
    plan: &RenderPlan,
    scene: &Scene,
    hooks: &dyn Hooks,
) -> Vec<Result<Rendered, Error>> {
    let frames = plan.frames as usize;
    let label = if frames > 1 { "frames" } else { "render" };
    let rows = plan.camera.height as u64;
    let mut out = Vec::new();
    hooks.progress(label, frames as u64 * rows, &mut |counter| {
        out = (0..frames)
            .map(|i| render_frame(plan, scene, i, &counter))
            .collect()
    });
    out
}

/// Frame `i`, through the plan's camera (or fisheye), its rows counted in `counter`.
fn render_frame(
    plan: &RenderPlan,
    scene: &Scene,
    i: usize,
    counter: &AtomicU64,
) -> Result<Rendered, Error> {
    let cam = plan.frame_camera(i);
    let settings = Settings {
        motion_from: plan.pan_blur.map(|p| cam.panned(p)),
        ..plan.settings
    };
    let frame = match plan.fisheye {
        Some((lens, fov)) => mirrorball_render::render_fisheye(
            scene,
            cam.eye,
            cam.target,
            cam.up,
            lens,
            fov,
            cam.width,
            (cam.width / 2).max(16),
            &settings,
        )
        .map(|img| {
            counter.fetch_add(plan.camera.height as u64, Ordering::Relaxed);
            Rendered {
                color: img.with_channels(4),
                aovs: None,
            }
        }),
        None => mirrorball_render::render_with_progress(scene, &cam, &settings, counter),
    };
    frame.map_err(Error::from)
}
