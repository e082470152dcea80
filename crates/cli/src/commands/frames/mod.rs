//! `convert` over many pictures: frame sequences (printf patterns and globs), raw frames
//! through pipes, and manifests of jobs sliced into shards for many machines.
//!
//! - `pattern.rs` — what a file argument names: one file, `%05d`, or a glob.
//! - `pipe.rs` — raw frames on standard input and output, in ffmpeg's pixel formats;
//!   `packing.rs` — where each texel of a packed output frame comes from, planned once.
//! - `sequence.rs` — a sequence's plan (one `Remap` for all frames) and its sources and
//!   sinks; `pipeline.rs` — the bounded loop that reads, converts and writes at once.
//! - `manifest.rs` — JSON-lines or CSV manifests, each job a `convert` of its own;
//!   `shard.rs` — `--shard i/n`; `log.rs` — the one JSON line per frame or job.

mod manifest;

use mirrorball::frames::{log, pattern, pipe, record, shard, FramesRequest};

use crate::choice::names;
use crate::error::CliError;
use crate::ConvertArgs;
use clap::Args;
use pattern::Pattern;
pub use pipe::PixFmt;

/// `convert`'s flags for frames, pipes and batches.
#[derive(Args, Debug, Clone, Default)]
pub struct FramesArgs {
    /// Size of the raw frames read from standard input (input `-`), WIDTHxHEIGHT: the whole
    /// picture (both eyes of a stereo pair, --in-stereo).
    #[arg(long, value_name = "WxH")]
    pub in_size: Option<String>,
    /// Pixel format of raw frames through `-` (standard input and output), named as
    /// ffmpeg's -pix_fmt: rgb24, rgb48le (sRGB-coded, as PNG), rgbf32le or gbrpf32le
    /// (linear float).
    #[arg(long, value_name = "FORMAT", value_parser = names::<PixFmt>())]
    pub pix_fmt: Option<String>,
    /// Pixel format of the frames written to standard output, when not --pix-fmt's.
    #[arg(long, value_name = "FORMAT", value_parser = names::<PixFmt>())]
    pub out_pix_fmt: Option<String>,
    /// Run the jobs listed in FILE (JSON lines: {"input", "output", "options"}; or CSV:
    /// input,output,options), each as `convert INPUT OUTPUT <these flags> <options>`.
    #[arg(long, value_name = "FILE")]
    pub manifest: Option<String>,
    /// Run only slice I of N equal slices of the frames or the manifest's jobs, I counted
    /// from 0 (Slurm: --array=0-(N-1) and $SLURM_ARRAY_TASK_ID; Kubernetes indexed Jobs:
    /// $JOB_COMPLETION_INDEX).
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    /// Convert frames and jobs whose outputs exist again (by default they are skipped: an
    /// output exists only once it is complete, being renamed into place when written).
    #[arg(long)]
    pub overwrite: bool,
    /// Print one JSON line per frame or job (always for --manifest), on standard output, or
    /// on standard error when standard output carries frames.
    #[arg(long)]
    pub json: bool,
    /// Video files (.mp4 .m4v .mov .mkv .webm; built with `--features video`): the encoder,
    /// by FFmpeg's name as -c:v takes it: libx264 (the default; libvpx-vp9 for .webm),
    /// libx265, libvpx-vp9, libaom-av1, …
    #[arg(long, value_name = "ENCODER")]
    pub codec: Option<String>,
    /// Video files: the encoder's constant rate factor, as -crf (libx264's default 23).
    #[arg(long, value_name = "N")]
    pub crf: Option<u32>,
    /// Video files: the encoder's preset, as -preset (libx264: ultrafast … veryslow).
    #[arg(long, value_name = "NAME")]
    pub preset: Option<String>,
}

/// Video file extensions (`mirrorball_video::EXTENSIONS`, known without the feature too).
const VIDEO: &[&str] = &["mp4", "m4v", "mov", "mkv", "webm"];

/// Whether `path` names a video file.
fn is_video(path: &str) -> bool {
    std::path::Path::new(path)
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| VIDEO.contains(&e.to_ascii_lowercase().as_str()))
}

