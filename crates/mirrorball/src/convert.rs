//! Conversion of one map to another projection, size, layout or container: a
//! [`ConvertRequest`] (plain values, as a front end parsed them) becomes a checked
//! [`ConvertPlan`] before any file is read, then the map is read ([`ConvertPlan::read`]),
//! its memory checked ([`ConvertPlan::check_memory`]) and converted
//! ([`convert_layers`], [`ConvertPlan::convert_eyes`], or core's `resample`).

use crate::budget;
use crate::error::Error;
use crate::fit;
use crate::guard::Files;
use crate::load::{self, InputPlan, Source};
use crate::save::{self, SaveOptions};
use crate::spec::{bad, ProjSpec};
use mirrorball_bake::Engine;
use mirrorball_core::{
    Axis, AxisMap, EnvMap, Image, Layout, Projection, ProjectionKind, Remap, ResampleOptions,
    Resampler, Rotation, Stereo, WorldProjection,
};
use mirrorball_io::{ExrCompression, Folders, Format, OutputSet, Precision, WriteOptions};
use std::path::PathBuf;

/// What a conversion is asked to do, as plain values. Errors name the settings by the
/// command line's flags (`--to`, `--size`, …), which every front end documents.
#[derive(Clone, Debug)]
pub struct ConvertRequest {
    /// The input file (`{face}` in the name: one file per layer).
    pub input: String,
    /// The output file; its extension picks the container.
    pub output: String,
    /// How to read the input.
    pub input_plan: InputPlan,
    /// The output's projection; `None`: the input's (only the container changes).
    pub to: Option<ProjSpec>,
    /// The output's size (a cube's face edge, a lat-long's height…); `None`: from the input.
    pub size: Option<i64>,
    /// The output's height, with `size` its width (`--size WxH`): a perspective view's vfov
    /// follows from it; other projections must have that height at that width.
    pub height: Option<i64>,
    /// The layout of the output's layers in its picture.
    pub layout: Option<Layout>,
    /// How the input picture holds its eyes (`None`: as the file records, else one eye).
    pub in_stereo: Option<Stereo>,
    /// How the output picture holds its eyes (`None`: one eye).
    pub stereo: Option<Stereo>,
    /// The view's rotation, in degrees: yaw about +Y, then pitch, then roll.
    pub yaw: f64,
    /// See `yaw`.
    pub pitch: f64,
    /// See `yaw`.
    pub roll: f64,
    /// Mirrors applied after the rotation, in order.
    pub flip: Vec<Axis>,
    /// A whole turn and mirrors (v360's `yaw`, `pitch`, `roll` in its `rorder` and its
    /// flips: [`crate::v360`]), in place of `yaw`, `pitch`, `roll` and `flip`.
    pub rotation: Option<Rotation>,
    /// An engine's axes, applied last (exactly, by moving texels, for a cube).
    pub engine: Option<Engine>,
    /// Exposure in stops.
    pub exposure: f32,
    /// The output's precision; `None`: the container's default.
    pub precision: Option<Precision>,
    /// OpenEXR compression; `None`: the default.
    pub compression: Option<ExrCompression>,
    /// A KTX2/DDS cube's mip chain.
    pub mips: bool,
    /// The most integration points per texel side (1..=16).
    pub max_samples: u32,
    /// What texels outside the output's covered domain hold; `None`: the projection's rule.
    pub outside: Option<mirrorball_core::Outside>,
}

impl Default for ConvertRequest {
    fn default() -> ConvertRequest {
        ConvertRequest {
            input: String::new(),
            output: String::new(),
            input_plan: InputPlan::default(),
            to: None,
            size: None,
            height: None,
            layout: None,
            in_stereo: None,
            stereo: None,
            yaw: 0.0,
            pitch: 0.0,
            roll: 0.0,
            flip: Vec::new(),
            rotation: None,
            engine: None,
            exposure: 0.0,
            precision: None,
            compression: None,
            mips: false,
            max_samples: ResampleOptions::default().max_samples,
            outside: None,
        }
    }
}

impl ConvertRequest {
    /// The container settings given, as [`save::check_flags`] names them.
    fn container_flags(&self) -> Vec<&'static str> {
        [
            ("--compression", self.compression.is_some()),
            ("--mips", self.mips),
            ("--layout", self.layout.is_some()),
        ]
        .into_iter()
        .filter_map(|(flag, given)| given.then_some(flag))
        .collect()
    }
}

