//! `mirrorball convert`: any projection, size, layout or container to any other.

use super::InputPlan;
use crate::budget;
use crate::error::CliError;
use crate::fit;
use crate::guard::Files;
use crate::progress::{with_progress, with_spinner, writing};
use crate::save::{self, SaveOptions};
use crate::spec::{bad, ProjSpec};
use crate::{load, ConvertArgs};
use mirrorball_core::{
    resample, Axis, AxisMap, EnvMap, Image, Layout, Projection, ProjectionKind, Remap,
    ResampleOptions, Resampler, Rotation, Stereo, WorldProjection,
};
use mirrorball_io::{ExrCompression, Folders, Format, OutputSet, Precision, WriteOptions};
use std::path::PathBuf;
use std::time::Instant;

/// Everything `convert` will do, checked before any work starts (for each frame of a
/// sequence too: `frames/`).
pub(crate) struct Plan {
    pub(crate) input: InputPlan,
    pub(crate) to: ProjSpec,
    pub(crate) size: Option<u32>,
    pub(crate) save: SaveOptions,
    pub(crate) resample: ResampleOptions,
    /// `--for`'s engine axes, for a cube output: applied exactly after resampling
    /// (`EnvMap::transformed`); other outputs take it in `resample.rotation`.
    pub(crate) orient: AxisMap,
    /// `--in-stereo`: how the input picture holds its eyes (`None`: as the file records,
    /// else one eye).
    pub(crate) in_stereo: Option<Stereo>,
    /// `--stereo`: how the output picture holds its eyes.
    pub(crate) stereo: Stereo,
    /// The input and output files, checked ([`Plan::new`]); their room on disk is checked
    /// once the output's size is known ([`Plan::check_room`]).
    pub(crate) files: Files,
    /// The output's container.
    pub(crate) format: Format,
    /// `--exposure`, for the advice when an output cannot hold a value.
    pub(crate) exposure: f32,
    /// `--quiet`.
    pub(crate) quiet: bool,
}

pub fn parse_precision(p: Option<&str>) -> Result<Option<Precision>, CliError> {
    p.map(|p| crate::choice::parse_flag("--precision", p))
        .transpose()
}

fn parse_compression(c: Option<&str>) -> Result<ExrCompression, CliError> {
    c.map(|c| crate::choice::parse_flag("--compression", c))
        .transpose()
        .map(Option::unwrap_or_default)
}

/// The container flags `a` gives, as [`save::check_flags`] names them.
fn container_flags(a: &ConvertArgs) -> Vec<&'static str> {
    [
        ("--compression", a.compression.is_some()),
        ("--mips", a.mips),
        ("--layout", a.layout.is_some()),
    ]
    .into_iter()
    .filter_map(|(flag, given)| given.then_some(flag))
    .collect()
}

impl Plan {
    /// The plan of `a`, its output written to files: each checked writable, its folders
    /// made as `folders` says (one file's must exist; a sequence makes its own).
    pub(crate) fn new(a: &ConvertArgs, folders: Folders) -> Result<Plan, CliError> {
        let mut plan = Plan::unwritten(a)?;
        plan.files.making(folders);
        plan.files.writable()?;
        Ok(plan)
    }

