//! `mirrorball`: make, convert and inspect environment maps.
//!
//! Raw arguments become a validated plan (projection specs parsed, output container and
//! layout checked, folders checked) before any file is read or any work starts.

mod choice;
mod commands;
mod error;
mod progress;

use mirrorball::{budget, fit, guard, load, save, size, spec};

use choice::{names, names_of};
use clap::parser::ValueSource;
use clap::{Args, CommandFactory, FromArgMatches, Parser, Subcommand};
use error::CliError;
use mirrorball_core::{Layout, Lens};
use mirrorball_filter::LobeKind;
use mirrorball_io::{ExrCompression, Precision};
use mirrorball_render::tone::Tone;
use mirrorball_render::{Attach, Indexing, ENVIRONMENT_FILTERS};
use std::process::ExitCode;

#[global_allocator]
static ALLOC: mirrorball_io::HugePages = mirrorball_io::HugePages;

/// Environment (reflection) maps: convert between world projections, inspect them.
#[derive(Parser, Debug)]
#[command(name = "mirrorball", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Refuse a job estimated to need more memory than this (8G, 512M; default: the
    /// memory available when it starts).
    #[arg(long, global = true, value_name = "SIZE", value_parser = budget::parse_bytes)]
    max_memory: Option<u64>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Convert an environment map to another projection, size, layout or file format.
    Convert(ConvertArgs),
    /// Describe an environment map: projection, size, layout, radiance statistics.
    Info(InfoArgs),
    /// Compare two environment maps (the second is converted to the first's projection and
    /// size) and print the log-domain PSNR over the directions both cover.
    Compare(CompareArgs),
    /// Convert a bundled HDR environment into every projection and write previews.
    Demo(DemoArgs),
    /// Render environment-mapped objects with a chosen indexing mode (1 texgen, 2 per-vertex
    /// reflection, 3 per-pixel, 4 Greene's cones).
    Render(Box<RenderArgs>),
    /// Measure each projection's distortion and error exactly and write a report (HTML with
    /// SVG plots, the plots as SVG files, and the numbers as JSON).
    Analyze(AnalyzeArgs),
    /// Prefiltered lighting: a Lambert, Phong or GGX mip chain (KTX2/DDS cube, or one
    /// image per level), spherical-harmonic coefficients (JSON) and a preview sheet (PNG).
    Prefilter(PrefilterArgs),
    /// Engine-ready lighting: everything one engine needs for image-based lighting (its
    /// containers, encodings, axes and roughness-to-mip rule) and a README.md saying how to
    /// load it. `bake --for list` prints what each engine gets.
    Bake(BakeArgs),
    /// The viewport in a browser: a local web server (127.0.0.1, a token in the printed URL)
    /// drawing a scene or an environment with WebGL2 as `render` draws it.
    Studio(commands::studio::StudioArgs),
    /// Add, replace or remove the 360° metadata of an MP4/MOV without re-encoding: Spherical
    /// Video V2 (st3d, sv3d), optionally V1's XML; `info FILE.mp4` shows what a video has.
    Tag(commands::tag::TagArgs),
    /// Cut a panorama into a rig of pinhole views for photogrammetry and Gaussian
    /// splatting, with the camera files COLMAP (a text model, rig_config.json) and
    /// nerfstudio (transforms.json) read, and masks of what the panorama does not cover.
    Views(commands::views::ViewsArgs),
}

/// `--from`'s long help: the names from core's table of projections, then the keys.
fn from_help() -> String {
    format!(
        "Projection of the input, `NAME[:key=value…]` (guessed from the file when omitted).\n\
         Names:\n{}\
         Keys: look=+x|-z|x,y,z  fov=DEG  lens=equidistant|equisolid|stereographic|orthographic\n\
         max-lat=DEG  hfov=DEG vfov=DEG (cylinders, half-equirect, views)  d=NUM (pannini)\n\
         yaw=DEG pitch=DEG roll=DEG (views: right, up, about the view axis).",
        mirrorball_core::ProjectionKind::help_list()
    )
}

