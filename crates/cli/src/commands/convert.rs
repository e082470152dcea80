//! `mirrorball convert`: any projection, size, layout or container to any other. The flags
//! become the library's `ConvertRequest`; its `ConvertPlan` does the work, this module
//! shows progress and prints.

use crate::error::CliError;
use crate::fit;
use crate::progress::{with_progress, with_spinner, writing};
use crate::save;
use crate::spec::{bad, ProjSpec};
use crate::{load, ConvertArgs};
use mirrorball::convert::{convert_layers, times, ConvertPlan, ConvertRequest};
use mirrorball_core::{resample, EnvMap, Remap, WorldProjection};
use std::ops::{Deref, DerefMut};
use std::time::Instant;

/// The library's plan of a conversion, and whether to print.
pub(crate) struct Plan {
    plan: ConvertPlan,
    /// `--quiet`.
    pub(crate) quiet: bool,
}

impl Deref for Plan {
    type Target = ConvertPlan;
    fn deref(&self) -> &ConvertPlan {
        &self.plan
    }
}

impl DerefMut for Plan {
    fn deref_mut(&mut self) -> &mut ConvertPlan {
        &mut self.plan
    }
}

pub use mirrorball::spec::parse_precision;

/// `a`'s flags as the library's request.
pub(crate) fn request(a: &ConvertArgs) -> Result<ConvertRequest, CliError> {
    let r = ConvertRequest {
        input: a.input.clone(),
        output: a.output.clone(),
        input_plan: crate::commands::input_plan(&a.input_args)?,
        to: (!a.to.is_empty())
            .then(|| ProjSpec::parse(&a.to).map_err(|e| bad("--to", e)))
            .transpose()?,
        size: a.size.map(|s| s.0),
        height: a.size.and_then(|s| s.1),
        layout: crate::commands::parse_layout("--layout", a.layout.as_deref())?,
        in_stereo: parse("--in-stereo", &a.in_stereo)?,
        stereo: parse("--stereo", &a.stereo)?,
        yaw: a.yaw,
        pitch: a.pitch,
        roll: a.roll,
        flip: a
            .flip
            .iter()
            .map(|f| crate::choice::parse_flag("--flip", f))
            .collect::<Result<_, _>>()?,
        engine: parse("--for", &a.engine)?,
        exposure: a.exposure,
        precision: parse_precision(a.precision.as_deref())?,
        compression: parse("--compression", &a.compression)?,
        mips: a.mips,
        max_samples: a.max_samples,
        outside: parse("--outside", &a.outside)?,
        rotation: None,
    };
    let Some(options) = &a.v360 else {
        return Ok(r);
    };
    let v360 = mirrorball::v360::parse(options).map_err(CliError::from)?;
    if !a.quiet {
        v360.notes.iter().for_each(|n| eprintln!("{n}"));
    }
    r.with_v360(&v360)
}

/// The value of `T` that `given` (the text of `flag`) names, if given.
fn parse<T: mirrorball_core::Choice>(
    flag: &str,
    given: &Option<String>,
) -> Result<Option<T>, CliError> {
    given
        .as_deref()
        .map(|m| crate::choice::parse_flag(flag, m))
        .transpose()
}

impl Plan {
    /// Says what `file` could not hold (unless `--quiet`), with the ways to keep it.
    pub(crate) fn say_clipped(&self, file: &str, report: &fit::Report) {
        if let (Some(line), false) = (self.clipped_line(file, report), self.quiet) {
            eprintln!("{line}");
        }
    }
}