    /// The plan of `a` whose output goes elsewhere (a pipe: `a.output` only names the
    /// container its frames are packed as), so no folder of it is checked.
    pub(crate) fn unwritten(a: &ConvertArgs) -> Result<Plan, CliError> {
        let input = InputPlan::new(&a.input_args)?;
        if a.to.is_empty() {
            return Err(CliError::request(
                "--to: a sequence, a pipe or a manifest's job needs the output's projection \
                 (only a conversion of one file keeps its input's)",
            ));
        }
        let to = ProjSpec::parse(&a.to).map_err(|e| bad("--to", e))?;
        let layout = a
            .layout
            .as_deref()
            .map(str::parse::<Layout>)
            .transpose()
            .map_err(|e| bad("--layout", e))?;
        let precision = parse_precision(a.precision.as_deref())?;
        let format = save::check_container(&a.output)?;
        save::check_flags(&a.output, format, &container_flags(a), precision)?;
        save::check(&a.output, to.kind, layout)?;
        let mut rotation = Rotation::from_euler_deg(a.yaw, a.pitch, a.roll);
        for f in &a.flip {
            let axis = crate::choice::parse_flag::<Axis>("--flip", f)?;
            rotation = rotation.then(Rotation::mirror(axis));
        }
        // The engine's axes come last: for a cube exactly, by moving texels; otherwise as
        // the rotation it is.
        let mut orient = AxisMap::IDENTITY;
        if let Some(e) = &a.engine {
            let engine = crate::choice::parse_flag::<mirrorball_bake::Engine>("--for", e)?;
            if to.kind == ProjectionKind::Cube {
                orient = engine.orientation();
            } else {
                rotation = rotation.then(engine.orientation().rotation());
            }
        }
        let write = WriteOptions {
            precision,
            exr_compression: parse_compression(a.compression.as_deref())?,
            jpeg_quality: 92,
            declared: None,
            note: None,
        };
        let save = SaveOptions {
            layout,
            write,
            mips: a.mips,
            keep_invalid: input.keep_invalid,
        };
        let layers = to.build(None).map_err(|e| bad("--to", e))?.layer_count();
        let in_stereo = stereo_flag("--in-stereo", a.in_stereo.as_deref())?;
        let stereo = stereo_flag("--stereo", a.stereo.as_deref())?.unwrap_or_default();
        save::check_stereo(&a.output, layers, stereo, &save)?;
        let dst = to.build(None).map_err(|e| bad("--to", e))?;
        let size = a
            .size
            .map(|s| save::size_bound(&a.output, dst, &save, stereo).check("--size", s))
            .transpose()?;
        let mut files = Files::new();
        files.input_arg("the input", &a.input);
        match save::layer_files(&a.output, layers, &save) {
            Some(paths) => paths.into_iter().for_each(|p| {
                files.output("the output", p);
            }),
            None => {
                files.output("the output", &a.output);
            }
        }
        files.distinct()?;
        Ok(Plan {
            input,
            to,
            size,
            save,
            resample: ResampleOptions {
                rotation,
                exposure: a.exposure,
                max_samples: a.max_samples,
                progress: None,
                progress_unit: 1,
            },
            orient,
            in_stereo,
            stereo,
            files,
            format,
            exposure: a.exposure,
            quiet: a.quiet,
        })
    }

    /// Says what `file` could not hold (unless `--quiet`), with the ways to keep it:
    /// `--precision float` for half, a lower `--exposure`.
    pub(crate) fn say_clipped(&self, file: &str, report: &fit::Report) {
        let keep: Vec<String> = fit::precision_advice(report.storage)
            .into_iter()
            .chain([fit::exposure_advice("--exposure", self.exposure, report)])
            .collect();
        if let (Some(line), false) = (report.line(file, &keep), self.quiet) {
            eprintln!("{line}");
        }
    }

    /// Refuses the job when the output's file system lacks room for a map of `layers`
    /// layers `w`×`h` of `channels` channels (`eyes` of them in one picture), with its mips
    /// when asked.
    pub(crate) fn check_room(
        &self,
        (w, h): (u32, u32),
        layers: usize,
        eyes: usize,
        channels: usize,
    ) -> Result<(), CliError> {
        let texels = w as u64 * h as u64 * layers as u64 * eyes as u64;
        let texels = if self.save.mips {
            texels * 4 / 3
        } else {
            texels
        };
        let bytes = self
            .format
            .bytes_estimate(texels, channels as u64, self.save.write.precision);
        self.files.room(bytes)
    }

    /// Whether either side is said to be a stereo pair (a pair a file records, read with
    /// neither flag, gives its left eye: a `2d` output).
    pub(crate) fn is_stereo(&self) -> bool {
        self.in_stereo.is_some_and(|s| s != Stereo::Mono) || self.stereo != Stereo::Mono
    }
}

/// Reads `a`'s input as `input` says: both eyes a stereo conversion needs
/// (`load::load_eyes`), else one map (`load::load`).
fn read(
    a: &ConvertArgs,
    input: &InputPlan,
    (in_stereo, stereo): (Option<Stereo>, Stereo),
) -> Result<load::Source, CliError> {
    let limits = mirrorball_io::Limits::default();
    let (from, layout) = (input.from.as_ref(), input.layout);
    if in_stereo.is_some_and(|s| s != Stereo::Mono) || stereo != Stereo::Mono {
        load::load_eyes(&a.input, from, layout, (in_stereo, stereo), &limits)
    } else {
        load::load(&a.input, from, layout, &limits)
    }
}