/// How to read an input file.
#[derive(Args, Debug, Clone)]
pub struct InputArgs {
    /// Projection of the input, `NAME[:key=value…]` (guessed from the file when omitted;
    /// --help lists the names and keys).
    #[arg(long, value_name = "PROJECTION", long_help = from_help())]
    from: Option<String>,
    /// Layout of the input's layers: hcross, vcross, hstrip, vstrip, separate, or v360's
    /// c3x2, c6x1, c1x6 (with `:forder=rludfb:frot=000000`) and eac.
    #[arg(long = "in-layout", value_name = "LAYOUT")]
    in_layout: Option<String>,
    /// Keep NaN, infinite and negative texels instead of replacing them by 0.
    #[arg(long)]
    keep_invalid: bool,
}

#[derive(Args, Debug, Clone)]
pub struct ConvertArgs {
    /// Input file (`{face}` in the name reads one file per layer: px nx py ny pz nz, or
    /// front back); frames: a pattern (in/%05d.exr, 'in/*.exr'), or - for raw frames on
    /// standard input.
    #[arg(
        required_unless_present = "manifest",
        default_value = "",
        hide_default_value = true
    )]
    input: String,
    /// Output file; the extension picks the container: .exr .hdr .png .jpg .ktx2 .dds.
    /// `{face}` in the name (or --layout separate) writes one file per layer; frames: a
    /// pattern (out/%05d.png), or - for raw frames on standard output.
    #[arg(
        required_unless_present = "manifest",
        default_value = "",
        hide_default_value = true
    )]
    output: String,
    /// Output projection, `NAME[:key=value…]` (see --from). Default, for one file: the
    /// input's projection, at the input's size unless --size (to change only the container
    /// or the layout); sequences, pipes and manifests need it.
    #[arg(
        long,
        value_name = "PROJECTION",
        default_value = "",
        hide_default_value = true
    )]
    to: String,
    /// Face edge (cubes), width (lat-long, Mercator, cylinders, Hammer, sinusoidal, views) or
    /// diameter (disk maps), in texels; one eye's, for a stereo pair (--stereo). WxH (as
    /// v360's w and h) for a flat view sets its vfov from the height (square pixels); for eac
    /// it is the picture's size (v360's eac at any size: 3840x2160); for other projections
    /// the height must be the one the width gives.
    /// Default: about the source's resolution (its one eye's).
    #[arg(long, value_name = "W[xH]", value_parser = size::parse_extent, allow_hyphen_values = true)]
    size: Option<(i64, Option<i64>)>,
    /// Layout of the output's layers: hcross, vcross, hstrip, vstrip, separate, or v360's
    /// c3x2, c6x1, c1x6 (with `:forder=rludfb:frot=000000`) and eac (EAC's default).
    #[arg(long, value_name = "LAYOUT")]
    layout: Option<String>,
    /// The input picture as a stereo pair, as FFmpeg v360's in_stereo: 2d (one eye), sbs
    /// (left eye | right eye), tb (left eye above the right). Each eye is read as --from and
    /// --in-layout say. Default: as the file records (a pair mirrorball wrote), else 2d.
    #[arg(long = "in-stereo", value_name = "MODE", value_parser = names::<mirrorball_core::Stereo>())]
    in_stereo: Option<String>,
    /// The output as a stereo pair, as v360's out_stereo: 2d (of a pair, the left eye), sbs
    /// or tb (of a 2d input, its one eye twice). --size and --layout are one eye's: the
    /// picture is twice as wide (sbs) or as tall (tb). One picture per frame (.exr .hdr .png
    /// .jpg, or a raw pipe).
    #[arg(long, value_name = "MODE", value_parser = names::<mirrorball_core::Stereo>())]
    stereo: Option<String>,
    #[command(flatten)]
    input_args: InputArgs,
    /// FFmpeg v360's options, as its filter takes them: IN:OUT[:key=value…], e.g.
    /// 'e:eac:yaw=30:pitch=20:rorder=ypr', 'e:c3x2:out_forder=fbudlr:w=1536:h=1024',
    /// 'e:flat:h_fov=90:v_fov=58.7:w=1280:h=720', 'dfisheye:e:ih_fov=190:iv_fov=190'. Means
    /// what v360 means (rotations, their order and flips, face orders and turns, fields of
    /// view, w and h, stereo modes); in place of --from, --in-layout, --to, --layout,
    /// --in-stereo, --stereo, --yaw, --pitch, --roll and --flip (refused beside it), and of
    /// --size when it has w and h. Without w and h the size is mirrorball's (--size). What
    /// mirrorball cannot make exactly (barrel, tsp, input flips, pads, …) is
    /// refused, naming the key; interp is accepted (every output texel is antialiased).
    #[arg(long, value_name = "OPTIONS")]
    v360: Option<String>,
    /// Turn the environment about +Y (degrees; positive turns it to the left).
    #[arg(long, value_parser = finite_f64, default_value_t = 0.0, allow_hyphen_values = true)]
    yaw: f64,
    /// Then about +X (degrees).
    #[arg(long, value_parser = finite_f64, default_value_t = 0.0, allow_hyphen_values = true)]
    pitch: f64,
    /// Then about the view axis (degrees).
    #[arg(long, value_parser = finite_f64, default_value_t = 0.0, allow_hyphen_values = true)]
    roll: f64,
    /// Mirror the environment across a plane: x, y or z (z switches between right- and
    /// left-handed worlds). May be repeated.
    #[arg(long, value_name = "AXIS", value_parser = names::<mirrorball_core::Axis>())]
    flip: Vec<String>,
    /// Turn the result into an engine's axes, as `bake --for` does (three mirrors x, bevy
    /// and unity mirror z, unreal turns to Z up, …): exact for a cube, a rotation otherwise;
    /// after --yaw, --pitch, --roll and --flip.
    #[arg(long = "for", value_name = "ENGINE", value_parser = names::<mirrorball_bake::Engine>())]
    engine: Option<String>,
    /// Exposure in stops (texels times 2^EV).
    #[arg(long, value_parser = exposure_stops, default_value_t = 0.0, allow_hyphen_values = true)]
    exposure: f32,
    /// Texel precision: half, float (EXR/KTX2/DDS) or 8, 16 (PNG).
    #[arg(long, value_parser = names::<Precision>())]
    precision: Option<String>,
    /// EXR compression (default zip; .exr outputs only).
    #[arg(long, value_parser = names::<ExrCompression>())]
    compression: Option<String>,
    /// Write the full mip chain (KTX2/DDS).
    #[arg(long)]
    mips: bool,
    /// Most points per axis when integrating over an output texel, 1..=16 (1 = plain
    /// bilinear).
    #[arg(
        long,
        default_value_t = mirrorball_core::ResampleOptions::default().max_samples,
        value_parser = clap::value_parser!(u32).range(1..=16)
    )]
    max_samples: u32,
    /// What the output's texels outside its picture's covered part hold: black (zero
    /// alpha), or the rim's value (so that filtering near the rim never darkens). Default:
    /// black for fisheye, dual fisheye, Hammer and sinusoidal (as v360), the rim for the
    /// sphere, angular and paraboloid maps a renderer samples
    #[arg(long, value_parser = names::<mirrorball_core::Outside>())]
    outside: Option<String>,
    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
    #[command(flatten)]
    frames: commands::frames::FramesArgs,
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
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
    /// Also write where they differ, in the reference's projection and layout: a .png heat
    /// map (black equal, white the largest difference) or an .exr of |ln(1+r) − ln(1+t)|.
    #[arg(long, value_name = "FILE")]
    diff: Option<String>,
}

