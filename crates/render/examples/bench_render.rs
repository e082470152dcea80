//! Frames per second at 1280×720 for `bench/render_mesa.py bench`: a mirror bunny and a
//! mirror teapot in a cube map (city.exr as six 256² faces). Prints `name<TAB>fps` lines,
//! best of `--reps` runs of `--frames` frames, each rendered into one reused frame (as Mesa
//! renders into its framebuffer). `--only TEXT` keeps the cases whose name has it;
//! `--portable` turns the AVX2 paths off.

use glam::{Mat4, Vec3};
use mirrorball_core::{resample, EnvMap, ProjectionKind, ResampleOptions};
use mirrorball_render::{
    load_mesh, render, render_into, Builtin, Camera, Environment, Indexing, Material, Mesh, Object,
    Scene, Settings,
};
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

// The allocator the `mirrorball` binary runs with, so that the figures are the binary's.
#[global_allocator]
static ALLOC: mirrorball_io::HugePages = mirrorball_io::HugePages;

fn arg(name: &str, default: u32) -> u32 {
    let a: Vec<String> = std::env::args().collect();
    a.iter()
        .position(|x| x == name)
        .and_then(|i| a.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn main() {
    // `--portable`: without the AVX2 paths (the same pictures), to measure what they give.
    if std::env::args().any(|a| a == "--portable") {
        mirrorball_render::set_portable(true);
    }
    let frames = arg("--frames", 20);
    let reps = arg("--reps", 3);
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let cube = load_cube(&root);
    let bunny = load_mesh(&root.join("assets/meshes/bunny.obj")).expect("bunny.obj");
    let fit = bunny.normalizing_transform();
    let teapot = Builtin::Teapot.mesh(8);
    let cam = Camera::perspective(Vec3::new(0.8, 0.4, 3.0), Vec3::ZERO, 40.0, 1280, 720);
    let cases = cases(&bunny, fit, &teapot);
    let only: Option<String> = std::env::args()
        .collect::<Vec<_>>()
        .windows(2)
        .find(|w| w[0] == "--only")
        .map(|w| w[1].clone());
    for (name, mesh, model, mode, background) in cases {
        if only.as_ref().is_some_and(|o| !name.contains(o.as_str())) {
            continue;
        }
        let (scene, settings) = scene_and_settings(name, mesh, model, mode, background, &cube);
        // Mode 4 filters every pixel with EWA in f64: a tenth of the frames.
        let frames = if mode == Indexing::Cone {
            (frames / 10).max(1)
        } else {
            frames
        };
        let best = best_fps(&scene, &cam, &settings, frames, reps);
        println!("{name}\t{best:.2}");
    }
}

/// city.exr as a cube map of FACE² texels per face (the environment variable, 256 when
/// not set).
fn load_cube(root: &Path) -> EnvMap {
    let loaded = mirrorball_io::read(&root.join("assets/env/city.exr"), &Default::default())
        .expect("city.exr");
    let ll = EnvMap::new(ProjectionKind::LatLong.default_projection(), loaded.layers).unwrap();
    resample(
        &ll,
        ProjectionKind::Cube.default_projection(),
        std::env::var("FACE")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(256),
        &ResampleOptions::default(),
    )
}

/// A benchmark case: its name, the mesh and its model matrix, the indexing mode and
/// whether the background is drawn.
type Case<'m> = (&'static str, &'m Mesh, Mat4, Indexing, bool);

/// The benchmark cases, in the order they run: the bunny (fitted by `fit`) in five, the
/// teapot in two.
fn cases<'m>(bunny: &'m Mesh, fit: Mat4, teapot: &'m Mesh) -> [Case<'m>; 7] {
    [
        (
            "mirrorball bunny per-pixel cube, no background",
            bunny,
            fit,
            Indexing::PerPixel,
            false,
        ),
        (
            "mirrorball bunny per-vertex reflection (mode 2) cube, no background",
            bunny,
            fit,
            Indexing::PerVertexReflection,
            false,
        ),
        (
            "mirrorball bunny per-pixel cube, every face drawn, no background",
            bunny,
            fit,
            Indexing::PerPixel,
            false,
        ),
        (
            "mirrorball bunny per-pixel cube, with background",
            bunny,
            fit,
            Indexing::PerPixel,
            true,
        ),
        (
            "mirrorball bunny mode 4 cones (EWA), with background",
            bunny,
            fit,
            Indexing::Cone,
            true,
        ),
        (
            "mirrorball teapot (level 8) per-pixel cube, no background",
            teapot,
            Mat4::IDENTITY,
            Indexing::PerPixel,
            false,
        ),
        (
            "mirrorball teapot (level 8) per-pixel cube, with background",
            teapot,
            Mat4::IDENTITY,
            Indexing::PerPixel,
            true,
        ),
    ]
}

/// The scene of one mirror object (`mesh` placed by `model`) in `cube`, and the settings of
/// the case `name`: its indexing `mode`, the background when `background`, hidden faces
/// culled except in the case that draws every face.
fn scene_and_settings(
    name: &str,
    mesh: &Mesh,
    model: Mat4,
    mode: Indexing,
    background: bool,
    cube: &EnvMap,
) -> (Scene, Settings) {
    let scene = Scene {
        objects: vec![Object {
            mesh: Arc::new(mesh.clone()),
            model,
            material: Material::mirror(),
        }],
        environment: Some(Environment::new(cube.clone())),
        background,
    };
    let settings = Settings {
        indexing: mode,
        supersample: 1,
        aovs: false,
        motion_from: None,
        // The bunny is watertight: its back faces are left out, except in the case that
        // measures what that gives.
        cull_hidden_faces: !name.contains("every face drawn"),
    };
    (scene, settings)
}

/// The best frames per second of `reps` runs of `frames` frames, each rendered into one
/// reused frame, as Mesa into its framebuffer.
fn best_fps(scene: &Scene, cam: &Camera, settings: &Settings, frames: u32, reps: u32) -> f64 {
    let mut frame = render(scene, cam, settings).unwrap();
    let mut best = 0.0f64;
    for _ in 0..reps {
        let t = Instant::now();
        for _ in 0..frames {
            render_into(scene, cam, settings, &mut frame).unwrap();
            std::hint::black_box(&frame);
        }
        best = best.max(frames as f64 / t.elapsed().as_secs_f64());
    }
    best
}
