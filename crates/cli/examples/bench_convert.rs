//! In-memory conversion benchmark, driven by `bench/convert_peers.py`.
//!
//! ```text
//! cargo run --release -p mirrorball-cli --example bench_convert -- INPUT.exr [REPS] [FACE] [WIDTH] [MAX_SAMPLES]
//! ```
//!
//! Reads a lat-long EXR, then times (best of REPS, default 5) the conversion to a cube of
//! FACE² texels per face (default 1024) and back to a lat-long WIDTH texels wide (default
//! 4096), with the default resampling options (MAX_SAMPLES, when given, overrides
//! `ResampleOptions::max_samples`; 1 is plain bilinear). File reading is not timed. Prints one JSON
//! line: the best times, output texels per second, and the round-trip log-domain PSNR of the
//! lat-long that came back against the input (`mirrorball_core::metrics::log_psnr`).
//!
//! Then the same two conversions through a [`Remap`] planned once (like `cv2.remap`'s
//! precomputed maps; planning not in the conversion times, reported apart): applied into a
//! new output each time (`plan_*_s`) and into a reused one (`plan_into_*_s`).

use mirrorball_core::{
    metrics, resample, EnvMap, Projection, ProjectionKind, Remap, ResampleOptions,
};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

// The allocator the `mirrorball` binary runs with, so that the figures are the binary's.
#[global_allocator]
static ALLOC: mirrorball_io::HugePages = mirrorball_io::HugePages;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.is_empty() || args.iter().any(|a| a == "-h" || a == "--help") {
        eprintln!("usage: bench_convert INPUT.exr [REPS=5] [FACE=1024] [WIDTH=4096] [MAX_SAMPLES]");
        return ExitCode::from(2);
    }
    let input = PathBuf::from(&args[0]);
    let defaults = ResampleOptions::default();
    let (reps, face, width, max_samples) = match parse_numbers(&args, &defaults) {
        Ok(n) => n,
        Err(e) => {
            eprintln!("bench_convert: {e}");
            return ExitCode::from(2);
        }
    };
    let env = match load(&input) {
        Ok(env) => env,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::FAILURE;
        }
    };
    let opts = ResampleOptions {
        max_samples,
        ..defaults
    };
    let cube_proj = ProjectionKind::Cube.default_projection();
    let ll_proj = ProjectionKind::LatLong.default_projection();

    // Forward: lat-long → cube, best of `reps`.
    let (forward_s, cube) = best_resample(reps, || resample(&env, cube_proj, face, &opts));
    // Back: cube → lat-long, best of `reps`.
    let (back_s, back) = best_resample(reps, || resample(&cube, ll_proj, width, &opts));

    let plans = time_plans(&env, (cube_proj, face), (ll_proj, width), &opts, reps);

    let texels = |m: &EnvMap| m.layers().len() as f64 * m.width() as f64 * m.height() as f64;
    let forward_texels = texels(&cube);
    let back_texels = texels(&back);
    let psnr = metrics::log_psnr(&env, &back);

    let json = serde_json::json!({
        "input": input.display().to_string(),
        "input_width": env.width(),
        "input_height": env.height(),
        "channels": env.channels(),
        "face": cube.width(),
        "back_width": back.width(),
        "back_height": back.height(),
        "reps": reps,
        "max_samples": max_samples,
        "threads": rayon::current_num_threads(),
        "forward_s": forward_s,
        "back_s": back_s,
        "forward_texels": forward_texels,
        "back_texels": back_texels,
        "forward_texels_per_s": forward_texels / forward_s,
        "back_texels_per_s": back_texels / back_s,
        // JSON has no infinity: an exact round trip (or a mismatch, None) prints null.
        "roundtrip_log_psnr_db": psnr.filter(|p| p.is_finite()),
        "plan_build_s": plans.build_s,
        "plan_bytes": plans.bytes,
        "plan_forward_s": plans.forward_s,
        "plan_back_s": plans.back_s,
        "plan_into_forward_s": plans.into_forward_s,
        "plan_into_back_s": plans.into_back_s,
        "plan_roundtrip_log_psnr_db": plans.psnr.filter(|p| p.is_finite()),
    });
    println!("{json}");
    ExitCode::SUCCESS
}