#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Folder to write into (created if missing).
    #[arg(long, default_value = "mirrorball-demo")]
    out: String,
    /// Lat-long width of the largest outputs; other projections scale to match.
    #[arg(long, default_value_t = 1024, value_parser = size::parse, allow_hyphen_values = true)]
    size: i64,
    /// Exposure of the PNG previews, in stops.
    #[arg(long, value_parser = exposure_stops, default_value_t = 0.0, allow_hyphen_values = true)]
    exposure: f32,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// A scene file (.json or .toml, the same schema: meshes with model matrices, camera,
    /// environment, material, indexing); a flag given on the command line wins over it.
    scene: Option<String>,
    /// Output image: .png/.jpg (exposure, tone curve, sRGB) or .exr/.hdr (linear).
    #[arg(short, long, default_value = "render.png")]
    output: String,
    /// Object: sphere, torus, cube, quad, teapot, or a .glb/.gltf/.obj file (centred and
    /// scaled to unit size).
    #[arg(long, default_value = "sphere")]
    object: String,
    /// Tessellation of a built-in (sphere/torus segments, quad/cube cells per edge, teapot
    /// subdivisions per patch edge).
    #[arg(long)]
    tessellation: Option<u32>,
    /// Environment map file.
    #[arg(long)]
    env: Option<String>,
    #[command(flatten)]
    input_args: InputArgs,
    /// Convert the environment to this projection first (`NAME[:key=value…]`, as --from).
    #[arg(long, value_name = "PROJECTION")]
    env_as: Option<String>,
    /// Size for --env-as (face edge, width or diameter).
    #[arg(long, value_parser = size::parse, allow_hyphen_values = true)]
    env_size: Option<i64>,
    /// Indexing mode: 1|texgen, 2|vertex, 3|pixel, 4|cone.
    #[arg(long, default_value = "pixel", value_parser = names::<Indexing>())]
    mode: String,
    /// What the environment is attached to: world (view-independent) or eye.
    #[arg(long, default_value = "world", value_parser = names::<Attach>())]
    attach: String,
    /// Lookup filter: nearest, bilinear, trilinear or ewa (the last two filter each pixel's
    /// footprint, objects and background; mode 4 always filters: EWA unless trilinear).
    #[arg(long, default_value = "bilinear", value_parser = names_of(&ENVIRONMENT_FILTERS))]
    filter: String,
    // The help is an attribute, not a doc comment: rustdoc would read its brackets as links.
    #[arg(
        long,
        default_value = "mirror",
        help = "Material: mirror, fresnel, cheap-chrome, diffuse, \
                greene[:dc=R,G,B][:sc=R,G,B][:phong=EXP|:ggx=ROUGHNESS] (Greene's dc·D + sc·S \
                from prefiltered maps), \
                phong-map[:exponent=N][:light=X,Y,Z][:specular=R,G,B][:ambient=A] \
                (highlights from a sphere map of Phong intensities, light in eye space)"
    )]
    material: String,
    /// Tint of a mirror, base colour of fresnel/diffuse: r,g,b.
    #[arg(long, default_value = "1,1,1")]
    tint: String,
    /// Reflectance at normal incidence for fresnel.
    #[arg(long, value_parser = finite_f32, default_value_t = 0.04)]
    f0: f32,
    /// Camera position x,y,z.
    #[arg(long, default_value = "0,0,3.5", allow_hyphen_values = true)]
    eye: String,
    /// Point looked at x,y,z.
    #[arg(long, default_value = "0,0,0", allow_hyphen_values = true)]
    target: String,
    /// Up direction.
    #[arg(long, default_value = "+y", allow_hyphen_values = true)]
    up: String,
    /// Vertical field of view in degrees (perspective).
    #[arg(long, value_parser = finite_f32, default_value_t = 40.0)]
    fov: f32,
    /// Orthographic camera with this half height instead of perspective.
    #[arg(long, value_parser = finite_f32)]
    ortho: Option<f32>,
    /// Fisheye (Omnimax, Greene §10) camera with this full field of view in degrees: the
    /// scene is captured as a cube at --eye and resampled to a WIDTHxWIDTH fisheye picture.
    #[arg(long, value_parser = finite_f64)]
    fisheye: Option<f64>,
    /// Lens of --fisheye.
    #[arg(long, default_value = "equidistant", value_parser = names::<Lens>())]
    fisheye_lens: String,
    /// Near clipping distance.
    #[arg(long, value_parser = finite_f32, default_value_t = 0.05)]
    near: f32,
    /// Far clipping distance.
    #[arg(long, value_parser = finite_f32, default_value_t = 1000.0)]
    far: f32,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "640x480", allow_hyphen_values = true)]
    size: String,
    /// Supersampling: NxN samples per pixel.
    #[arg(long, default_value_t = 2)]
    ss: u32,
    /// Exposure in stops.
    #[arg(long, value_parser = exposure_stops, default_value_t = 0.0, allow_hyphen_values = true)]
    exposure: f32,
    /// Tone curve for PNG/JPEG.
    #[arg(long, default_value = "aces", value_parser = names::<Tone>())]
    tone: String,
    /// Draw objects over transparent black instead of the environment.
    #[arg(long)]
    no_background: bool,
    /// Camera-rotation motion blur of the background (Greene §9): the camera panned this
    /// many degrees (about its up axis) since the previous frame.
    #[arg(long, value_parser = finite_f32, allow_hyphen_values = true)]
    pan_blur: Option<f32>,
    /// Also write the diagnostic channels as float EXRs beside the image: -st (u, v,
    /// layer read), -reflect (world reflected vector), -normal, -depth (eye depth, window
    /// depth, coverage).
    #[arg(long)]
    aovs: bool,
    /// Also write NAME-diag.png: the environment map with the texels the image read marked,
    /// and the per-vertex texture coordinates and triangle edges drawn in texture space.
    #[arg(long)]
    diagnostics: bool,
    /// Render N frames orbiting the target about +Y (NAME-0000.png …).
    #[arg(long, default_value_t = 1)]
    turntable: u32,
    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
    /// The flags given on the command line (their ids), which win over the scene file's
    /// values; filled from clap's matches, not parsed.
    #[arg(skip)]
    given: Vec<String>,
}