pub fn run(a: ConvertArgs) -> Result<(), CliError> {
    // Sequences, pipes and manifests (`frames/`).
    if let Some(done) = super::frames::route(&a) {
        return done;
    }
    let t0 = Instant::now();
    let (plan, mut src) = ConvertPlan::new_and_read(&request(&a)?)?;
    let mut plan = Plan {
        plan,
        quiet: a.quiet,
    };
    if plan.is_stereo() {
        return convert_pair(&a, &plan, src, t0);
    }
    let say = |s: String| {
        if !a.quiet {
            eprintln!("{s}");
        }
    };
    for line in src.prepare(&a.input, plan.input.keep_invalid) {
        say(line);
    }
    let t_read = t0.elapsed();
    let dst = plan.projection()?;
    let size = plan
        .size
        .unwrap_or_else(|| save::default_size(&src.env, dst.kind()));
    let (w, h) = dst.layer_extent(size);
    if plan.size.is_none() {
        plan.check_room((w, h), dst.layer_count(), 1, src.env.channels())?;
    }
    let rows = h as u64 * dst.layer_count() as u64;
    // Turning a cube into an engine's axes moves texels between faces: the whole map first.
    let layer_files = save::layer_files(&a.output, dst.layer_count(), &plan.save)
        .filter(|_| plan.orient.is_identity());
    plan.check_memory(&src.env, dst, (w, h), &a.output, layer_files.is_some())?;
    let t1 = Instant::now();
    let (files, t_conv, t_write) = match layer_files {
        // One file a layer: each is written as soon as it is made.
        Some(paths) => {
            let report = with_progress("converting", rows, a.quiet, |counter| {
                plan.resample.progress = Some(counter);
                let write = save::per_layer_write(&plan.save.write, dst);
                let fit = plan.layer_fit(&src.env);
                convert_layers(src, (dst, w, h), &plan.resample, &paths, (&write, fit))
            })?;
            plan.say_clipped(&a.output, &report);
            (paths, t1.elapsed(), None)
        }
        None => {
            let out = with_progress("converting", rows, a.quiet, |counter| {
                plan.resample.progress = Some(counter);
                resample(&src.env, dst, size, &plan.resample)
            });
            let out = plan.oriented(out);
            let t_conv = t1.elapsed();
            drop(src);
            let t2 = Instant::now();
            let work = save::write_work(&a.output, &[&out], &plan.save);
            let saved = writing(work, a.quiet, || save::save(&out, &a.output, &plan.save))?;
            plan.say_clipped(&a.output, &saved.report);
            (saved.files, t_conv, Some(t2.elapsed()))
        }
    };
    let names: Vec<String> = files.iter().map(|p| p.display().to_string()).collect();
    let timing = match t_write {
        Some(t) => format!(
            "read {:.2}s, convert {:.2}s, write {:.2}s",
            t_read.as_secs_f64(),
            t_conv.as_secs_f64(),
            t.as_secs_f64()
        ),
        None => format!(
            "read {:.2}s, convert and write {:.2}s",
            t_read.as_secs_f64(),
            t_conv.as_secs_f64()
        ),
    };
    say(format!(
        "wrote {}: {} {}x{}{} ({timing})",
        names.join(", "),
        dst.name(),
        w,
        h,
        times(dst.layer_count()),
    ));
    Ok(())
}

/// `convert` of one file with a stereo pair on either side (`--in-stereo`, `--stereo`): the
/// eyes it needs read (`Stereo::eyes_read`), one `Remap` planned from the left eye's shape
/// and applied to each, each output eye made from its `Stereo::source_eye`, the eyes packed
/// and joined into one picture.
fn convert_pair(
    a: &ConvertArgs,
    plan: &Plan,
    mut src: load::Source,
    t0: Instant,
) -> Result<(), CliError> {
    let in_stereo = src.stereo;
    for line in src.prepare(&a.input, plan.input.keep_invalid) {
        if !a.quiet {
            eprintln!("{line}");
        }
    }
    let eyes: Vec<EnvMap> = std::iter::once(src.env).chain(src.right).collect();
    let t_read = t0.elapsed();
    let dst = plan.projection()?;
    let left = &eyes[0];
    let size = plan
        .size
        .unwrap_or_else(|| save::default_size(left, dst.kind()));
    let (w, h) = dst.layer_extent(size);
    if plan.size.is_none() {
        plan.check_room(
            (w, h),
            dst.layer_count(),
            plan.stereo.eyes(),
            left.channels(),
        )?;
    }
    let remap = Remap::with_extent(
        *left.projection(),
        (left.width(), left.height()),
        left.layers().len(),
        dst,
        (w, h),
        &plan.resample,
    );
    plan.check_pair_memory(&eyes, dst, (w, h), &remap, &a.output)?;
    let t1 = Instant::now();
    let out = with_spinner("converting", a.quiet, || {
        plan.convert_eyes(&remap, &eyes, in_stereo, &a.input)
    })?;
    let t_conv = t1.elapsed();
    let eyes_read = eyes.len();
    drop(eyes);
    let work = save::write_work(&a.output, &out.iter().collect::<Vec<_>>(), &plan.save);
    let saved = writing(work, a.quiet, || {
        save::save_eyes(&out, plan.stereo, &a.output, &plan.save)
    })?;
    plan.say_clipped(&a.output, &saved.report);
    let files = saved.files;
    if !a.quiet {
        let names: Vec<String> = files.iter().map(|p| p.display().to_string()).collect();
        eprintln!(
            "wrote {}: {} {w}x{h}{} per eye, {} ({} read; read {:.2}s, convert {:.2}s, write {:.2}s)",
            names.join(", "),
            dst.name(),
            times(dst.layer_count()),
            plan.stereo,
            mirrorball_core::count(eyes_read as u64, "eye"),
            t_read.as_secs_f64(),
            t_conv.as_secs_f64(),
            (t1.elapsed() - t_conv).as_secs_f64()
        );
    }
    Ok(())
}
