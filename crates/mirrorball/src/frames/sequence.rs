//! A sequence of frames: from files (a pattern) or raw frames on standard input, to files
//! (a printf pattern) or raw frames on standard output. The whole request is checked before
//! the first frame is read; the first frame's shape plans one `Remap`, which converts every
//! frame (a later frame of another shape is refused by name); frames go through the
//! bounded pipeline of `pipeline.rs`. A frame's file is written to a temporary file and
//! renamed into place (io's atomic writes), so an interrupt or a failure leaves whole
//! frames only, and a frame whose output exists is skipped unless `--overwrite`: a rerun
//! after a crash or a killed node carries on where it stopped.

use super::log::{Log, Status};
use super::packing::{Packing, Picture};
use super::pattern::{Frame, Pattern, Printf};
use super::pipe::{self, PixFmt};
use super::pipeline::{self, Eyes, Meta, FRAMES_IN_FLIGHT};
use super::record::{self, Verdict};
use super::shard::Shard;
use crate::convert::{times, ConvertPlan as Plan, ConvertRequest};
use crate::error::Error;
use crate::hooks::Hooks;
use crate::{budget, load, save};
use mirrorball_core::{
    EnvMap, Image, Layout, Projection, Remap, RemapRows, Stereo, WorldProjection,
};
use serde_json::json;
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// A conversion of many frames (a pattern of files, or raw frames through `-`), as plain
/// values.
#[derive(Clone, Debug, Default)]
pub struct FramesRequest {
    /// Each frame's conversion: `input` and `output` are patterns (`%05d`, a glob) or `-`.
    pub convert: ConvertRequest,
    /// The size of raw frames on standard input (the whole picture, both eyes of a pair).
    pub in_size: Option<(u32, u32)>,
    /// The pixel format of raw frames through `-`.
    pub pix_fmt: Option<PixFmt>,
    /// The pixel format of the frames written to standard output, when not `pix_fmt`.
    pub out_pix_fmt: Option<PixFmt>,
    /// Only this slice of the frames.
    pub shard: Option<Shard>,
    /// Convert frames whose outputs exist again.
    pub overwrite: bool,
    /// One JSON line per frame.
    pub json: bool,
}

/// Where frames come from.
enum Input {
    /// Files, in frame order (this shard's).
    Files(Vec<Frame>),
    /// Raw frames of this size and format on standard input.
    Pipe { w: u32, h: u32, fmt: PixFmt },
}

/// Where frames go.
enum Output {
    Files(Printf),
    /// One file (a single input frame only).
    File(String),
    Pipe(PixFmt),
}

/// `path`'s folder resolved, joined with its name: how two names of one file are told
/// apart across a sequence without a system call per pair.
fn resolved(path: &Path, dirs: &mut std::collections::HashMap<PathBuf, PathBuf>) -> PathBuf {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let real = dirs
        .entry(dir.to_path_buf())
        .or_insert_with(|| std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf()))
        .clone();
    real.join(path.file_name().unwrap_or_default())
}