/// The plan and the source read. Without `--to` the input's projection is kept (and its
/// size, unless `--size`), so the input is read first; what the output's container alone
/// decides is checked before that.
fn plan_and_read(mut a: ConvertArgs) -> Result<(ConvertArgs, Plan, load::Source), CliError> {
    if !a.to.is_empty() {
        let plan = Plan::new(&a, Folders::Exist)?;
        // The room on disk now when --size gives the output's size (four channels at
        // most), else once the source is read.
        if let Some(size) = plan.size {
            let dst = plan.to.build(None).map_err(|e| bad("--to", e))?;
            plan.check_room(
                dst.layer_extent(size),
                dst.layer_count(),
                plan.stereo.eyes(),
                4,
            )?;
        }
        let src = read(&a, &plan.input, (plan.in_stereo, plan.stereo))?;
        return Ok((a, plan, src));
    }
    // Only the container changes: the output is checked as one file before the input is
    // read, the plan made once the input tells its projection.
    let precision = parse_precision(a.precision.as_deref())?;
    let format = save::check_container(&a.output)?;
    save::check_flags(&a.output, format, &container_flags(&a), precision)?;
    let mut files = Files::new();
    files
        .input_arg("the input", &a.input)
        .output("the output", &a.output);
    files.check()?;
    let input = InputPlan::new(&a.input_args)?;
    let in_stereo = stereo_flag("--in-stereo", a.in_stereo.as_deref())?;
    let stereo = stereo_flag("--stereo", a.stereo.as_deref())?.unwrap_or_default();
    let src = read(&a, &input, (in_stereo, stereo))?;
    a.to = src.env.projection().to_string();
    let plan = Plan::new(&a, Folders::Exist)?;
    Ok((a, plan, src))
}

/// A stereo flag's mode, if given.
fn stereo_flag(flag: &str, given: Option<&str>) -> Result<Option<Stereo>, CliError> {
    given
        .map(|m| crate::choice::parse_flag::<Stereo>(flag, m))
        .transpose()
}