#[derive(Args, Debug)]
pub struct AnalyzeArgs {
    /// Projection to analyse, `NAME[:key=value…]` (see `convert --from`); repeat for more.
    /// Default: every projection.
    #[arg(long = "projection", value_name = "PROJECTION")]
    projections: Vec<String>,
    /// The same edge size for every projection (cube face edge, lat-long width, disk
    /// diameter).
    #[arg(
        long,
        conflicts_with = "texel_budget",
        value_parser = size::parse,
        allow_hyphen_values = true
    )]
    size: Option<i64>,
    /// The same number of texels, all layers together, for every projection (a fair
    /// comparison: 1572864 = six 512² cube faces = one 1254² sphere map). Default: 1572864.
    #[arg(long, value_name = "TEXELS")]
    texel_budget: Option<u64>,
    /// Folder to write the report into (created if missing).
    #[arg(long)]
    out: String,
    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
}

#[derive(Args, Debug)]
pub struct PrefilterArgs {
    /// Input environment map (any projection; `{face}` reads one file per layer).
    input: String,
    /// Output: .ktx2 or .dds (a cube map with the whole chain), or .exr/.hdr/.png (one file
    /// per level: `{level}` in the name, or `_mip0`, `_mip1`, … added).
    output: String,
    /// The lobe: lambert (irradiance E/π), phong, or ggx (split-sum prefiltered radiance).
    #[arg(long, value_parser = names::<LobeKind>())]
    lobe: String,
    /// Face edge of level 0 (cubes; width or diameter for other projections). Default: 32
    /// for lambert; the source's resolution (a power of two, at most 512) otherwise.
    #[arg(long, value_parser = size::parse, allow_hyphen_values = true)]
    size: Option<i64>,
    /// Output projection (as --to of convert); KTX2/DDS hold cubes only.
    #[arg(long, default_value = "cube", value_name = "PROJECTION")]
    to: String,
    /// Number of mip levels (default: all, down to 1×1).
    #[arg(long)]
    levels: Option<usize>,
    /// Roughness of each level: linear (r = level/(levels−1)), ue4, filament, or a
    /// comma-separated list of roughness values, one per level.
    #[arg(long, default_value = "linear")]
    mapping: String,
    /// Phong exponents, one per level (`inf` is a mirror); default: 2/α² − 2 from the
    /// mapping's roughness.
    #[arg(long)]
    exponents: Option<String>,
    /// Importance samples per texel for the sharpest lobes (wider lobes take more).
    #[arg(long, default_value_t = 128)]
    samples: u32,
    /// Face size of the working cube the source is filtered from, 1..=4096 (default: as
    /// fine as the levels need, at most the source's resolution).
    #[arg(long)]
    cube_size: Option<u32>,
    /// Tame extreme texels first: none, clamp:MAX, soft:MAX, soft:KNEE:MAX (luminance);
    /// the energy removed is reported.
    #[arg(long, default_value = "none")]
    compress: String,
    #[arg(
        long,
        default_value = "none",
        help = "Window against spherical-harmonic ringing: none, hann[:W], lanczos[:W], auto \
                (the weakest Hann window with non-negative irradiance)"
    )]
    sh_window: String,
    /// How lambert maps are computed: exact (the brute-force sum, fast) or sh (nine
    /// coefficients, windowed by --sh-window).
    #[arg(
        long,
        default_value = "exact",
        value_parser = names::<mirrorball_filter::IrradianceMethod>()
    )]
    irradiance: String,
    /// Where to write the spherical-harmonic JSON (default: beside OUTPUT, .sh.json).
    #[arg(long)]
    sh: Option<String>,
    /// Do not write the spherical-harmonic JSON.
    #[arg(long)]
    no_sh: bool,
    /// Where to write the preview sheet (default: beside OUTPUT, _preview.png).
    #[arg(long)]
    preview: Option<String>,
    /// Do not write the preview sheet.
    #[arg(long)]
    no_preview: bool,
    /// Exposure of the preview sheet in stops (level 0's mean is shown at 18% grey).
    #[arg(long, value_parser = exposure_stops, default_value_t = 0.0, allow_hyphen_values = true)]
    preview_exposure: f32,
    /// Also write the split-sum BRDF table (A, B in red and green) to this .exr or .png.
    #[arg(long)]
    lut: Option<String>,
    /// Edge of the BRDF table.
    #[arg(long, default_value_t = 128)]
    lut_size: u32,
    /// Replace a side file (SH JSON, preview, BRDF table) that no mirrorball run wrote
    /// (else prefilter refuses it; its own from an earlier run it replaces).
    #[arg(long)]
    overwrite: bool,
    /// Layout of flat outputs of multi-layer projections.
    #[arg(long, value_name = "LAYOUT", value_parser = names::<Layout>())]
    layout: Option<String>,
    /// Texel precision: half (default) or float.
    #[arg(long, value_parser = names::<Precision>())]
    precision: Option<String>,
    #[command(flatten)]
    input_args: InputArgs,
    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
}