/// Converts the frames `r` names, saying what it does through `hooks`.
pub fn run(r: &FramesRequest, hooks: &dyn Hooks) -> Result<(), Error> {
    let a = &r.convert;
    let shard = r.shard;
    let in_fmt = r.pix_fmt;
    let out_fmt = r.out_pix_fmt.or(in_fmt);
    if a.input == a.output && a.input != "-" {
        return Err(Error::request(format!(
            "{}: the output pattern is the input pattern, so each frame would overwrite itself; choose another name or folder",
            a.output
        )));
    }
    let mut first_of_all = None;
    let mut empty_slice = None;
    let input = if a.input == "-" {
        if shard.is_some() {
            return Err(Error::request(
                "--shard slices frames from files; standard input (-) is one stream, so give each machine its own stream instead",
            ));
        }
        let (Some((w, h)), Some(fmt)) = (r.in_size, in_fmt) else {
            return Err(Error::request(
                "input -: raw frames need --in-size WIDTHxHEIGHT and --pix-fmt (rgb24, rgb48le, rgbf32le, gbrpf32le)",
            ));
        };
        if let Some(s) = a.in_stereo {
            s.eye_extent(w, h)
                .map_err(|e| Error::request(format!("--in-size {w}x{h}: {e}")))?;
        }
        Input::Pipe { w, h, fmt }
    } else {
        if r.in_size.is_some() {
            return Err(Error::request(format!(
                "--in-size is the size of raw frames on standard input; {} is read from files, which say their size",
                a.input
            )));
        }
        let frames = match Pattern::parse(&a.input)? {
            Some(p) => p.expand(&a.input)?,
            None => vec![Frame {
                number: 0,
                path: PathBuf::from(&a.input),
            }],
        };
        // The whole sequence's first frame stands for every shard's in the request's
        // checks, so that each shard, an empty one too, accepts or refuses alike.
        first_of_all = Some(frames[0].clone());
        let slice = shard.map_or(0..frames.len(), |s| s.range(frames.len()));
        if slice.is_empty() {
            empty_slice = Some((slice.start, frames.len()));
        }
        Input::Files(frames[slice].to_vec())
    };
    let output = if a.output == "-" {
        let fmt = out_fmt.ok_or_else(|| {
            Error::request("output -: raw frames need --pix-fmt (or --out-pix-fmt): rgb24, rgb48le, rgbf32le, gbrpf32le")
        })?;
        if a.precision.is_some() || a.mips || a.compression.is_some() {
            return Err(Error::request(
                "output -: raw frames carry --pix-fmt's precision, no mips and no compression; leave out --precision, --mips and --compression",
            ));
        }
        Output::Pipe(fmt)
    } else {
        match Pattern::output(&a.output)? {
            Some(p) => Output::Files(p),
            None => match &input {
                Input::Files(_) if Pattern::parse(&a.input)?.is_none() => {
                    Output::File(a.output.clone())
                }
                _ => {
                    return Err(Error::request(format!(
                        "{}: many frames need an output pattern with %d or %0Nd (out/%05d.exr), or - for standard output",
                        a.output
                    )))
                }
            },
        }
    };

    // The request as one frame's conversion, checked by convert's own plan.
    let mut probe = a.clone();
    let first_number = first_of_all.as_ref().map_or(0, |fr| fr.number);
    probe.input = match &first_of_all {
        Some(fr) => fr.path.to_string_lossy().into_owned(),
        None => "-".into(),
    };
    probe.output = match &output {
        Output::Files(p) => p.path(first_number).to_string_lossy().into_owned(),
        Output::File(s) => s.clone(),
        // A pipe's frames are packed pictures: checked as an EXR of the same layout.
        Output::Pipe(_) => "frame.exr".into(),
    };
    let mut plan = match output {
        Output::Pipe(_) => Plan::unwritten(&probe)?,
        _ => Plan::new(&probe, mirrorball_io::Folders::MakeOne)?,
    };
    // `--for`'s engine axes: frames are made by one planned `Remap`, so a cube output takes
    // them as the rotation they are (its texel centres map to texel centres).
    if !plan.orient.is_identity() {
        plan.resample.rotation = plan.resample.rotation.then(plan.orient.rotation());
        plan.orient = mirrorball_core::AxisMap::IDENTITY;
    }
    let dst: Projection = plan
        .to
        .build(None)
        .map_err(|e| crate::spec::bad("--to", e))?;
    if matches!(output, Output::Pipe(_))
        && dst.layer_count() > 1
        && plan.save.layout == Some(Layout::Separate)
    {
        return Err(Error::request(
            "output -: a raw frame is one picture; give a packed --layout (hcross, vcross, hstrip, vstrip)",
        ));
    }
    if let (Some((at, len)), Some(s)) = (empty_slice, shard) {
        hooks.note(&format!(
            "--shard {}/{}: frames {at}..{at} of {len}: this slice is empty, nothing to do",
            s.index, s.count
        ));
        return Ok(());
    }

    // Frames from files: outputs named, checked against every input, and those done already.
    let log = Log {
        on: r.json,
        to_stderr: matches!(output, Output::Pipe(_)),
    };
    let outputs_of = |path: &Path| -> Vec<PathBuf> {
        let s = path.to_string_lossy();
        save::layer_files(&s, dst.layer_count(), &plan.save)
            .unwrap_or_else(|| vec![path.to_path_buf()])
    };
    let settings = record::settings(r);
    let mut made = record::Made::default();
    let (mut skipped, mut unknown, mut again) = (0u64, 0u64, 0u64);
    let input = match input {
        Input::Files(frames) => {
            let mut dirs = std::collections::HashMap::new();
            let inputs: HashSet<PathBuf> = frames
                .iter()
                .map(|fr| resolved(&fr.path, &mut dirs))
                .collect();
            let mut todo = Vec::with_capacity(frames.len());
            for fr in frames {
                let outs = match &output {
                    Output::Files(p) => outputs_of(&p.path(fr.number)),
                    Output::File(s) => outputs_of(Path::new(s)),
                    Output::Pipe(_) => Vec::new(),
                };
                if let Some(o) = outs
                    .iter()
                    .find(|o| inputs.contains(&resolved(o, &mut dirs)))
                {
                    return Err(Error::request(format!(
                        "{}: frame {}'s output would overwrite an input frame; choose another name or folder",
                        o.display(),
                        fr.number
                    )));
                }
                if !r.overwrite && !outs.is_empty() && outs.iter().all(|o| o.exists()) {
                    let verdict = made.verdict(&outs[0], record::stamp(&settings, &fr.path));
                    if verdict == Verdict::Other {
                        again += 1;
                    } else {
                        skipped += 1;
                        unknown += u64::from(verdict == Verdict::Unknown);
                        log.line(
                            json!({"frame": fr.number, "input": fr.path, "output": outs[0]}),
                            Status::Skipped,
                            Default::default(),
                            None,
                        );
                        continue;
                    }
                }
                todo.push(fr);
            }
            for line in record::kept_lines("frame", skipped, unknown, again) {
                hooks.note(&line);
            }
            if todo.is_empty() {
                return Ok(());
            }
            Input::Files(todo)
        }
        pipe => pipe,
    };
    let _folder = match &output {
        Output::Files(p) => MadeFolder::for_output(&p.path(first_number))?,
        Output::File(s) => MadeFolder::for_output(Path::new(s))?,
        Output::Pipe(_) => MadeFolder(None),
    };
    convert_frames(r, hooks, &plan, dst, input, output, log, skipped)
}