/// REPS, FACE, WIDTH and MAX_SAMPLES (arguments 2 to 5), each a positive integer or its
/// default when not given; the first bad one's message otherwise.
fn parse_numbers(
    args: &[String],
    defaults: &ResampleOptions,
) -> Result<(u32, u32, u32, u32), String> {
    let num =
        |i: usize, default: u32| -> Result<u32, String> {
            match args.get(i) {
                None => Ok(default),
                Some(s) => s.parse::<u32>().ok().filter(|&n| n > 0).ok_or_else(|| {
                    format!("argument {} must be a positive integer, got {s:?}", i + 1)
                }),
            }
        };
    let parsed = (
        num(1, 5),
        num(2, 1024),
        num(3, 4096),
        num(4, defaults.max_samples),
    );
    match parsed {
        (Ok(r), Ok(f), Ok(w), Ok(m)) => Ok((r, f, w, m)),
        (Err(e), ..) | (_, Err(e), ..) | (.., Err(e), _) | (.., Err(e)) => Err(e),
    }
}

/// The lat-long map in `input`, or the message to print.
fn load(input: &Path) -> Result<EnvMap, String> {
    let loaded = match mirrorball_io::read(input, &mirrorball_io::Limits::default()) {
        Ok(l) => l,
        Err(e) => return Err(format!("bench_convert: {e}")),
    };
    match EnvMap::new(ProjectionKind::LatLong.default_projection(), loaded.layers) {
        Ok(e) => Ok(e),
        Err(e) => Err(format!("bench_convert: {}: {e}", input.display())),
    }
}

/// Runs `convert` `reps` times (at least once): the best time in seconds and the last map.
fn best_resample(reps: u32, mut convert: impl FnMut() -> EnvMap) -> (f64, EnvMap) {
    let mut best_s = f64::INFINITY;
    let mut out = None;
    for _ in 0..reps {
        let t = Instant::now();
        let c = convert();
        best_s = best_s.min(t.elapsed().as_secs_f64());
        out = Some(c);
    }
    (best_s, out.expect("reps > 0"))
}

/// The times and figures of the two conversions through a [`Remap`] planned once.
struct PlanTimes {
    /// Planning both, seconds.
    build_s: f64,
    /// Both plans' memory.
    bytes: usize,
    /// Best of REPS, into a new output each time.
    forward_s: f64,
    back_s: f64,
    /// Best of REPS, into a reused output.
    into_forward_s: f64,
    into_back_s: f64,
    /// The round trip's log-domain PSNR.
    psnr: Option<f64>,
}

/// Plans `env` → cube (`cube`: its projection and face size) and back → lat-long (`ll`: its
/// projection and width) once, then times applying each, best of `reps`, into new and into
/// reused outputs.
fn time_plans(
    env: &EnvMap,
    (cube_proj, face): (Projection, u32),
    (ll_proj, width): (Projection, u32),
    opts: &ResampleOptions,
    reps: u32,
) -> PlanTimes {
    // The same conversions, planned once.
    let t = Instant::now();
    let fwd_plan = Remap::new(
        *env.projection(),
        (env.width(), env.height()),
        1,
        cube_proj,
        face,
        opts,
    );
    let back_plan = Remap::new(cube_proj, (face, face), 6, ll_proj, width, opts);
    let plan_build_s = t.elapsed().as_secs_f64();
    let best = |f: &mut dyn FnMut()| {
        let mut b = f64::INFINITY;
        for _ in 0..reps {
            let t = Instant::now();
            f();
            b = b.min(t.elapsed().as_secs_f64());
        }
        b
    };
    let mut pc = fwd_plan.apply(env).expect("plan fits its source");
    let mut pb = back_plan.apply(&pc).expect("plan fits its source");
    let plan_forward_s = best(&mut || {
        std::hint::black_box(fwd_plan.apply(env).expect("plan fits"));
    });
    let plan_back_s = best(&mut || {
        std::hint::black_box(back_plan.apply(&pc).expect("plan fits"));
    });
    let plan_into_forward_s = best(&mut || fwd_plan.apply_into(env, &mut pc).expect("plan fits"));
    let plan_into_back_s = best(&mut || back_plan.apply_into(&pc, &mut pb).expect("plan fits"));
    let plan_psnr = metrics::log_psnr(env, &pb);
    PlanTimes {
        build_s: plan_build_s,
        bytes: fwd_plan.memory_bytes() + back_plan.memory_bytes(),
        forward_s: plan_forward_s,
        back_s: plan_back_s,
        into_forward_s: plan_into_forward_s,
        into_back_s: plan_into_back_s,
        psnr: plan_psnr,
    }
}