#[derive(Args, Debug)]
pub struct BakeArgs {
    /// Input environment map (any projection; `{face}` reads one file per layer).
    input: Option<String>,
    /// The engine: bevy, three, babylon, gltf, filament, unity, unreal, ktx2; or list, to
    /// print what each writes.
    #[arg(long = "for", value_name = "ENGINE")]
    engine: String,
    /// The folder to write into (made if missing; its parent must exist).
    out_dir: Option<String>,
    /// Face edge of the specular chain's level 0, a power of two.
    #[arg(long, default_value_t = 256, value_parser = size::parse, allow_hyphen_values = true)]
    size: i64,
    /// Face edge of the sky background (bevy, three, filament), a power of two; default:
    /// the source's resolution (the edge that keeps its texels per steradian, 16 to 2048).
    #[arg(long, value_name = "EDGE", value_parser = size::parse, allow_hyphen_values = true)]
    background_size: Option<i64>,
    /// Replace files in OUT-DIR that no mirrorball run wrote (else bake refuses them; the
    /// files of an earlier bake there are replaced, or removed when not written again).
    #[arg(long)]
    overwrite: bool,
    /// Texel encoding (default: the engine's; `bake --for list` shows which it takes).
    #[arg(long, value_parser = names::<mirrorball_io::Encoding>())]
    encoding: Option<String>,
    /// How hard the BC6H encoder searches.
    #[arg(long, default_value = "basic", value_parser = names::<mirrorball_io::Effort>())]
    effort: String,
    /// Zstandard level for KTX2 supercompression (default 3 where the engine reads it).
    #[arg(long, value_name = "LEVEL", conflicts_with = "no_zstd")]
    zstd: Option<i32>,
    /// No supercompression.
    #[arg(long)]
    no_zstd: bool,
    /// Roughness of each level instead of the engine's rule: linear, ue4, filament, or a
    /// comma-separated list, one per level.
    #[arg(long)]
    mapping: Option<String>,
    /// Importance samples per texel for the sharpest lobes.
    #[arg(long, default_value_t = 128)]
    samples: u32,
    #[command(flatten)]
    input_args: InputArgs,
    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
}