/// Everything a conversion will do, checked before any work starts (for each frame of a
/// sequence too).
pub struct ConvertPlan {
    /// How the input is read.
    pub input: InputPlan,
    /// The output's projection.
    pub to: ProjSpec,
    /// The output's size, checked against the container's bound.
    pub size: Option<u32>,
    /// How the output is written.
    pub save: SaveOptions,
    /// The resampler's settings: rotation, exposure, samples.
    pub resample: ResampleOptions,
    /// The engine's axes, for a cube output: applied exactly after resampling
    /// (`EnvMap::transformed`); other outputs take it in `resample.rotation`.
    pub orient: AxisMap,
    /// How the input picture holds its eyes (`None`: as the file records, else one eye).
    pub in_stereo: Option<Stereo>,
    /// How the output picture holds its eyes.
    pub stereo: Stereo,
    /// The input and output files, checked ([`ConvertPlan::new`]); their room on disk is
    /// checked once the output's size is known ([`ConvertPlan::check_room`]).
    pub files: Files,
    /// The output's container.
    pub format: Format,
    /// The exposure, for the advice when an output cannot hold a value.
    pub exposure: f32,
}

impl ConvertPlan {
    /// The plan of `r`, its output written to files: each checked writable, its folders
    /// made as `folders` says (one file's must exist; a sequence makes its own).
    pub fn new(r: &ConvertRequest, folders: Folders) -> Result<ConvertPlan, Error> {
        let mut plan = ConvertPlan::unwritten(r)?;
        plan.files.making(folders);
        plan.files.writable()?;
        Ok(plan)
    }

    /// The plan of `r` whose output goes elsewhere (a pipe: `r.output` only names the
    /// container its frames are packed as), so no folder of it is checked.
    pub fn unwritten(r: &ConvertRequest) -> Result<ConvertPlan, Error> {
        let input = r.input_plan.clone();
        let Some(mut to) = r.to.clone() else {
            return Err(Error::request(
                "--to: a sequence, a pipe or a manifest's job needs the output's projection \
                 (only a conversion of one file keeps its input's)",
            ));
        };
        let (mut size, mut layout) = (r.size, r.layout);
        if let (Some(w), Some(h)) = (r.size, r.height) {
            let dim = |v: i64| u32::try_from(v).ok().filter(|&v| v > 0);
            let (Some(w), Some(h)) = (dim(w), dim(h)) else {
                return Err(Error::request(format!(
                    "--size {w}x{h}: give a positive width and height"
                )));
            };
            if to.kind == ProjectionKind::Eac && layout.is_none_or(|l| l == Layout::eac()) {
                // The picture, as v360's w and h: v360's eac at that size.
                let (cells, n) = mirrorball_core::CubeCells::eac_frame(w, h).ok_or_else(|| {
                    Error::request(format!(
                        "--size {w}x{h}: too small for an eac picture (six faces between \
                         two-texel borders)"
                    ))
                })?;
                (size, layout) = (Some(n as i64), Some(Layout::Cells(cells)));
            } else {
                to = to.with_height(w, h)?;
            }
        }
        let format = save::check_container(&r.output)?;
        save::check_flags(&r.output, format, &r.container_flags(), r.precision)?;
        save::check(&r.output, to.kind, layout)?;
        let mut rotation = r.rotation.unwrap_or_else(|| {
            r.flip.iter().fold(
                Rotation::from_euler_deg(r.yaw, r.pitch, r.roll),
                |rotation, &axis| rotation.then(Rotation::mirror(axis)),
            )
        });
        // The engine's axes come last: for a cube exactly, by moving texels; otherwise as
        // the rotation it is.
        let mut orient = AxisMap::IDENTITY;
        if let Some(engine) = r.engine {
            if to.kind == ProjectionKind::Cube {
                orient = engine.orientation();
            } else {
                rotation = rotation.then(engine.orientation().rotation());
            }
        }
        let write = WriteOptions {
            precision: r.precision,
            exr_compression: r.compression.unwrap_or_default(),
            jpeg_quality: 92,
            declared: None,
            note: None,
        };
        let save = SaveOptions {
            layout,
            write,
            mips: r.mips,
            keep_invalid: input.keep_invalid,
        };
        let dst = to.build(None).map_err(|e| bad("--to", e))?;
        let layers = dst.layer_count();
        let stereo = r.stereo.unwrap_or_default();
        save::check_stereo(&r.output, layers, stereo, &save)?;
        let size = size
            .map(|s| save::size_bound(&r.output, dst, &save, stereo).check("--size", s))
            .transpose()?;
        let mut files = Files::new();
        files.input_arg("the input", &r.input);
        match save::layer_files(&r.output, layers, &save) {
            Some(paths) => paths.into_iter().for_each(|p| {
                files.output("the output", p);
            }),
            None => {
                files.output("the output", &r.output);
            }
        }
        files.distinct()?;
        Ok(ConvertPlan {
            input,
            to,
            size,
            save,
            resample: ResampleOptions {
                rotation,
                exposure: r.exposure,
                max_samples: r.max_samples,
                outside: r.outside,
                ..ResampleOptions::default()
            },
            orient,
            in_stereo: r.in_stereo,
            stereo,
            files,
            format,
            exposure: r.exposure,
        })
    }