/// The output folder, made for the frames when missing (`save::make_folder`); removed again
/// if the run leaves it empty (it failed before its first frame).
struct MadeFolder(Option<PathBuf>);

impl MadeFolder {
    fn for_output(out: &Path) -> Result<MadeFolder, Error> {
        save::make_folder(out).map(MadeFolder)
    }
}

impl Drop for MadeFolder {
    fn drop(&mut self) {
        if let Some(dir) = &self.0 {
            mirrorball_io::keep_folder(dir);
            let _ = std::fs::remove_dir(dir); // only when empty
        }
    }
}

/// Reads frames one after another.
struct Reader<'a> {
    hooks: &'a dyn Hooks,
    plan: &'a Plan,
    input: Input,
    /// Files: the next frame's position; pipe: frames read.
    at: usize,
    stdin: std::io::Stdin,
    bytes: Vec<u8>,
    /// The pipe's projection and layout (of each eye), once decided by the first frame.
    decided: Option<(Projection, Layout)>,
    /// How the input pictures hold their eyes, once the first frame is read.
    stereo: Option<Stereo>,
    limits: mirrorball_io::Limits,
}

impl Reader<'_> {
    /// The next raw frame's bytes as they came, into `spare` where one came back: for a
    /// converter that reads them as codes (`PixFmt::codes`). A pipe's only.
    fn next_codes(&mut self, spare: Option<Vec<u8>>) -> Option<Result<(Meta, Vec<u8>), Error>> {
        let Input::Pipe { w, h, fmt } = self.input else {
            unreachable!("codes are read from a pipe");
        };
        let n = self.at as u64;
        let mut bytes = spare.unwrap_or_default();
        bytes.resize(fmt.frame_bytes(w, h), 0);
        match pipe::read_frame(&mut self.stdin, &mut bytes, n) {
            Ok(false) => None,
            Err(e) => Some(Err(e)),
            Ok(true) => {
                self.at += 1;
                Some(Ok((meta(n, format!("frame {n} of standard input")), bytes)))
            }
        }
    }

    fn next(&mut self, spare: Option<Eyes>) -> Option<Result<(Meta, Eyes), Error>> {
        match &self.input {
            Input::Files(frames) => {
                let fr = frames.get(self.at)?.clone();
                self.at += 1;
                Some(self.read_file(&fr))
            }
            Input::Pipe { w, h, fmt } => {
                let (w, h, fmt) = (*w, *h, *fmt);
                let n = self.at as u64;
                let stdin = &mut self.stdin;
                self.bytes.resize(fmt.frame_bytes(w, h), 0);
                match pipe::read_frame(stdin, &mut self.bytes, n) {
                    Ok(false) => return None,
                    Ok(true) => {}
                    Err(e) => return Some(Err(e)),
                }
                self.at += 1;
                Some(self.decode(n, w, h, fmt, spare))
            }
        }
    }

    fn read_file(&mut self, fr: &Frame) -> Result<(Meta, Eyes), Error> {
        let name = fr.path.to_string_lossy().into_owned();
        let mut src = load::load_eyes(
            &name,
            self.plan.input.from.as_ref(),
            self.plan.input.layout,
            (self.plan.in_stereo, self.plan.stereo),
            &self.limits,
        )?;
        self.stereo.get_or_insert(src.stereo);
        let lines = src.prepare(&name, self.plan.input.keep_invalid);
        // What was decided, for the first frame; warnings for every frame.
        lines
            .iter()
            .enumerate()
            .filter(|(i, _)| self.at == 1 || *i > 0)
            .for_each(|(_, l)| self.hooks.note(l));
        Ok((
            meta(fr.number, name),
            std::iter::once(src.env).chain(src.right).collect(),
        ))
    }

    fn decode(
        &mut self,
        n: u64,
        w: u32,
        h: u32,
        fmt: PixFmt,
        spare: Option<Eyes>,
    ) -> Result<(Meta, Eyes), Error> {
        let name = format!("frame {n} of standard input");
        let stereo = self.plan.in_stereo.unwrap_or_default();
        self.stereo = Some(stereo);
        let reads = stereo.eyes_read(self.plan.stereo);
        // A one-picture map's layer comes back whole; unpacked layouts and eyes are cut
        // afresh.
        let mut img = match (spare, self.decided) {
            (Some(mut eyes), Some((_, Layout::Separate))) if stereo == Stereo::Mono => {
                eyes.swap_remove(0).into_layers().swap_remove(0)
            }
            _ => Image::new(w, h, 3),
        };
        let invalid = fmt.decode(&self.bytes, &mut img);
        let mut eyes = match self.decided {
            Some((proj, layout)) => stereo
                .split(img, reads)
                .map_err(|e| Error::request(format!("{name}: {e}")))?
                .into_iter()
                .map(|eye| {
                    layout
                        .unpack_owned(eye, proj)
                        .map_err(|e| Error::input(format!("{name}: {e}")))
                })
                .collect::<Result<Eyes, Error>>()?,
            None => {
                let (left, right, decided) = load::interpret_eyes(
                    "-",
                    img,
                    (stereo, reads),
                    self.plan.input.from.as_ref(),
                    self.plan.input.layout,
                    None,
                    None,
                    |_| String::new(),
                )?;
                let layout = match self.plan.input.layout {
                    Some(l) => l,
                    None => Layout::from_extent(left.width(), left.height(), left.layers().len())
                        .map(|l| l.0)
                        .unwrap_or(Layout::Separate),
                };
                self.hooks.note(&format!(
                    "reading {w}x{h} {fmt} frames from standard input: {} — {decided}",
                    left.projection().name()
                ));
                self.decided = Some((*left.projection(), layout));
                std::iter::once(left).chain(right).collect()
            }
        };
        let keep = self.plan.input.keep_invalid;
        if let Some(warning) = load::zero_invalid(&name, &mut eyes, invalid, keep) {
            self.hooks.note(&warning);
        }
        Ok((meta(n, name), eyes))
    }
}