/// On SIGINT, SIGTERM or SIGHUP: let a set of files being renamed into place land, remove
/// every temporary file, and exit with 128 + the signal's number (130 for Ctrl-C), as
/// shells do.
#[cfg(unix)]
fn on_interrupt_clean_up() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
        return; // no handler: the default action (exit) still leaves no half-written output
    };
    std::thread::spawn(move || {
        if let Some(sig) = signals.forever().next() {
            let removed = mirrorball_io::interrupted();
            let what = match sig {
                SIGINT => "interrupted",
                SIGTERM => "terminated",
                _ => "hung up",
            };
            // A new line: a progress bar may be on this one.
            eprintln!(
                "\nmirrorball: {what}; removed {}, nothing half-written left",
                mirrorball_core::count(removed as u64, "unfinished file")
            );
            std::process::exit(128 + sig);
        }
    });
}

#[cfg(not(unix))]
fn on_interrupt_clean_up() {}

/// A number flag's value: finite (`nan`, `inf` and `1e999` are refused by name).
fn finite_f64(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(format!("'{s}' is not a finite number")),
        Err(_) => Err(format!("'{s}' is not a number")),
    }
}

/// [`finite_f64`], for `f32` flags (and in `f32`'s range).
fn finite_f32(s: &str) -> Result<f32, String> {
    let v = finite_f64(s)?;
    if v.abs() > f32::MAX as f64 {
        return Err(format!("'{s}' is too large"));
    }
    Ok(v as f32)
}