    /// The plan of `r` and its source read. Without `to` the input's projection is kept
    /// (and its size, unless `size`), so the input is read first; what the output's
    /// container alone decides is checked before that. The output's folder must exist.
    pub fn new_and_read(r: &ConvertRequest) -> Result<(ConvertPlan, Source), Error> {
        if r.to.is_none() && r.height.is_some() {
            return Err(Error::request(
                "--size WxH: give --to too (a height is the output projection's)",
            ));
        }
        if r.to.is_some() {
            let plan = ConvertPlan::new(r, Folders::Exist)?;
            // The room on disk now when the size gives the output's (four channels at
            // most), else once the source is read.
            if let Some(size) = plan.size {
                let dst = plan.projection()?;
                plan.check_room(
                    dst.layer_extent(size),
                    dst.layer_count(),
                    plan.stereo.eyes(),
                    4,
                )?;
            }
            let src = read(r, &plan.input, (plan.in_stereo, plan.stereo))?;
            return Ok((plan, src));
        }
        let format = save::check_container(&r.output)?;
        save::check_flags(&r.output, format, &r.container_flags(), r.precision)?;
        let mut files = Files::new();
        files
            .input_arg("the input", &r.input)
            .output("the output", &r.output);
        files.check()?;
        let stereo = r.stereo.unwrap_or_default();
        let src = read(r, &r.input_plan, (r.in_stereo, stereo))?;
        let mut r = r.clone();
        r.to =
            Some(ProjSpec::parse(&src.env.projection().to_string()).map_err(|e| bad("--to", e))?);
        let plan = ConvertPlan::new(&r, Folders::Exist)?;
        Ok((plan, src))
    }

    /// The output's projection.
    pub fn projection(&self) -> Result<Projection, Error> {
        self.to.build(None).map_err(|e| bad("--to", e))
    }

    /// The line saying what `file` could not hold, with the ways to keep it (a wider
    /// precision, a lower exposure), or `None` when it held everything.
    pub fn clipped_line(&self, file: &str, report: &fit::Report) -> Option<String> {
        let keep: Vec<String> = fit::precision_advice(report.storage)
            .into_iter()
            .chain([fit::exposure_advice("--exposure", self.exposure, report)])
            .collect();
        report.line(file, &keep)
    }