/// Converts a video file (the `video` feature).
#[cfg(feature = "video")]
fn video(a: &ConvertArgs) -> Result<(), CliError> {
    let r = mirrorball_video::VideoRequest {
        convert: super::convert::request(a)?,
        codec: a.frames.codec.clone(),
        crf: a.frames.crf,
        preset: a.frames.preset.clone(),
    };
    mirrorball_video::run(&r, &crate::progress::Printer { quiet: a.quiet })
}

/// Says how to get video files: this binary was built without them.
#[cfg(not(feature = "video"))]
fn video(a: &ConvertArgs) -> Result<(), CliError> {
    Err(CliError::request(format!(
        "{} {}: video files need mirrorball built with its `video` feature, on the system's \
         FFmpeg libraries: `apt-get install libavcodec-dev libavformat-dev libavutil-dev pkg-config \
         clang libclang-dev` \
         then `cargo install --path crates/cli --features video`; or pipe raw frames \
         (`ffmpeg -i in.mp4 -f rawvideo -pix_fmt rgb24 - | mirrorball convert - …`)",
        a.input, a.output
    )))
}

/// Runs `a` here when it is a sequence, a pipe or a manifest; `None` when it is a plain
/// conversion of one map.
pub fn route(a: &ConvertArgs) -> Option<Result<(), CliError>> {
    if a.frames.manifest.is_some() {
        return Some(manifest::run(a));
    }
    if is_video(&a.input) || is_video(&a.output) {
        return Some(video(a));
    }
    let f = &a.frames;
    let encoder = [
        ("--codec", f.codec.is_some()),
        ("--crf", f.crf.is_some()),
        ("--preset", f.preset.is_some()),
    ];
    if let Some((flag, _)) = encoder.iter().find(|(_, g)| *g) {
        return Some(Err(CliError::request(format!(
            "{flag} is for video files ({}); {} is not one",
            VIDEO.join(", "),
            a.output
        ))));
    }
    let many = || -> Result<bool, CliError> {
        Ok(a.input == "-"
            || a.output == "-"
            || Pattern::parse(&a.input)?.is_some()
            || Pattern::output(&a.output)?.is_some())
    };
    match many() {
        Ok(true) => Some(frames_request(a).and_then(|r| {
            mirrorball::frames::run(&r, &crate::progress::Printer { quiet: a.quiet })
        })),
        Ok(false) => single_only(a).err().map(Err),
        Err(e) => Some(Err(e)),
    }
}

/// Refuses the frames flags on a conversion of one file.
fn single_only(a: &ConvertArgs) -> Result<(), CliError> {
    let f = &a.frames;
    let given = [
        ("--in-size", f.in_size.is_some()),
        ("--pix-fmt", f.pix_fmt.is_some()),
        ("--out-pix-fmt", f.out_pix_fmt.is_some()),
        ("--shard", f.shard.is_some()),
    ];
    match given.iter().find(|(_, g)| *g) {
        Some((flag, _)) => Err(CliError::request(format!(
            "{flag} is for frames: a pattern (%05d, *), - for a pipe, or --manifest; {} is one file",
            a.input
        ))),
        None => Ok(()),
    }
}

/// `a`'s flags as the library's request of frames.
pub fn frames_request(a: &ConvertArgs) -> Result<FramesRequest, CliError> {
    let f = &a.frames;
    let pix_fmt = |flag: &str, given: &Option<String>| {
        given
            .as_deref()
            .map(|s| crate::choice::parse_flag::<PixFmt>(flag, s))
            .transpose()
    };
    Ok(FramesRequest {
        convert: super::convert::request(a)?,
        in_size: f
            .in_size
            .as_deref()
            .map(|s| pipe::parse_size("--in-size", s))
            .transpose()?,
        pix_fmt: pix_fmt("--pix-fmt", &f.pix_fmt)?,
        out_pix_fmt: pix_fmt("--out-pix-fmt", &f.out_pix_fmt)?,
        shard: f.shard.as_deref().map(shard::Shard::parse).transpose()?,
        overwrite: f.overwrite,
        json: f.json,
    })
}
