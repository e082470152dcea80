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
use crate::load;
use crate::progress::{with_progress, with_spinner};
use crate::BakeArgs;
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

impl From<mirrorball_bake::Error> for CliError {
    fn from(e: mirrorball_bake::Error) -> CliError {
        CliError::new(e.fault, e.message)
    }
}

fn bake(mut plan: BakePlan) -> Result<(), CliError> {
    let say = |s: String| {
        if !plan.quiet {
            eprintln!("{s}");
        }
    };
    let t0 = Instant::now();
    let env = load::read_prepared(&plan.source, &plan.input, plan.quiet)?;
    plan.bake.check(&env)?;
    let size = plan.bake.opts.size;
    let face = size.clamp(256, 4096) as u64;
    // The cubes made, and their copy in the engine's axes.
    budget::check_prefilter(
        &format!("baking a {size}² chain (working cube {face}²)"),
        &env,
        face,
        2 * plan.bake.texels(),
        "a smaller --size",
    )?;
    let t1 = Instant::now();
    let lighting = with_progress("prefilter", plan.bake.rows(), plan.quiet, |counter| {
        plan.prefilter.progress = Some(counter);
        plan.bake.lighting(&env, plan.prefilter.clone())
    });
    drop(env);
    let t2 = Instant::now();
    let files = with_spinner("writing", plan.quiet, || {
        plan.bake.write(&lighting, &plan.dir)
    })?;
    let names: Vec<String> = files.iter().map(|p| p.display().to_string()).collect();
    say(format!(
        "wrote {} for {}: {} from {size}², {} (read {:.2}s, prefilter {:.2}s, write {:.2}s)",
        names.join(", "),
        plan.bake.engine,
        mirrorball_core::count(plan.bake.spec.levels.len() as u64, "level"),
        plan.bake.encoding().label(),
        (t1 - t0).as_secs_f64(),
        (t2 - t1).as_secs_f64(),
        t2.elapsed().as_secs_f64()
    ));
    Ok(())
}