/// What a plan is made for: the source's projection, layer extent and layer count, and the
/// output's layer extent.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Shape {
    from: Projection,
    extent: (u32, u32),
    layers: usize,
    out: (u32, u32),
}

impl Shape {
    fn of(src: &EnvMap, out: (u32, u32)) -> Shape {
        Shape {
            from: *src.projection(),
            extent: (src.width(), src.height()),
            layers: src.layers().len(),
            out,
        }
    }

    fn plan(&self, dst: Projection, plan: &Plan) -> Remap {
        Remap::with_extent(
            self.from,
            self.extent,
            self.layers,
            dst,
            self.out,
            &plan.resample,
        )
    }
}

/// How a pipe writes its frames: the layout, where each packed texel of a 2d frame comes
/// from (stereo pairs are packed frame by frame), and the pixel format; `None` for files.
fn pipe_packing(
    plan: &Plan,
    output: &Output,
    dst: Projection,
    (w, h): (u32, u32),
) -> Option<(Layout, Option<Packing>, PixFmt)> {
    let Output::Pipe(fmt) = output else {
        return None;
    };
    let layout = plan
        .save
        .layout
        .unwrap_or_else(|| Layout::default_for(dst.kind()));
    let packing = (plan.stereo == Stereo::Mono)
        .then(|| Packing::new(layout, dst, (w, h)))
        .flatten();
    Some((layout, packing, *fmt))
}

