//! `mirrorball render`: environment-mapped objects, as each indexing mode truly behaves.
//!
//! `args → RenderPlan` (every option parsed and checked, the output's folder and format
//! checked, the scene file read: `plan.rs`, `schema.rs`, `material.rs`) `→` environment and
//! meshes loaded `→` `mirrorball_render::render` for each frame `→` PNG/JPEG (exposure,
//! tone curve, sRGB) or EXR/HDR (linear) `→` diagnostic channels as separate float EXRs
//! beside the image (`output.rs`).

use mirrorball::materials as material;
mod output;
mod plan;
pub(crate) mod schema;

use crate::budget;
use crate::error::CliError;
use crate::progress::with_progress;
use crate::{load, RenderArgs};
use mirrorball_core::glam::Mat4;
use mirrorball_core::{resample, ResampleOptions, WorldProjection};
use mirrorball_render::tone;
use mirrorball_render::{Camera, Environment, Mesh, Object, Rendered, Scene, Settings};
use plan::{MeshSource, ObjectPlan, RenderPlan};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Instant;

pub fn run(a: RenderArgs) -> Result<(), CliError> {
    let plan = RenderPlan::new(&a)?;
    let files = output::files(&plan);
    files.check()?;
    files.room(output::bytes(&plan))?;
    let scene = load_scene(&plan)?;
    let triangles: usize = scene.objects.iter().map(|o| o.mesh.triangles.len()).sum();
    let started = Instant::now();
    let results = render_frames(&plan, &scene);
    let secs = started.elapsed().as_secs_f64();
    let mut animation = Vec::new();
    for (i, f) in results.into_iter().enumerate() {
        let f = f?;
        if plan.animated() {
            animation.push(tone::to_display(&f.color, plan.exposure, plan.tone));
        }
        output::write_frame(&plan, &scene, i, &f)?;
    }
    output::write_animation(&plan, &animation)?;
    if !plan.quiet {
        let (w, h) = (plan.camera.width, plan.camera.height);
        eprintln!(
            "{} {w}x{h}, {}, mode {}, {}x{} samples per pixel: {:.3} s ({:.1} frames/s)",
            mirrorball_core::count(u64::from(plan.frames), "frame"),
            mirrorball_core::count(triangles as u64, "triangle"),
            plan.settings.indexing.name(),
            plan.settings.supersample,
            plan.settings.supersample,
            secs,
            plan.frames as f64 / secs.max(1e-9),
        );
    }
    Ok(())
}

/// The plan's environment and objects, loaded.
fn load_scene(plan: &RenderPlan) -> Result<Scene, CliError> {
    // The meshes first: a missing or broken one is said before the environment, the longer
    // read, is read.
    let objects = plan
        .objects
        .iter()
        .map(load_object)
        .collect::<Result<Vec<_>, _>>()?;
    let environment = match &plan.env_file {
        Some(f) => Some(load_environment(plan, f)?),
        None => None,
    };
    Ok(Scene {
        objects,
        environment,
        background: plan.background,
    })
}

/// What `mirrorball render` with `a` would draw, loaded, with its camera, settings,
/// exposure and tone curve, and per object the built-in and tessellation it was made from
/// (none for a mesh file): what `mirrorball studio` shows.
#[allow(clippy::type_complexity)]
pub fn studio_scene(
    a: &RenderArgs,
) -> Result<
    (
        Scene,
        Camera,
        Settings,
        f32,
        tone::Tone,
        Vec<Option<(mirrorball_render::Builtin, u32)>>,
    ),
    CliError,
> {
    let plan = RenderPlan::new(a)?;
    let scene = load_scene(&plan)?;
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
fn load_environment(plan: &RenderPlan, file: &str) -> Result<Environment, CliError> {
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
    if !plan.quiet {
        eprintln!(
            "environment: {} {}x{} ({})",
            env.projection().name(),
            env.width(),
            env.height(),
            src.decided
        );
    }
    let env = match &plan.env_as {
        Some((spec, size)) => {
            let p = spec
                .build(None)
                .map_err(|e| CliError::request(format!("--env-as: {e}")))?;
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
            if !plan.quiet {
                eprintln!("environment converted to {} {w}x{h}", p.name());
            }
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

fn load_object(o: &ObjectPlan) -> Result<Object, CliError> {
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
fn render_frames(plan: &RenderPlan, scene: &Scene) -> Vec<Result<Rendered, CliError>> {
    let frames = plan.frames as usize;
    let label = if frames > 1 { "frames" } else { "render" };
    let rows = plan.camera.height as u64;
    with_progress(label, frames as u64 * rows, plan.quiet, |counter| {
        (0..frames)
            .map(|i| render_frame(plan, scene, i, &counter))
            .collect()
    })
}

/// Frame `i`, through the plan's camera (or fisheye), its rows counted in `counter`.
fn render_frame(
    plan: &RenderPlan,
    scene: &Scene,
    i: usize,
    counter: &AtomicU64,
) -> Result<Rendered, CliError> {
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
    frame.map_err(CliError::from)
}