/// The exposures a flag takes, in stops: `2^EV` is a normal `f32` (neither 0 nor infinite),
/// so scaling by it never turns every texel to 0 or to infinity (and 0·∞ into NaN).
const EXPOSURE_STOPS: std::ops::RangeInclusive<f32> = -126.0..=127.0;

/// An exposure flag's value ([`EXPOSURE_STOPS`]).
fn exposure_stops(s: &str) -> Result<f32, String> {
    let v = finite_f64(s)?;
    if !EXPOSURE_STOPS.contains(&(v as f32)) || v.abs() > f32::MAX as f64 {
        return Err(format!(
            "'{s}' stops is outside {}..={}: 2^{s} is {} as a 32-bit float",
            EXPOSURE_STOPS.start(),
            EXPOSURE_STOPS.end(),
            if v > 0.0 {
                "infinite"
            } else {
                "0 or subnormal"
            }
        ));
    }
    Ok(v as f32)
}

fn main() -> ExitCode {
    on_interrupt_clean_up();
    let matches = Cli::command().get_matches();
    let mut cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    if let (Command::Render(r), Some(m)) = (&mut cli.command, matches.subcommand_matches("render"))
    {
        r.given = m
            .ids()
            .filter(|id| m.value_source(id.as_str()) == Some(ValueSource::CommandLine))
            .map(|id| id.to_string())
            .collect();
    }
    budget::set_max(cli.max_memory);
    let quiet = matches.subcommand().is_some_and(|(_, m)| {
        m.try_get_one::<bool>("quiet")
            .ok()
            .flatten()
            .copied()
            .unwrap_or(false)
    });
    let result: Result<(), CliError> = match cli.command {
        Command::Convert(a) => commands::convert::run(a),
        Command::Info(a) => commands::info::run(a),
        Command::Compare(a) => commands::compare::run(a),
        Command::Demo(a) => commands::demo::run(a),
        Command::Prefilter(a) => commands::prefilter::run(a),
        Command::Bake(a) => commands::bake::run(a),
        Command::Analyze(a) => commands::analyze::run(a),
        Command::Render(a) => commands::render::run(*a),
        Command::Studio(a) => commands::studio::run(a),
        Command::Tag(a) => commands::tag::run(a),
        Command::Views(a) => commands::views::run(a),
    };
    if !quiet {
        for f in mirrorball_io::removed_leftovers() {
            eprintln!(
                "mirrorball: removed {}, left by a mirrorball run that was killed (its process no longer runs)",
                f.display()
            );
        }
    }
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("mirrorball: error: {e}");
            ExitCode::from(error::exit_code(&e))
        }
    }
}