/// The conversion of frames of `shape`: its plan, laid out as the packed picture where the
/// packing turns cells (EAC: [`Packing::lay_out`], the plan of the faces let go), with what
/// encodes that picture's rows.
fn plan_frames(
    shape: &Shape,
    dst: Projection,
    plan: &Plan,
    packing: Option<&Packing>,
) -> (Remap, Option<Picture>) {
    let remap = shape.plan(dst, plan);
    match packing {
        Some(p) if !p.along_rows() => {
            let (laid, picture) = p.lay_out(&remap, &dst);
            (laid, Some(picture))
        }
        _ => (remap, None),
    }
}

/// The conversion for a `w`×`h` raw frame ([`plan_frames`]), decided as the pipe's first
/// frame will be (its shape alone decides it): `None` where that decision fails or the
/// frames would not fit in memory (the real frame then says why, before anything of this
/// size is made).
fn plan_for_blank(
    plan: &Plan,
    output: &Output,
    dst: Projection,
    w: u32,
    h: u32,
) -> Option<(Shape, Remap, Option<Picture>)> {
    let frame = budget::f32_texels(w as u64 * h as u64, 3);
    budget::check("", 0, FRAMES_IN_FLIGHT * frame, "").ok()?;
    let stereo = plan.in_stereo.unwrap_or_default();
    let (left, _, _) = load::interpret_eyes(
        "-",
        Image::new(w, h, 3),
        (stereo, stereo.eyes_read(plan.stereo)),
        plan.input.from.as_ref(),
        plan.input.layout,
        None,
        None,
        |_| String::new(),
    )
    .ok()?;
    let size = plan
        .size
        .unwrap_or_else(|| save::default_size(&left, dst.kind()));
    let shape = Shape::of(&left, dst.layer_extent(size));
    drop(left);
    let packed = pipe_packing(plan, output, dst, shape.out);
    let packing = packed.as_ref().and_then(|(_, p, _)| p.as_ref());
    let (remap, picture) = plan_frames(&shape, dst, plan, packing);
    Some((shape, remap, picture))
}

/// The rows `remap` makes of a coded pipe's source frame: from its maps, or from its bytes
/// read as codes (`w`×`h` frames of `fmt`).
fn source_rows<'a>(
    remap: &'a Remap,
    (w, h, fmt): (u32, u32, PixFmt),
    m: &Meta,
    src: &'a Source,
) -> Result<mirrorball_core::RemapRows<'a>, Error> {
    match src {
        Source::Maps(eyes) => remap.rows(&eyes[0]),
        Source::Codes(c) => {
            let codes = fmt
                .codes(c, w, h)
                .ok_or_else(|| Error::input(format!("{}: not one {w}x{h} {fmt} frame", m.input)))?;
            remap.rows_coded(codes)
        }
    }
    .map_err(|e| pipeline::misfit(m, e))
}