    /// Refuses the job when the output's file system lacks room for a map of `layers`
    /// layers `w`×`h` of `channels` channels (`eyes` of them in one picture), with its mips
    /// when asked.
    pub fn check_room(
        &self,
        (w, h): (u32, u32),
        layers: usize,
        eyes: usize,
        channels: usize,
    ) -> Result<(), Error> {
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
    /// neither setting, gives its left eye: a `2d` output).
    pub fn is_stereo(&self) -> bool {
        self.in_stereo.is_some_and(|s| s != Stereo::Mono) || self.stereo != Stereo::Mono
    }

    /// Refuses a one-eye conversion of `env` into `dst` layers `w`×`h` written to `output`
    /// (one file a layer when `per_layer`) that would not fit in memory: the source held,
    /// the resampler's scratch, the map made and what writing copies.
    pub fn check_memory(
        &self,
        env: &EnvMap,
        dst: Projection,
        (w, h): (u32, u32),
        output: &str,
        per_layer: bool,
    ) -> Result<(), Error> {
        let c = env.channels() as u64;
        let held = budget::f32_texels(
            env.width() as u64 * env.height() as u64 * env.layers().len() as u64,
            c,
        );
        let layer = budget::f32_texels(w as u64 * h as u64, c);
        let mut scratch = mirrorball_core::resample_memory(env, dst, (w, h), &self.resample);
        let map = layer.saturating_mul(dst.layer_count() as u64);
        if !self.orient.is_identity() {
            // The map turned into an engine's axes is a copy, made once the pyramid is gone.
            scratch = scratch.max(map);
        }
        // One file a layer: a layer being made while the one before is written. One file:
        // the map, then what writing copies (the packed picture, a cube container's levels).
        let (made, written) = match per_layer {
            true => (2 * layer, 0),
            false => (
                map,
                save::write_bytes(
                    output,
                    dst.kind(),
                    (w, h, dst.layer_count()),
                    (1, c as usize),
                    &self.save,
                ),
            ),
        };
        budget::check_convert(
            &format!("{} {w}x{h}x{}", dst.name(), dst.layer_count()),
            held,
            (scratch, made, written),
            "a smaller --size",
        )
    }

    /// Refuses a stereo conversion that would not fit in memory: `eyes` read, the plan
    /// `remap`, the output eyes `w`×`h` and the pictures packed from them for `output`.
    pub fn check_pair_memory(
        &self,
        eyes: &[EnvMap],
        dst: Projection,
        (w, h): (u32, u32),
        remap: &Remap,
        output: &str,
    ) -> Result<(), Error> {
        let left = &eyes[0];
        let c = left.channels() as u64;
        let texels = |w: u32, h: u32, n: usize| w as u64 * h as u64 * n as u64;
        let out_eyes = self.stereo.eyes();
        let eye = budget::f32_texels(texels(w, h, dst.layer_count()), c);
        let plan_bytes = remap.memory_bytes() as u64;
        // Converting: the eyes read, the conversion's plan and the output eyes (one more
        // while an eye is turned into an engine's axes). Writing: the plan, the output eyes
        // and the pictures packed from them.
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
                plan_bytes + if self.orient.is_identity() { 0 } else { eye },
                eye * out_eyes as u64,
                plan_bytes
                    + save::write_bytes(
                        output,
                        dst.kind(),
                        (w, h, dst.layer_count()),
                        (out_eyes, c as usize),
                        &self.save,
                    ),
            ),
            "a smaller --size",
        )
    }

    /// The output eyes of a stereo conversion: each made by `remap` from its
    /// `Stereo::source_eye` of `eyes` (held as `in_stereo`; a 2d input converted once),
    /// turned into the engine's axes. `input` names the file in errors.
    pub fn convert_eyes(
        &self,
        remap: &Remap,
        eyes: &[EnvMap],
        in_stereo: Stereo,
        input: &str,
    ) -> Result<Vec<EnvMap>, Error> {
        let out_eyes = self.stereo.eyes();
        let mut out: Vec<EnvMap> = Vec::with_capacity(out_eyes);
        for e in 0..out_eyes {
            let from = in_stereo.source_eye(e);
            if e > 0 && in_stereo.source_eye(e - 1) == from {
                out.push(out[e - 1].clone());
                continue;
            }
            let made = remap
                .apply(&eyes[from])
                .map_err(|err| Error::input(format!("{input}: {err}")))?;
            out.push(self.oriented(made));
        }
        Ok(out)
    }

    /// `map` turned into the engine's axes (a cube output; others took them in the
    /// rotation).
    pub fn oriented(&self, map: EnvMap) -> EnvMap {
        match self.orient.is_identity() {
            true => map,
            false => map
                .transformed(&self.orient)
                .expect("only cube outputs are oriented"),
        }
    }

    /// How layers written one at a time are measured against their storage.
    pub fn layer_fit(&self, src: &EnvMap) -> LayerFit {
        LayerFit::new(src, self.format.storage(self.save.write.precision), self)
    }
}

/// Reads `r`'s input as `input` says: both eyes a stereo conversion needs
/// (`load::load_eyes`), else one map (`load::load`).
fn read(
    r: &ConvertRequest,
    input: &InputPlan,
    (in_stereo, stereo): (Option<Stereo>, Stereo),
) -> Result<Source, Error> {
    let limits = mirrorball_io::Limits::default();
    let (from, layout) = (input.from.as_ref(), input.layout);
    if in_stereo.is_some_and(|s| s != Stereo::Mono) || stereo != Stereo::Mono {
        load::load_eyes(&r.input, from, layout, (in_stereo, stereo), &limits)
    } else {
        load::load(&r.input, from, layout, &limits)
    }
}

/// How the layers written one at a time are measured against their storage: with their
/// texels' solid angles when the source's largest value, exposed, may be past the storage's
/// range (resampling averages with non-negative weights, so no output value is larger), so
/// the map's energy is known whichever layer clips; NaN and infinities replaced by 0 unless
/// the input plan keeps them.
pub struct LayerFit {
    storage: mirrorball_io::Storage,
    weighted: bool,
    keep_invalid: bool,
}

impl LayerFit {
    fn new(src: &EnvMap, storage: mirrorball_io::Storage, plan: &ConvertPlan) -> LayerFit {
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
pub fn convert_layers(
    src: Source,
    (dst, w, h): (Projection, u32, u32),
    opts: &ResampleOptions,
    paths: &[PathBuf],
    (write, fit): (&WriteOptions, LayerFit),
) -> Result<fit::Report, Error> {
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

/// " x6" after a layer's size, for maps of several layers.
pub fn times(layers: usize) -> String {
    if layers > 1 {
        format!(" x{layers}")
    } else {
        String::new()
    }
}
