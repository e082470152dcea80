//! `mirrorball`: make, convert and inspect environment maps.
//!
//! Raw arguments become a validated plan (projection specs parsed, output container and
//! layout checked, folders checked) before any file is read or any work starts.

mod commands;
mod error;
mod load;
mod progress;
mod save;
mod spec;

use clap::{Args, Parser, Subcommand};
use error::CliError;
use std::process::ExitCode;

/// Environment (reflection) maps: convert between world projections, inspect them.
#[derive(Parser, Debug)]
#[command(name = "mirrorball", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Convert an environment map to another projection, size, layout or file format.
    Convert(ConvertArgs),
    /// Describe an environment map: projection, size, layout, radiance statistics.
    Info(InfoArgs),
    /// Compare two environment maps (the second is converted to the first's projection and
    /// size) and print the log-domain PSNR.
    Compare(CompareArgs),
    /// Convert a bundled HDR environment into every projection and write previews.
    Demo(DemoArgs),
}

/// How to read an input file.
#[derive(Args, Debug, Clone)]
pub struct InputArgs {
    /// Projection of the input, `NAME[:key=value…]` (guessed from the file when omitted).
    /// Names: latlong, cube, sphere, paraboloid, continuous-cube, mercator, angular, fisheye,
    /// octahedral, equal-area-octahedral (aliases: equirect, cubemap, matcap, probe, …).
    /// Keys: look=+x|-z|x,y,z  fov=DEG  lens=equidistant|equisolid|stereographic|orthographic
    /// max-lat=DEG.
    #[arg(long, value_name = "PROJECTION")]
    from: Option<String>,
    /// Layout of the input's layers: separate, hcross, vcross, hstrip, vstrip.
    #[arg(long = "in-layout", value_name = "LAYOUT")]
    in_layout: Option<String>,
    /// Keep NaN, infinite and negative texels instead of replacing them by 0.
    #[arg(long)]
    keep_invalid: bool,
}

#[derive(Args, Debug)]
pub struct ConvertArgs {
    /// Input file (`{face}` in the name reads one file per layer: px nx py ny pz nz, or
    /// front back).
    input: String,
    /// Output file; the extension picks the container: .exr .hdr .png .jpg .ktx2 .dds.
    /// `{face}` in the name (or --layout separate) writes one file per layer.
    output: String,
    /// Output projection, `NAME[:key=value…]` (see --from).
    #[arg(long, value_name = "PROJECTION")]
    to: String,
    /// Face edge (cubes), width (lat-long, Mercator) or diameter (disk maps), in texels.
    /// Default: about the source's resolution.
    #[arg(long)]
    size: Option<u32>,
    /// Layout of the output's layers: separate, hcross, vcross, hstrip, vstrip.
    #[arg(long, value_name = "LAYOUT")]
    layout: Option<String>,
    #[command(flatten)]
    input_args: InputArgs,
    /// Turn the environment about +Y (degrees; positive turns it to the left).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    yaw: f64,
    /// Then about +X (degrees).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pitch: f64,
    /// Then about the view axis (degrees).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    roll: f64,
    /// Mirror the environment across a plane: x, y or z (z switches between right- and
    /// left-handed worlds). May be repeated.
    #[arg(long, value_name = "AXIS")]
    flip: Vec<String>,
    /// Exposure in stops (texels times 2^EV).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    exposure: f32,
    /// Texel precision: half, float (EXR/KTX2/DDS) or 8, 16 (PNG).
    #[arg(long)]
    precision: Option<String>,
    /// EXR compression: none, rle, zips, zip, piz, pxr24.
    #[arg(long, default_value = "zip")]
    compression: String,
    /// Write the full mip chain (KTX2/DDS).
    #[arg(long)]
    mips: bool,
    /// Most points per axis when integrating over an output texel (1 = plain bilinear).
    #[arg(long, default_value_t = 4)]
    max_samples: u32,
    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
}

#[derive(Args, Debug)]
pub struct InfoArgs {
    /// The file.
    input: String,
    #[command(flatten)]
    input_args: InputArgs,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The reference map.
    reference: String,
    /// The map to compare with it.
    test: String,
    /// Projection of the reference (guessed when omitted).
    #[arg(long)]
    from: Option<String>,
    /// Projection of the test map (guessed when omitted).
    #[arg(long = "test-from")]
    test_from: Option<String>,
}

#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Folder to write into (created if missing).
    #[arg(long, default_value = "mirrorball-demo")]
    out: String,
    /// Lat-long width of the largest outputs; other projections scale to match.
    #[arg(long, default_value_t = 1024)]
    size: u32,
    /// Exposure of the PNG previews, in stops.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    exposure: f32,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result: Result<(), CliError> = match cli.command {
        Command::Convert(a) => commands::convert::run(a),
        Command::Info(a) => commands::info::run(a),
        Command::Compare(a) => commands::compare::run(a),
        Command::Demo(a) => commands::demo::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("mirrorball: error: {e}");
            ExitCode::from(e.code as u8)
        }
    }
}