/// A source frame as the coded pipe's converter takes it.
enum Source {
    /// Decoded maps (the first frame, read to decide what the frames are).
    Maps(Eyes),
    /// A raw frame's bytes as they came, read as codes.
    Codes(Vec<u8>),
}

fn meta(number: u64, input: String) -> Meta {
    Meta { number, input }
}

#[allow(clippy::too_many_arguments)]
fn convert_frames(
    r: &FramesRequest,
    hooks: &dyn Hooks,
    plan: &Plan,
    dst: Projection,
    input: Input,
    output: Output,
    log: Log,
    skipped: u64,
) -> Result<(), Error> {
    let total = match &input {
        Input::Files(fr) => fr.len() as u64,
        Input::Pipe { .. } => 0,
    };
    let mut reader = Reader {
        hooks,
        plan,
        input,
        at: 0,
        stdin: std::io::stdin(),
        bytes: Vec::new(),
        decided: None,
        stereo: None,
        limits: mirrorball_io::Limits::default(),
    };
    let t0 = Instant::now();
    // Raw frames cross pipes in 1 MiB rounds, not 64 KiB ones (io's `widen_pipe`).
    if matches!(reader.input, Input::Pipe { .. }) {
        mirrorball_io::widen_pipe(std::io::stdin(), mirrorball_io::PIPE_BYTES);
    }
    if matches!(output, Output::Pipe(_)) {
        mirrorball_io::widen_pipe(std::io::stdout(), mirrorball_io::PIPE_BYTES);
    }
    // A pipe's frames have the shape --in-size says, so the conversion is planned while the
    // first frame is on its way (the producer starting and sending it), and used when that
    // frame turns out to have the shape it was planned for (else planned again).
    let blank = match &reader.input {
        Input::Pipe { w, h, .. } => Some((*w, *h)),
        Input::Files(_) => None,
    };
    let (first, early) = std::thread::scope(|s| {
        let output = &output;
        let early = blank.map(|(w, h)| s.spawn(move || plan_for_blank(plan, output, dst, w, h)));
        let first = reader.next(None);
        (first, early.and_then(|e| e.join().ok().flatten()))
    });
    let Some(first) = first else {
        return Err(Error::input("standard input ended before the first frame"));
    };
    let (meta0, eyes0) = first?;
    let from = reader.stereo.unwrap_or_default();
    let src0 = &eyes0[0];
    let size = plan
        .size
        .unwrap_or_else(|| save::default_size(src0, dst.kind()));
    let (w, h) = dst.layer_extent(size);
    let c = src0.channels();
    let shape0 = Shape::of(src0, (w, h));
    let packed = pipe_packing(plan, &output, dst, (w, h));
    let packing = packed.as_ref().and_then(|(_, p, _)| p.as_ref());
    let (remap, picture) = match early {
        Some((shape, remap, picture)) if shape == shape0 => (remap, picture),
        _ => plan_frames(&shape0, dst, plan, packing),
    };
    let frame_bytes = |env_texels: u64| budget::f32_texels(env_texels, c as u64);
    let source = frame_bytes(
        src0.width() as u64
            * src0.height() as u64
            * src0.layers().len() as u64
            * eyes0.len() as u64,
    );
    let out_eyes = plan.stereo.eyes();
    let made = frame_bytes(w as u64 * h as u64 * dst.layer_count() as u64 * out_eyes as u64);
    // The frame being written is packed into a picture (a file's layout; a pair's eyes
    // joined for a pipe).
    let written = match &output {
        Output::Files(p) => save::write_bytes(
            &p.path(meta0.number).to_string_lossy(),
            dst.kind(),
            (w, h, dst.layer_count()),
            (out_eyes, c),
            &plan.save,
        ),
        Output::File(f) => save::write_bytes(
            f,
            dst.kind(),
            (w, h, dst.layer_count()),
            (out_eyes, c),
            &plan.save,
        ),
        Output::Pipe(_) if out_eyes > 1 => 2 * made,
        Output::Pipe(_) => 0,
    };
    // The pipeline's frames in flight, source and output, the plan, and the picture being
    // written.
    budget::check(
        &format!("frames of {} {w}x{h}x{}", dst.name(), dst.layer_count()),
        0,
        FRAMES_IN_FLIGHT * (source + made) + remap.memory_bytes() as u64 + written,
        "a smaller --size",
    )?;
    if let Some((layout, _, fmt)) = &packed {
        let (pw, ph) = if *layout == Layout::Separate {
            (w, h)
        } else {
            layout.extent(dst.layer_count(), w, h)
        };
        let (pw, ph) = plan.stereo.extent(pw, ph);
        hooks.note(&format!(
            "writing {pw}x{ph} {fmt} frames to standard output: {} {w}x{h}{} ({layout}{})",
            dst.name(),
            times(dst.layer_count()),
            match plan.stereo {
                Stereo::Mono => String::new(),
                s => format!(", each eye of a {s} pair"),
            }
        ));
    }
    // A raw frame of integer codes that is the source's one layer as it is (no eyes to
    // split, no layout to unpack, no lens overlap to blend) is read by the plan as it came:
    // no float copy of it is made (`Remap::rows_coded`: the same bytes out).
    let coded = match (&reader.input, &packed) {
        (Input::Pipe { w, h, fmt }, Some((_, Some(p), _)))
            if fmt.has_codes()
                && remap.takes_codes()
                && from == Stereo::Mono
                && eyes0.len() == 1
                && matches!(reader.decided, Some((_, Layout::Separate)))
                && (src0.width(), src0.height()) == (*w, *h) =>
        {
            Some((*w, *h, *fmt))
        }
        _ => None,
    };
    // Frames are encoded as their rows are made: a strip's or a cross's from its layers'
    // rows, turned cells' (EAC) from the plan laid out as the packed picture.
    let encode =
        |fmt: PixFmt, packing: &Packing, rows: &RemapRows, bytes: &mut Vec<u8>| match &picture {
            Some(p) => p.encode_rows(fmt, rows, bytes),
            None => packing.encode_rows(fmt, rows, bytes),
        };
    let t_plan = t0.elapsed();
    let settings = record::settings(r);

    let fresh = || -> Eyes {
        (0..plan.stereo.eyes())
            .map(|_| {
                let layers = (0..dst.layer_count())
                    .map(|_| Image::new(w, h, c))
                    .collect();
                EnvMap::new(dst, layers).expect("layers of the plan's shape")
            })
            .collect()
    };
    let mut first = Some((meta0, eyes0));
    let stdout = std::io::stdout();
    let logged = |m: &Meta, out: String, t: Instant| {
        log.line(
            json!({"frame": m.number, "input": m.input, "output": out}),
            Status::Done,
            t.elapsed(),
            None,
        );
    };
    let mut bytes = Vec::new();
    let mut put = |m: &Meta, eyes: &Eyes| -> Result<(), Error> {
        let t = Instant::now();
        let out: String = match (&output, &packed) {
            (Output::Pipe(_), Some((layout, packing, fmt))) => {
                // A 2d frame's packing makes its rows as they are encoded (below), so
                // only stereo pairs come here, packed whole.
                debug_assert!(packing.is_none());
                let pic = save::pack_eyes(eyes, plan.stereo, *layout)
                    .map_err(|e| e.context(format!("--layout {layout}")))?;
                Packing::single(pic.width(), pic.height()).encode_layers(
                    *fmt,
                    std::slice::from_ref(&pic),
                    &mut bytes,
                );
                pipe::write_frame(&mut stdout.lock(), &bytes, m.number)?;
                "-".into()
            }
            (Output::Files(p), _) => {
                save_frame(eyes, &p.path(m.number), (plan, hooks), &m.input, &settings)?
            }
            (Output::File(s), _) => {
                save_frame(eyes, Path::new(s), (plan, hooks), &m.input, &settings)?
            }
            _ => unreachable!("a pipe has its format"),
        };
        logged(m, out, t);
        Ok(())
    };
    let t1 = Instant::now();
    let mut done = None;
    hooks.progress("frames", total, &mut |counter| {
        let counted = AtomicU64::new(0);
        let mut next = |spare: Option<Eyes>| first.take().map(Ok).or_else(|| reader.next(spare));
        let mut put_bytes = |m: &Meta, bytes: &Vec<u8>| {
            let t = Instant::now();
            pipe::write_frame(&mut stdout.lock(), bytes, m.number)?;
            logged(m, "-".into(), t);
            counter.fetch_add(1, Ordering::Relaxed);
            Ok(())
        };
        let r = match &packed {
            // Rows made from the frame's codes and encoded together: no float copy of the
            // source frame or of the output frame (the first frame, read to decide the
            // projection, is converted from its maps: the same bytes).
            Some((_, Some(packing), fmt)) if coded.is_some() => {
                let codes = coded.expect("a coded pipe");
                let mut first = first.take().map(|(m, eyes)| (m, Source::Maps(eyes)));
                let mut next_codes = |spare: Option<Source>| {
                    if let Some(f) = first.take() {
                        return Some(Ok(f));
                    }
                    let spare = match spare {
                        Some(Source::Codes(bytes)) => Some(bytes),
                        _ => None,
                    };
                    reader
                        .next_codes(spare)
                        .map(|r| r.map(|(m, bytes)| (m, Source::Codes(bytes))))
                };
                pipeline::run(
                    &mut next_codes,
                    &|m: &Meta, src: &Source, bytes: &mut Vec<u8>| {
                        let rows = source_rows(&remap, codes, m, src)?;
                        encode(*fmt, packing, &rows, bytes);
                        Ok(())
                    },
                    &Vec::new,
                    &mut put_bytes,
                    &counted,
                )
            }
            // Rows made and encoded together: no float copy of the output frame.
            Some((_, Some(packing), fmt)) => pipeline::run(
                &mut next,
                &|m: &Meta, src: &Eyes, bytes: &mut Vec<u8>| {
                    let rows = remap.rows(&src[0]).map_err(|e| pipeline::misfit(m, e))?;
                    encode(*fmt, packing, &rows, bytes);
                    Ok(())
                },
                &Vec::new,
                &mut put_bytes,
                &counted,
            ),
            _ => pipeline::run(
                &mut next,
                &|m: &Meta, src: &Eyes, out: &mut Eyes| {
                    pipeline::convert_eyes((&remap, from), m, src, out)
                },
                &fresh,
                &mut |m: &Meta, e: &Eyes| {
                    put(m, e)?;
                    counter.fetch_add(1, Ordering::Relaxed);
                    Ok(())
                },
                &counted,
            ),
        };
        done = Some((r, counted.load(Ordering::Relaxed)));
    });
    let (result, n) = done.expect("the work ran");
    let secs = t1.elapsed().as_secs_f64();
    {
        hooks.note(&format!(
            "{} to {} {w}x{h}{} in {secs:.2}s ({:.2} frames/s; planned in {:.2}s){}",
            mirrorball_core::count(n, "frame"),
            dst.name(),
            times(dst.layer_count()),
            n as f64 / secs.max(1e-9),
            t_plan.as_secs_f64(),
            if skipped > 0 {
                format!("; {skipped} skipped, their outputs exist")
            } else {
                String::new()
            }
        ));
    }
    result
}

/// Writes one frame's file(s) through io's atomic writes and records how it was made (from
/// `input` with `settings`: `record.rs`); the name for the log.
fn save_frame(
    eyes: &[EnvMap],
    path: &Path,
    (plan, hooks): (&Plan, &dyn Hooks),
    input: &str,
    settings: &str,
) -> Result<String, Error> {
    let s = path.to_string_lossy().into_owned();
    let saved = save::save_eyes(eyes, plan.stereo, &s, &plan.save)?;
    if let Some(line) = plan.clipped_line(&s, &saved.report) {
        hooks.note(&line);
    }
    if let Some(first) = saved.files.first() {
        record::note(first, record::stamp(settings, Path::new(input)))?;
    }
    Ok(s)
}
