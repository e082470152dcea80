//! `mirrorball views IN OUT-DIR`: a panorama cut into a rig of pinhole views with the camera
//! files COLMAP and nerfstudio read. The flags become the library's `ViewsRequest`
//! (`mirrorball::views`), planned and run there.

use crate::error::CliError;
use crate::progress::Printer;
use crate::InputArgs;
use clap::Args;
use mirrorball::views::{self, ViewsPlan, ViewsRequest};

/// `--rig`'s long help, from the library's table of rigs.
fn rig_help() -> String {
    views::rig::help()
}

#[derive(Args, Debug)]
pub struct ViewsArgs {
    /// The panorama (any projection mirrorball reads; `{face}` reads one file per layer), or
    /// a sequence: a pattern (in/%05d.exr, 'in/*.jpg'), one rig over every frame.
    input: String,
    /// The folder to write into (made if missing; its parent must exist): images/VIEW/,
    /// masks/VIEW/, sparse/0/ (COLMAP), rig_config.json, transforms.json (nerfstudio).
    out_dir: String,
    /// The rig: cube, cube-96, ringN, or a .json file of views (--help lists them).
    #[arg(long, default_value = "cube", long_help = rig_help())]
    rig: String,
    /// Each view's size, W or WxH: the width of views the rig gives none, the height of
    /// views that set neither height nor vfov (default: square pixels at about the
    /// panorama's resolution).
    #[arg(long, value_name = "W[xH]", value_parser = mirrorball::size::parse_extent, allow_hyphen_values = true)]
    size: Option<(i64, Option<i64>)>,
    /// The views' container: png (8-bit), png16 (16-bit PNG), jpg or exr (half float).
    #[arg(long, default_value = "png")]
    format: String,
    /// Write every view's mask (by default masks are written only when some pixel of a
    /// view lies outside what the panorama covers, or outside --mask).
    #[arg(long)]
    masks: bool,
    /// A mask drawn on the panorama, the panorama's size: white where pixels count, black
    /// where they do not (a tripod, the photographer); resampled into every view's mask.
    #[arg(long, value_name = "FILE")]
    mask: Option<String>,
    /// The most integration points per texel side (1 turns antialiasing off).
    #[arg(
        long,
        default_value_t = mirrorball_core::ResampleOptions::default().max_samples,
        value_parser = clap::value_parser!(u32).range(1..=16)
    )]
    max_samples: u32,
    /// Replace files in OUT-DIR that mirrorball did not write (by default such a file is
    /// left alone and the run refused; files an earlier run wrote are replaced, and those
    /// it wrote that this run does not are removed).
    #[arg(long)]
    overwrite: bool,
    #[command(flatten)]
    input_args: InputArgs,
    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
}

pub fn run(a: ViewsArgs) -> Result<(), CliError> {
    let request = ViewsRequest {
        input: a.input,
        out_dir: a.out_dir,
        input_plan: crate::commands::input_plan(&a.input_args)?,
        rig: a.rig,
        size: a.size,
        format: a.format,
        masks: a.masks,
        mask: a.mask,
        max_samples: a.max_samples,
        overwrite: a.overwrite,
    };
    let plan = ViewsPlan::new(&request)?;
    views::run(&plan, &Printer { quiet: a.quiet })?;
    Ok(())
}
