//! `mirrorball bake IN --for ENGINE OUT-DIR`: everything one engine needs for image-based
//! lighting, in its convention, with a README saying how to load it.
//!
//! `args → Plan (engine, size, encoding, folder and files checked: plan.rs) → read and
//! prepare (as prefilter) → the source checked against the encoding → memory estimated →
//! mirrorball_bake::Bake::lighting (progress bar) → Bake::write (the files land together)`.
//! The pipeline's steps are the bake library's; this module only reads, reports and times.

mod plan;

use crate::budget;
use crate::error::CliError;
use crate::fit;
use crate::load;
use crate::progress::with_work_progress;
use crate::BakeArgs;
use mirrorball_core::Choice;
use plan::{BakePlan, Plan};
use std::time::Instant;

pub fn run(a: BakeArgs) -> Result<(), CliError> {
    let plan = match Plan::new(&a)? {
        Plan::List => {
            print!("{}", mirrorball_bake::list());
            return Ok(());
        }
        Plan::Bake(p) => *p,
    };
    bake(plan)
}

fn bake(mut plan: BakePlan) -> Result<(), CliError> {
    let quiet = plan.quiet;
    let say = |s: String| {
        if !quiet {
            eprintln!("{s}");
        }
    };
    let t0 = Instant::now();
    let (env, notes) = load::read_prepared(&plan.source, &plan.input)?;
    if !plan.quiet {
        notes.iter().for_each(|line| eprintln!("{line}"));
    }
    plan.bake.check(&env)?;
    plan.bake.fit(&env);
    let size = plan.bake.opts.size;
    let held = budget::f32_texels(
        env.width() as u64 * env.height() as u64 * env.layers().len() as u64,
        env.channels() as u64,
    );
    let peak = plan.bake.memory(&env, &plan.prefilter);
    budget::check(
        &format!("baking a {size}² chain"),
        held,
        peak.saturating_sub(held),
        "a smaller --size",
    )?;
    // One bar over the prefilter and the writing, each weighted by its work (the
    // prefilter's units and the writers' are the same: about a nanosecond of one core).
    let work = plan.bake.lighting_work(&env, &plan.prefilter) + plan.bake.write_work();
    let t1 = Instant::now();
    let (report, written, t2) = with_work_progress("baking", work, quiet, |counter| {
        plan.prefilter.progress = Some(counter);
        let mut lighting = plan.bake.lighting(&env, plan.prefilter.clone());
        drop(env);
        let report = measure(&mut lighting, &plan);
        let t2 = Instant::now();
        let written = plan.bake.write_into(&lighting, &plan.dir);
        (report, written, t2)
    });
    let dir = format!("{}/", plan.dir.display());
    if let Some(line) = report.line(&dir, &keep_advice(&plan, &report)) {
        say(line);
    }
    let written = written?;
    let names: Vec<String> = written
        .files
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    let background = match plan.bake.spec.background_face {
        Some(f) => format!(", background {f}²"),
        None => String::new(),
    };
    say(format!(
        "wrote {} for {}: {} from {size}²{background}, {} (read {:.2}s, prefilter {:.2}s, write {:.2}s)",
        names.join(", "),
        plan.bake.engine,
        mirrorball_core::count(plan.bake.spec.levels.len() as u64, "level"),
        plan.bake.encoding().label(),
        (t1 - t0).as_secs_f64(),
        (t2 - t1).as_secs_f64(),
        t2.elapsed().as_secs_f64()
    ));
    if !written.removed.is_empty() {
        let gone: Vec<String> = written
            .removed
            .iter()
            .map(|p| p.display().to_string())
            .collect();
        say(format!(
            "removed {} of the earlier bake in {} that this one does not write: {}",
            mirrorball_core::count(gone.len() as u64, "file"),
            plan.dir.display(),
            gone.join(", ")
        ));
    }
    Ok(())
}

/// The lighting's cubes measured against the bake's encoding (every cube file is written in
/// it), NaN and infinities the work made replaced by 0 unless `--keep-invalid`: one part a
/// specular level, then the diffuse cube.
fn measure(l: &mut mirrorball_bake::Lighting, plan: &BakePlan) -> fit::Report {
    let storage = mirrorball_io::Storage::Texels(plan.bake.encoding());
    let keep = plan.input.keep_invalid;
    let mut report = fit::measure_in_place(&mut l.specular, storage, keep);
    report.labels = (0..l.specular.len())
        .map(|i| format!("specular level {i}"))
        .collect();
    if let Some(d) = l.diffuse.as_mut() {
        let mut diffuse = fit::measure_in_place(std::slice::from_mut(d), storage, keep);
        diffuse.labels = vec!["the diffuse cube".into()];
        report.extend(diffuse);
    }
    report
}

/// How to keep what the encoding clips: a float encoding where the engine takes one, else a
/// darker source (and the engine's intensity raised to match).
fn keep_advice(plan: &BakePlan, report: &fit::Report) -> Vec<String> {
    let engine = plan.bake.engine;
    let float = mirrorball_io::Encoding::Rgba32F;
    if engine.describe().encodings.contains(&float) {
        return vec![format!("--encoding {}", float.name())];
    }
    let n = report.stops_to_fit();
    vec![format!(
        "darken the source first (mirrorball convert --exposure -{n}) and raise {engine}'s intensity {}x",
        1u64.checked_shl(n).map_or("2^n".to_string(), |k| k.to_string())
    )]
}