pub fn run(a: ConvertArgs) -> Result<(), CliError> {
    // Sequences, pipes and manifests (`frames/`).
    if let Some(done) = super::frames::route(&a) {
        return done;
    }
    let t0 = Instant::now();
    let (a, mut plan, mut src) = plan_and_read(a)?;
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
    let dst = plan.to.build(None).map_err(|e| bad("--to", e))?;
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
    {
        let env = &src.env;
        let c = env.channels() as u64;
        let held = budget::f32_texels(
            env.width() as u64 * env.height() as u64 * env.layers().len() as u64,
            c,
        );
        let layer = budget::f32_texels(w as u64 * h as u64, c);
        let mut scratch = mirrorball_core::resample_memory(env, dst, (w, h), &plan.resample);
        let map = layer.saturating_mul(dst.layer_count() as u64);
        if !plan.orient.is_identity() {
            // The map turned into an engine's axes is a copy, made once the pyramid is gone.
            scratch = scratch.max(map);
        }
        // One file a layer: a layer being made while the one before is written. One file:
        // the map, then what writing copies (the packed picture, a cube container's levels).
        let (made, written) = match &layer_files {
            Some(_) => (2 * layer, 0),
            None => (
                map,
                save::write_bytes(
                    &a.output,
                    dst.kind(),
                    (w, h, dst.layer_count()),
                    (1, c as usize),
                    &plan.save,
                ),
            ),
        };
        budget::check_convert(
            &format!("{} {w}x{h}x{}", dst.name(), dst.layer_count()),
            held,
            (scratch, made, written),
            "a smaller --size",
        )?;
    }
    let t1 = Instant::now();
    let (files, t_conv, t_write) = match layer_files {
        // One file a layer: each is written as soon as it is made.
        Some(paths) => {
            let storage = plan.format.storage(plan.save.write.precision);
            let report = with_progress("converting", rows, a.quiet, |counter| {
                plan.resample.progress = Some(counter);
                let write = save::per_layer_write(&plan.save.write, dst);
                let fit = LayerFit::new(&src.env, storage, &plan);
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
            let out = match plan.orient.is_identity() {
                true => out,
                false => out
                    .transformed(&plan.orient)
                    .expect("only cube outputs are oriented here"),
            };
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

/// How the layers written one at a time are measured against their storage: with their
/// texels' solid angles when the source's largest value, exposed, may be past the storage's
/// range (resampling averages with non-negative weights, so no output value is larger), so
/// the map's energy is known whichever layer clips; NaN and infinities replaced by 0 unless
/// `--keep-invalid`.
struct LayerFit {
    storage: mirrorball_io::Storage,
    weighted: bool,
    keep_invalid: bool,
}

impl LayerFit {
    fn new(src: &EnvMap, storage: mirrorball_io::Storage, plan: &Plan) -> LayerFit {
        let range = storage.range();
        let largest = src
            .layers()
            .iter()
            .flat_map(|l| l.data().chunks_exact(l.channels()))
            .flat_map(|px| &px[..3])
            .fold(0f32, |m, v| m.max(v.abs()));
        LayerFit {
            storage,
            weighted: !range.display && largest * plan.exposure.exp2() > range.least_max(),
            keep_invalid: plan.input.keep_invalid,
        }
    }

    /// Measures layer `layer` of a `dst` map (`img`), fixing what it must, into `report`.
    fn layer(&self, dst: Projection, layer: usize, img: &mut Image, report: &mut fit::Report) {
        let range = self.storage.range();
        let (w, h) = (img.width(), img.height());
        let weight = move |x: u32, y: u32| dst.texel_solid_angle(layer, x, y, w, h);
        let mut m = range.measure(img, self.weighted.then_some(&weight as _));
        if m.invalid > 0 && !self.keep_invalid {
            report.replaced += mirrorball_core::sanitize_layer(img);
            m = range.measure(img, self.weighted.then_some(&weight as _));
        }
        match report.parts.first_mut() {
            Some(p) => *p = *p + m,
            None => report.parts.push(m),
        }
    }
}

/// Converts `src` into `dst`'s projection, layers `w`×`h`, one layer after another, and
/// writes layer `i` to `paths[i]`, the set landing together (`mirrorball_io::OutputSet`): an
/// interrupted or failed run leaves the old files as they were. One layer is in memory at a
/// time, its buffer filled again for the next. Each layer is measured by `fit` before it is
/// written; returns what the set could not hold.
fn convert_layers(
    src: load::Source,
    (dst, w, h): (Projection, u32, u32),
    opts: &ResampleOptions,
    paths: &[PathBuf],
    (write, fit): (&WriteOptions, LayerFit),
) -> Result<fit::Report, CliError> {
    let r = Resampler::new(&src.env, dst, w, h, opts);
    let mut set = OutputSet::new(write);
    let mut report = fit::Report::new(fit.storage);
    for (layer, path) in paths.iter().enumerate() {
        let mut img = match set.spare() {
            Some(mut img) => {
                r.layer_into(layer, &mut img);
                img
            }
            None => r.layer(layer),
        };
        fit.layer(dst, layer, &mut img, &mut report);
        set.push(path, img)?;
    }
    drop(r);
    drop(src);
    set.finish()?;
    Ok(report)
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
    let dst = plan.to.build(None).map_err(|e| bad("--to", e))?;
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
    let c = left.channels() as u64;
    let texels = |w: u32, h: u32, n: usize| w as u64 * h as u64 * n as u64;
    let out_eyes = plan.stereo.eyes();
    let remap = Remap::with_extent(
        *left.projection(),
        (left.width(), left.height()),
        left.layers().len(),
        dst,
        (w, h),
        &plan.resample,
    );
    let eye = budget::f32_texels(texels(w, h, dst.layer_count()), c);
    let plan_bytes = remap.memory_bytes() as u64;
    // Converting: the eyes read, the conversion's plan and the output eyes (one more while
    // an eye is turned into an engine's axes). Writing: the plan, the output eyes and the
    // pictures packed from them.
    budget::check_convert(
        &format!(
            "{} {w}x{h}x{}, {}",
            dst.name(),
            dst.layer_count(),
            mirrorball_core::count(out_eyes as u64, "eye")
        ),
        budget::f32_texels(
            texels(left.width(), left.height(), left.layers().len()) * eyes.len() as u64,
            c,
        ),
        (
            plan_bytes + if plan.orient.is_identity() { 0 } else { eye },
            eye * out_eyes as u64,
            plan_bytes
                + save::write_bytes(
                    &a.output,
                    dst.kind(),
                    (w, h, dst.layer_count()),
                    (out_eyes, c as usize),
                    &plan.save,
                ),
        ),
        "a smaller --size",
    )?;
    let t1 = Instant::now();
    let out = with_spinner(
        "converting",
        a.quiet,
        || -> Result<Vec<EnvMap>, CliError> {
            let mut out: Vec<EnvMap> = Vec::with_capacity(out_eyes);
            for e in 0..out_eyes {
                let from = in_stereo.source_eye(e);
                // A 2d input gives both eyes one picture: converted once.
                if e > 0 && in_stereo.source_eye(e - 1) == from {
                    out.push(out[e - 1].clone());
                    continue;
                }
                let made = remap
                    .apply(&eyes[from])
                    .map_err(|err| CliError::input(format!("{}: {err}", a.input)))?;
                out.push(match plan.orient.is_identity() {
                    true => made,
                    false => made
                        .transformed(&plan.orient)
                        .expect("only cube outputs are oriented here"),
                });
            }
            Ok(out)
        },
    )?;
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

/// " x6" after a layer's size, for maps of several layers.
pub(crate) fn times(layers: usize) -> String {
    if layers > 1 {
        format!(" x{layers}")
    } else {
        String::new()
    }
}
