//! Rigs of pinhole views for photogrammetry and Gaussian splatting (`mirrorball views IN
//! OUT-DIR`): a panorama cut into perspective views, each antialiased as every conversion
//! is (core's `Remap` from the panorama's projection to a rectilinear `View`, or to an
//! equidistant `Fisheye` for a rig of fisheye views), with the camera files COLMAP and
//! nerfstudio read ([`cameras`]) and masks of what the panorama does not cover.
//!
//! `ViewsRequest → ViewsPlan (rig, fields of view, sizes, container, folder, a sequence's
//! frames and every file checked: nothing read yet) → read the (first) panorama (and
//! --mask, the same size) → each view's size and camera → memory and room checked → per
//! view: its plan and its mask, made once → per frame: each view's picture from its plan,
//! the masks, while the next frame is read → every file lands together
//! (io::write_together)`.
//!
//! A sequence (`frames/%04d.exr`, `'frames/*.jpg'`: `frames::pattern`) is one rig: each
//! frame's views are its images in `frames.txt` and `transforms.json`, every frame's rig at
//! the same pose (the poses within the rig are exact; where a moving camera stood is for
//! the mapper to find, with `rig_config.json`). A source's capture time and GPS fields
//! ([`metadata`]) go into each JPEG view's EXIF and into `transforms.json`
//! (`mirrorball.exif`, per frame).
//!
//! What OUT-DIR holds (`FRAME` each panorama's file stem, `EXT` the views' container):
//! - `images/VIEW/FRAME.EXT`: the views, one folder per view, as COLMAP's rig
//!   configuration takes them (each camera its own image prefix);
//! - `masks/VIEW/FRAME.EXT.png`: 8-bit grey, 255 where the pixel's direction is covered by
//!   the panorama (and white in `--mask`), 0 elsewhere; COLMAP's `mask_path` naming.
//!   Written for every view when one of them is not all valid, or with `--masks`;
//! - `sparse/0/`: the COLMAP text model, `rig_config.json`, `transforms.json`.

pub mod cameras;
pub mod metadata;
pub mod rig;

use crate::budget;
use crate::error::Error;
use crate::frames::pattern::Pattern;
use crate::guard::Files;
use crate::hooks::Hooks;
use crate::load::{self, InputPlan};
use crate::spec::ProjSpec;
use cameras::{Camera, Model, Shot};
use mirrorball_core::glam::DVec2;
use mirrorball_core::{
    EnvMap, Fisheye, Frame, Lens, Projection, Remap, ResampleOptions, View, WorldProjection,
};
use mirrorball_io::{Folders, Format, Precision, WriteOptions};
pub use rig::{ViewSpec, PRESETS};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What to cut, as plain values: the command line's `views` flags.
#[derive(Clone, Debug)]
pub struct ViewsRequest {
    /// The panorama (any projection mirrorball reads), or a sequence's pattern (printf
    /// `%04d` or a glob, in the file name).
    pub input: String,
    /// The folder to write into (made if missing; its parent must exist).
    pub out_dir: String,
    /// How to read the input.
    pub input_plan: InputPlan,
    /// A preset's name ([`PRESETS`]) or a `.json` file of views.
    pub rig: String,
    /// `--size W[xH]`: each view's width (where the rig gives none) and height (where the
    /// view sets neither its height nor its vertical field of view).
    pub size: Option<(i64, Option<i64>)>,
    /// The views' container: `png` (8-bit), `png16` (16-bit PNG), `jpg` or `exr` (half).
    pub format: String,
    /// Write every view's mask even when all its pixels are valid.
    pub masks: bool,
    /// A mask drawn on the panorama (white: valid), the panorama's size.
    pub mask: Option<String>,
    /// The most integration points per texel side (1..=16).
    pub max_samples: u32,
    /// Replace files in OUT-DIR that mirrorball did not write (its record,
    /// `mirrorball_io::Owned`, does not list them); by default the run is refused.
    pub overwrite: bool,
}

impl ViewsRequest {
    /// The command line's defaults for cutting `input` into `out_dir`.
    pub fn new(input: &str, out_dir: &str) -> ViewsRequest {
        ViewsRequest {
            input: input.into(),
            out_dir: out_dir.into(),
            input_plan: InputPlan::default(),
            rig: "cube".into(),
            size: None,
            format: "png".into(),
            masks: false,
            mask: None,
            max_samples: ResampleOptions::default().max_samples,
            overwrite: false,
        }
    }
}

/// A view, checked: its aim and fields, its size where known before the panorama is read.
#[derive(Clone, Debug)]
struct Planned {
    spec: ViewSpec,
    width: Option<u32>,
    height: Option<u32>,
}

/// A cut, checked before any file is read.
pub struct ViewsPlan {
    input: String,
    input_plan: InputPlan,
    rig: String,
    views: Vec<Planned>,
    format: Format,
    ext: &'static str,
    precision: Option<Precision>,
    dir: PathBuf,
    /// Each panorama (one, or a sequence's frames) and its name in the views' folders.
    frames: Vec<(String, String)>,
    mask: Option<String>,
    masks: bool,
    max_samples: u32,
    bound: crate::size::Bound,
    files: Files,
    /// OUT-DIR's record of the files mirrorball wrote there, read when planned.
    owned: mirrorball_io::Owned,
}

impl ViewsPlan {
    /// Checks `r`: the rig, each view's fields of view and size, the container, OUT-DIR and
    /// every file written.
    pub fn new(r: &ViewsRequest) -> Result<ViewsPlan, Error> {
        let (planned, bound) = plan_rig(r)?;
        let (format, ext, precision) = container(&r.format)?;
        let dir = PathBuf::from(&r.out_dir);
        check_dir(&dir)?;
        let frames: Vec<(String, String)> = match Pattern::parse(&r.input)? {
            Some(p) => p
                .expand(&r.input)?
                .into_iter()
                .map(|f| {
                    let path = f.path.to_string_lossy().into_owned();
                    let name = frame_name(&path);
                    (path, name)
                })
                .collect(),
            None => vec![(r.input.clone(), frame_name(&r.input))],
        };
        let mut names = std::collections::HashSet::new();
        if let Some((path, name)) = frames.iter().find(|(_, n)| !names.insert(n.clone())) {
            return Err(Error::request(format!(
                "{}: {path} is another frame named {name} (frames are named by their file stems)",
                r.input
            )));
        }
        let mut files = Files::new();
        files.making(Folders::MakeAll);
        for (path, _) in &frames {
            files.input_arg("the input", path);
        }
        if let Some(m) = &r.mask {
            files.input("--mask", m);
        }
        let mut plan = ViewsPlan {
            input: r.input.clone(),
            input_plan: r.input_plan.clone(),
            rig: r.rig.clone(),
            views: planned,
            format,
            ext,
            precision,
            dir,
            frames,
            mask: r.mask.clone(),
            masks: r.masks,
            max_samples: r.max_samples,
            bound,
            files: Files::new(),
            owned: mirrorball_io::Owned::read(&PathBuf::from(&r.out_dir))?,
        };
        for (_, frame) in &plan.frames {
            for v in &plan.views {
                files.output("a view", plan.image_path(&v.spec.name, frame));
                files.output("a mask", plan.mask_path(&v.spec.name, frame));
            }
        }
        for name in TEXT_FILES {
            files.output("a camera file", plan.dir.join(name));
        }
        files.check()?;
        plan.owned.check(&plan.names(true), r.overwrite)?;
        plan.files = files;
        Ok(plan)
    }

    /// The picture of view `name`, relative to `images/`.
    fn image_name(&self, name: &str, frame: &str) -> String {
        format!("{name}/{frame}.{}", self.ext)
    }

    /// The mask of view `name`, relative to OUT-DIR.
    fn mask_name(&self, name: &str, frame: &str) -> String {
        format!("masks/{}.png", self.image_name(name, frame))
    }

    /// Every file the run writes, relative to OUT-DIR: the views, their masks (`masks`)
    /// and the camera files.
    fn names(&self, masks: bool) -> Vec<String> {
        let mut names = Vec::new();
        for (_, frame) in &self.frames {
            for v in &self.views {
                names.push(format!("images/{}", self.image_name(&v.spec.name, frame)));
                if masks {
                    names.push(self.mask_name(&v.spec.name, frame));
                }
            }
        }
        names.extend(TEXT_FILES.iter().map(|n| n.to_string()));
        names
    }

    fn image_path(&self, name: &str, frame: &str) -> PathBuf {
        self.dir.join("images").join(self.image_name(name, frame))
    }

    fn mask_path(&self, name: &str, frame: &str) -> PathBuf {
        self.dir.join(self.mask_name(name, frame))
    }

    /// The rig's cameras for a panorama `env`: each view's size (from `--size`, the view,
    /// else the panorama's resolution) and fields of view.
    fn cameras(&self, source: Shape) -> Result<Vec<(Projection, Camera)>, Error> {
        rig_cameras(&self.views, &self.bound, source)
    }
}

/// The rig's cameras for a panorama of shape `source`: each view's size (from `--size`, the
/// view, else the panorama's resolution) and fields of view.
fn rig_cameras(
    views: &[Planned],
    bound: &crate::size::Bound,
    (p, (w, h, layers)): Shape,
) -> Result<Vec<(Projection, Camera)>, Error> {
    let texels = w as f64 * h as f64 * layers as f64;
    // Texels per radian: the panorama's, were they spread evenly over what it covers.
    let per_radian = (texels / p.covered_solid_angle()).sqrt();
    views
        .iter()
        .map(|v| {
            let s = &v.spec;
            let t = (0.5 * s.fov.to_radians()).tan();
            // The picture's half-width over the focal length: the plane's, or (a
            // fisheye's) the rim's angle.
            let half = match s.model {
                Model::Pinhole => t,
                Model::Fisheye => 0.5 * s.fov.to_radians(),
            };
            let w = match v.width {
                Some(w) => w,
                None => {
                    let w = (2.0 * half * per_radian).round().max(16.0);
                    bound.check(&format!("view '{}': its width", s.name), w as i64)?
                }
            };
            let frame = View::frame_of(s.yaw, s.pitch, s.roll);
            if s.model == Model::Fisheye {
                let lens = Fisheye::new(Frame::turned(frame), Lens::Equidistant, s.fov)
                    .ok_or_else(|| {
                        Error::request(format!(
                            "view '{}': a fisheye of {}° cannot be drawn",
                            s.name, s.fov
                        ))
                    })?;
                let cam = Camera::fisheye(&s.name, w, s.fov, frame);
                return Ok((Projection::Fisheye(lens), cam));
            }
            let (h, vfov) = match (v.height, s.vfov) {
                (Some(h), Some(vfov)) => (h, vfov),
                (Some(h), None) => (h, fov_of(t * h as f64 / w as f64)),
                (None, Some(vfov)) => {
                    let tv = (0.5 * vfov.to_radians()).tan();
                    let h = (w as f64 * tv / t).round().max(1.0) as i64;
                    (
                        bound.check(&format!("view '{}': its height", s.name), h)?,
                        vfov,
                    )
                }
                (None, None) => (w, s.fov),
            };
            let view = View::perspective(s.fov, vfov, s.yaw, s.pitch, s.roll).ok_or_else(|| {
                Error::request(format!(
                    "view '{}': a pinhole view of {}°×{vfov}° cannot be drawn",
                    s.name, s.fov
                ))
            })?;
            let cam = Camera::new(&s.name, (w, h), (s.fov, vfov), frame);
            Ok((Projection::View(view), cam))
        })
        .collect()
}

/// `--format`'s container: the format, the views' extension and the precision.
fn container(name: &str) -> Result<(Format, &'static str, Option<Precision>), Error> {
    match name.to_ascii_lowercase().as_str() {
        "png" => Ok((Format::Png, "png", None)),
        "png16" => Ok((Format::Png, "png", Some(Precision::U16))),
        "jpg" | "jpeg" => Ok((Format::Jpeg, "jpg", None)),
        "exr" => Ok((Format::Exr, "exr", None)),
        other => Err(Error::request(format!(
            "--format: unknown '{other}' (png, png16, jpg, exr)"
        ))),
    }
}

/// The request's rig checked ([`plan_view`] each view, one camera model, `--max-samples`),
/// with the size bound of its container.
fn plan_rig(r: &ViewsRequest) -> Result<(Vec<Planned>, crate::size::Bound), Error> {
    let views = rig::resolve(&r.rig)?;
    let (format, ext, _) = container(&r.format)?;
    if !(1..=16).contains(&r.max_samples) {
        return Err(Error::request(format!(
            "--max-samples: {} is outside 1..=16",
            r.max_samples
        )));
    }
    let bound = crate::size::pictures(format, &format!("a .{ext} view"), |s| (s as u64, s as u64));
    let size = r
        .size
        .map(|(w, h)| {
            Ok::<_, Error>((
                bound.check("--size", w)?,
                h.map(|h| bound.check("--size", h)).transpose()?,
            ))
        })
        .transpose()?;
    if let Some(v) = views.iter().find(|v| v.model != views[0].model) {
        return Err(Error::request(format!(
            "--rig {}: view '{}' is {} and view '{}' is not: a rig's views are all pinhole or all fisheye (nerfstudio reads one camera model a file)",
            r.rig,
            v.name,
            v.model.name(),
            views[0].name
        )));
    }
    let planned = views
        .into_iter()
        .map(|v| plan_view(v, size, &bound))
        .collect::<Result<Vec<_>, _>>()?;
    Ok((planned, bound))
}

/// The request's rig cut from a panorama held in memory (`env`: a decoded array, a frame):
/// each view's camera and its picture, the floats [`run`] encodes into its files (the same
/// rig, sizes, plans and antialiasing). `r`'s rig, size, format (its size bound) and
/// `max_samples` are read; its files are not.
///
/// ```
/// use mirrorball::core::{EnvMap, ProjectionKind};
/// use mirrorball::views::{cut, ViewsRequest};
/// let env = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 64, 3, |d| [d.x as f32, 0.5, 0.5, 1.0]);
/// let mut r = ViewsRequest::new("", "");
/// r.size = Some((16, None));
/// let views = cut(&env, &r).unwrap();
/// assert_eq!(views.len(), 6);
/// assert_eq!((views[0].1.width(), views[0].1.height()), (16, 16));
/// assert!((views[0].0.focal.0 - 8.0).abs() < 1e-9); // 90°: f = w/2
/// ```
pub fn cut(env: &EnvMap, r: &ViewsRequest) -> Result<Vec<(Camera, mirrorball_core::Image)>, Error> {
    use rayon::prelude::*;
    let (views, bound) = plan_rig(r)?;
    let source = (
        *env.projection(),
        (env.width(), env.height(), env.layers().len()),
    );
    let rig = rig_cameras(&views, &bound, source)?;
    let texels: u64 = rig
        .iter()
        .map(|(_, c)| c.size.0 as u64 * c.size.1 as u64)
        .sum();
    let c = env.channels() as u64;
    budget::check(
        &format!("{} views", rig.len()),
        0,
        texels * (17 + 4 * c),
        "a smaller size",
    )?;
    let opts = ResampleOptions {
        max_samples: r.max_samples,
        ..Default::default()
    };
    rig.into_par_iter()
        .map(|(view, cam)| {
            let (w, h, layers) = source.1;
            let remap = Remap::with_extent(source.0, (w, h), layers, view, cam.size, &opts);
            let out = remap.apply(env).map_err(|e| Error::input(e.to_string()))?;
            let picture = out.into_layers().swap_remove(0);
            Ok((cam, picture))
        })
        .collect()
}

/// The writer's name in OUT-DIR's record of the files mirrorball wrote
/// (`mirrorball_io::Owned`).
const WRITER: &str = "views";

/// The camera files, relative to OUT-DIR.
const TEXT_FILES: [&str; 7] = [
    "sparse/0/cameras.txt",
    "sparse/0/images.txt",
    "sparse/0/points3D.txt",
    "sparse/0/rigs.txt",
    "sparse/0/frames.txt",
    "rig_config.json",
    "transforms.json",
];

/// The field of view, degrees, whose half-angle's tangent is `t`.
fn fov_of(t: f64) -> f64 {
    2.0 * t.atan().to_degrees()
}

/// A rig's view checked: finite angles, fields of view a pinhole draws, sizes within the
/// container's bound; `--size` (`size`) where the view gives none.
fn plan_view(
    spec: ViewSpec,
    size: Option<(u32, Option<u32>)>,
    bound: &crate::size::Bound,
) -> Result<Planned, Error> {
    let name = &spec.name;
    for (what, v) in [
        ("yaw", spec.yaw),
        ("pitch", spec.pitch),
        ("roll", spec.roll),
    ] {
        if !v.is_finite() {
            return Err(Error::request(format!(
                "view '{name}': {what} {v} is not finite"
            )));
        }
    }
    // A pinhole's plane, and the fisheye model's too (OPENCV_FISHEYE's rays lie in front
    // of the camera): (0°, 180°).
    let fovs = View::hfov_range(0.0);
    let kind = match spec.model {
        Model::Pinhole => "pinhole",
        Model::Fisheye => "fisheye",
    };
    for (what, v) in [("fov", Some(spec.fov)), ("vfov", spec.vfov)] {
        if let Some(v) = v.filter(|v| !fovs.contains(*v)) {
            return Err(Error::request(format!(
                "view '{name}': {what} {v}°: a {kind} view's field of view lies in (0°, 180°)"
            )));
        }
    }
    if spec.model == Model::Fisheye && (spec.vfov.is_some() || spec.height.is_some()) {
        return Err(Error::request(format!(
            "view '{name}': a fisheye view is square, its disk fov across: give its width, not vfov or height"
        )));
    }
    let width = match spec.width {
        Some(w) => Some(bound.check(&format!("view '{name}': width"), w)?),
        None => size.map(|s| s.0),
    };
    let height = match (spec.height, spec.vfov) {
        (Some(h), _) => Some(bound.check(&format!("view '{name}': height"), h)?),
        (None, None) if spec.width.is_none() && spec.model == Model::Pinhole => {
            size.and_then(|s| s.1)
        }
        _ => None,
    };
    if let (None, Some(h)) = (width, height) {
        return Err(Error::request(format!(
            "view '{name}': a height ({h}) needs a width (the view's, or --size's)"
        )));
    }
    Ok(Planned {
        spec,
        width,
        height,
    })
}

/// OUT-DIR: a folder or nothing yet, in a folder that exists.
fn check_dir(dir: &Path) -> Result<(), Error> {
    if dir.exists() && !dir.is_dir() {
        return Err(Error::request(format!(
            "{}: OUT-DIR is a file; views writes a folder of files (give a folder's name)",
            dir.display()
        )));
    }
    let parent = dir.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(p) = parent.filter(|p| !dir.exists() && !p.is_dir()) {
        return Err(Error::request(format!(
            "{}: the folder {} does not exist (views makes OUT-DIR, not the folders above it)",
            dir.display(),
            p.display()
        )));
    }
    Ok(())
}

/// The frame's name in each view's folder: the input's file stem (`{face}` left out).
fn frame_name(input: &str) -> String {
    let stem = Path::new(&input.replace(load::FACE, ""))
        .file_stem()
        .map(|s| {
            s.to_string_lossy()
                .trim_matches(['_', '-', '.'])
                .to_string()
        })
        .unwrap_or_default();
    let plain: String = stem
        .chars()
        .map(
            |c| match c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') {
                true => c,
                false => '_',
            },
        )
        .collect();
    match plain.is_empty() {
        true => "frame".into(),
        false => plain,
    }
}

/// Where each pixel of `view` (`w`×`h`) is valid: its centre's direction covered by
/// `source` (255) or not (0).
fn coverage(view: &Projection, (w, h): (u32, u32), source: &Projection) -> Vec<u8> {
    use rayon::prelude::*;
    // A lat-long covers every direction: only the view's own outline is looked up, and a
    // flat view (`View`) has a direction at every pixel centre: nothing to look up.
    let everywhere = matches!(source, Projection::LatLong(_));
    if everywhere && matches!(view, Projection::View(_)) {
        return vec![255; w as usize * h as usize];
    }
    let mut out = vec![0u8; w as usize * h as usize];
    out.par_chunks_mut(w as usize)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, m) in row.iter_mut().enumerate() {
                let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                let covered = view
                    .uv_to_dir(0, uv)
                    .is_some_and(|d| everywhere || source.dir_to_uv(d).is_some());
                *m = if covered { 255 } else { 0 };
            }
        });
    out
}

/// Reads `--mask` as a map of the panorama's projection and layout, refused unless it is
/// the panorama's size.
fn read_mask(plan: &ViewsPlan, path: &str, (proj, size): Shape) -> Result<EnvMap, Error> {
    let from =
        ProjSpec::parse(&proj.to_string()).map_err(|e| Error::request(format!("--mask: {e}")))?;
    let limits = mirrorball_io::Limits::default();
    let shape = |(w, h, layers): (u32, u32, usize)| {
        let layers = match layers {
            1 => String::new(),
            n => format!("x{n}"),
        };
        format!("{w}x{h}{layers}")
    };
    let m = load::load(path, Some(&from), plan.input_plan.layout, &limits)
        .map_err(|e| e.context("--mask"))?
        .env;
    let found = (m.width(), m.height(), m.layers().len());
    if found != size {
        return Err(Error::input(format!(
            "--mask {path}: {}, the panorama is {}: a mask is drawn on the panorama, the same size",
            shape(found),
            shape(size)
        )));
    }
    Ok(m)
}

/// What [`run`] wrote.
pub struct Written {
    /// Every file, in the order written.
    pub files: Vec<PathBuf>,
    /// The views' cameras.
    pub cameras: Vec<Camera>,
    /// Whether masks were written.
    pub masks: bool,
}

/// A panorama's projection and extent: width, height, layers.
type Shape = (Projection, (u32, u32, usize));

/// A panorama as read: its float layers, or (a PNG or JPEG of RGB samples that is one
/// layer as it is: `load::read_coded`) its sRGB codes in a buffer reused frame after
/// frame, with no float copy of them (`Remap::rows_coded`: the same bits out).
enum Pano {
    Floats(EnvMap),
    Codes(load::CodedMap, Vec<u8>),
}

impl Pano {
    /// Reads `path` into `buf` as codes where it can (unless `floats`), else as floats; with
    /// the lines saying what was read.
    fn read(
        path: &str,
        plan: &InputPlan,
        mut buf: Vec<u8>,
        floats: bool,
    ) -> Result<(Pano, Vec<String>), Error> {
        if !floats {
            if let Some((map, notes)) = load::read_coded(path, plan, &mut buf)? {
                return Ok((Pano::Codes(map, buf), notes));
            }
        }
        let (env, notes) = load::read_prepared(path, plan)?;
        Ok((Pano::Floats(env), notes))
    }

    fn shape(&self) -> Shape {
        match self {
            Pano::Floats(env) => (
                *env.projection(),
                (env.width(), env.height(), env.layers().len()),
            ),
            Pano::Codes(map, _) => (map.projection, (map.extent.0, map.extent.1, 1)),
        }
    }

    fn channels(&self) -> usize {
        match self {
            Pano::Floats(env) => env.channels(),
            Pano::Codes(..) => 3,
        }
    }

    /// Bytes the panorama holds.
    fn bytes(&self) -> u64 {
        match self {
            Pano::Floats(env) => budget::f32_texels(
                env.width() as u64 * env.height() as u64 * env.layers().len() as u64,
                env.channels() as u64,
            ),
            Pano::Codes(_, b) => b.len() as u64,
        }
    }

    /// The same panorama as floats (for plans that do not take codes).
    fn into_floats(self) -> Pano {
        match self {
            Pano::Codes(map, buf) => {
                let codes = map.codes(&buf).expect("read_coded's codes fit its map");
                let env = EnvMap::new(map.projection, vec![codes.to_image()])
                    .expect("one layer of a one-layer projection");
                Pano::Floats(env)
            }
            floats => floats,
        }
    }

    /// Its buffer of codes, for the next frame (none for floats).
    fn into_buffer(self) -> Vec<u8> {
        match self {
            Pano::Codes(_, buf) => buf,
            Pano::Floats(_) => Vec::new(),
        }
    }

    /// The rows `remap` makes of it.
    fn rows<'a>(
        &'a self,
        remap: &'a Remap,
    ) -> Result<mirrorball_core::RemapRows<'a>, mirrorball_core::RemapError> {
        match self {
            Pano::Floats(env) => remap.rows(env),
            Pano::Codes(map, buf) => {
                let codes = map.codes(buf).ok_or(mirrorball_core::RemapError::Codes)?;
                remap.rows_coded(codes)
            }
        }
    }
}

/// Refuses the job when it would not fit in memory (a panorama, two for a sequence, and
/// the mask when `masked`; each view's plan (8 bytes a texel, and taps), mask, and picture,
/// all views made at once) or on the disk (every frame's views and masks).
fn check_resources(
    plan: &ViewsPlan,
    pano: &Pano,
    rig: &[(Projection, Camera)],
    masked: bool,
) -> Result<(), Error> {
    let (_, (w, h, layers)) = pano.shape();
    let c = pano.channels() as u64;
    // A sequence holds two frames: the next one is read while this one's views are made.
    let frames = plan.frames.len().min(2) as u64;
    let mask = budget::f32_texels(w as u64 * h as u64 * layers as u64, c);
    let held = pano.bytes() * frames + if masked { mask } else { 0 };
    let texels = |cam: &Camera| cam.size.0 as u64 * cam.size.1 as u64;
    let all: u64 = rig.iter().map(|(_, cam)| texels(cam)).sum();
    budget::check(
        &format!("{} views", rig.len()),
        held,
        all * (17 + 4 * c * 2),
        "a smaller --size",
    )?;
    let bytes: u64 = rig
        .iter()
        .map(|(_, cam)| plan.format.bytes_estimate(texels(cam), 3, None) + texels(cam))
        .sum();
    plan.files.room(bytes * plan.frames.len() as u64)
}

/// A reading error of `path` as io's, for the writes' set.
fn input_error(path: &str, problem: String) -> mirrorball_io::Error {
    mirrorball_io::Error::input(Path::new(path), problem)
}

/// A view's mask as its PNG file's bytes, and whether some pixel of it is not valid.
type MaskFile = (Vec<u8>, bool);

/// Each view's plan from a panorama of shape `src` and its mask file (a PNG of the
/// coverage, less what `user_mask` blacks out; `None` where every pixel is valid), made
/// in parallel, each counted by `tick`.
fn plan_views(
    plan: &ViewsPlan,
    rig: &[(Projection, Camera)],
    (src, shape): Shape,
    user_mask: Option<&EnvMap>,
    tick: &(dyn Fn() + Sync),
) -> Result<(Vec<Remap>, Vec<MaskFile>), mirrorball_io::Error> {
    use rayon::prelude::*;
    let opts = ResampleOptions {
        max_samples: plan.max_samples,
        ..Default::default()
    };
    rig.par_iter()
        .map(|(view, cam)| {
            let remap =
                Remap::with_extent(src, (shape.0, shape.1), shape.2, *view, cam.size, &opts);
            let mut mask = coverage(view, cam.size, &src);
            if let Some(m) = user_mask {
                let name = plan.mask.as_deref().unwrap_or_default();
                let drawn = remap
                    .apply(m)
                    .map_err(|e| input_error(name, e.to_string()))?;
                let img = &drawn.layers()[0];
                for (v, px) in mask.iter_mut().zip(img.data().chunks_exact(img.channels())) {
                    if px[0] < 0.5 {
                        *v = 0;
                    }
                }
            }
            let partial = mask.contains(&0);
            let named = plan.mask_path(&cam.name, &plan.frames[0].1);
            let png = mirrorball_io::grey_png(&named, cam.size, &mask)?;
            tick();
            Ok((remap, (png, partial)))
        })
        .collect::<Result<Vec<_>, _>>()
        .map(|v| v.into_iter().unzip())
}

/// View `remap`'s picture of `pano` as its file's bytes (`path` names it in messages),
/// with `app1` (EXIF) in a JPEG: 8-bit (or 16-bit) files straight from the rows through
/// the sRGB encoder into `codes` (reused view after view), others from a float image.
fn encode_view(
    plan: &ViewsPlan,
    (remap, size, path): (&Remap, (u32, u32), &Path),
    pano: &Pano,
    app1: Option<&[u8]>,
    codes: &mut Vec<u8>,
) -> Result<Vec<u8>, mirrorball_io::Error> {
    use crate::frames::pipe::{PixFmt, SrgbTable};
    use rayon::prelude::*;
    let misfit = |e: mirrorball_core::RemapError| {
        input_error(
            &path.display().to_string(),
            format!("{e} (every frame must have the first's projection and size)"),
        )
    };
    let rows = pano.rows(remap).map_err(misfit)?;
    let (w, h) = (size.0 as usize, size.1 as usize);
    let wide = plan.precision == Some(Precision::U16);
    // A JPEG drops alpha; a PNG keeps it, so an RGBA view is written from floats.
    let c = rows.row_len() / w;
    let coded = match plan.format {
        Format::Jpeg => true,
        Format::Png => c == 3 && (!wide || cfg!(target_endian = "little")),
        _ => false,
    };
    if !coded {
        let mut image = mirrorball_core::Image::new(size.0, size.1, c);
        image
            .data_mut()
            .par_chunks_mut(w * c)
            .enumerate()
            .for_each(|(y, row)| rows.row_into(0, y, row));
        let write = WriteOptions {
            precision: plan.precision,
            jpeg_quality: JPEG_QUALITY,
            ..Default::default()
        };
        let hint = mirrorball_io::Hint::Format(plan.format);
        return mirrorball_io::write_bytes(&[vec![image]], hint, &write);
    }
    let (fmt, table) = match wide {
        true => (PixFmt::Rgb48le, SrgbTable::get(65535.0)),
        false => (PixFmt::Rgb24, SrgbTable::get(255.0)),
    };
    let row_bytes = w * fmt.pixel_bytes();
    codes.resize(row_bytes * h, 0);
    codes.par_chunks_mut(row_bytes).enumerate().for_each_init(
        || vec![0.0f32; w * c],
        |row, (y, out)| {
            rows.row_into(0, y, row);
            fmt.encode_texels(Some(table), row, c, out);
        },
    );
    let segments = app1.unwrap_or_default();
    mirrorball_io::encode_codes(
        path,
        plan.format,
        size,
        (codes, wide),
        JPEG_QUALITY,
        segments,
    )
}

/// JPEG views' quality.
const JPEG_QUALITY: u8 = 92;

/// Writes the views of one panorama `pano` (the file `path`, named `frame` in the views'
/// folders) by their `plans`, with the EXIF it carries in JPEG views: every view made and
/// encoded at once (`codes`: each view's buffer, reused frame after frame), then the files
/// written, each counted by `tick`; the folders made go to `made`. Returns the EXIF
/// carried, for transforms.json.
fn write_frame(
    plan: &ViewsPlan,
    (rig, plans): (&[(Projection, Camera)], &[Remap]),
    codes: &mut [Vec<u8>],
    (pano, path, frame): (&Pano, &str, &str),
    made: &mut Vec<PathBuf>,
    tick: &(dyn Fn() + Sync),
) -> Result<Option<serde_json::Value>, mirrorball_io::Error> {
    use rayon::prelude::*;
    let carried = metadata::read(Path::new(path));
    let app1 = carried
        .as_ref()
        .filter(|_| plan.format == Format::Jpeg)
        .and_then(metadata::Carried::app1);
    let files: Vec<(PathBuf, Vec<u8>)> = rig
        .par_iter()
        .zip(plans)
        .zip(codes)
        .map(|(((_, cam), remap), codes)| {
            let image = plan.image_path(&cam.name, frame);
            let bytes = encode_view(
                plan,
                (remap, cam.size, &image),
                pano,
                app1.as_deref(),
                codes,
            )?;
            Ok((image, bytes))
        })
        .collect::<Result<_, mirrorball_io::Error>>()?;
    for (image, bytes) in files {
        made.extend(make_folders(std::slice::from_ref(&image))?);
        write_file(&image, &bytes)?;
        tick();
    }
    Ok(carried.map(|c| c.json()))
}

/// Writes `bytes` to `path` through the atomic writes (inside the caller's
/// `write_together`).
fn write_file(path: &Path, bytes: &[u8]) -> Result<(), mirrorball_io::Error> {
    mirrorball_io::atomic_write(path, |w| {
        std::io::Write::write_all(w, bytes).map_err(|e| mirrorball_io::Error::io(path, e))
    })
}

/// Cuts the panorama (or each frame of the sequence) into the rig's views and writes them
/// with their masks and camera files, every file landing together, saying what it does
/// through `hooks`.
pub fn run(plan: &ViewsPlan, hooks: &dyn Hooks) -> Result<Written, Error> {
    let t0 = Instant::now();
    let (pano, notes) = Pano::read(&plan.frames[0].0, &plan.input_plan, Vec::new(), false)?;
    notes.iter().for_each(|l| hooks.note(l));
    let source = pano.shape();
    let user_mask = plan
        .mask
        .as_deref()
        .map(|m| read_mask(plan, m, source))
        .transpose()?;
    let rig = plan.cameras(source)?;
    check_resources(plan, &pano, &rig, user_mask.is_some())?;
    let t1 = Instant::now();
    let mut wanted: Vec<PathBuf> = rig
        .iter()
        .map(|(_, cam)| plan.image_path(&cam.name, &plan.frames[0].1))
        .collect();
    wanted.extend(TEXT_FILES.iter().map(|n| plan.dir.join(n)));
    let mut made = make_folders(&wanted)?;
    let mut pano = Some(pano);
    let mut done = None;
    // Progress in views: each view's plan, then each view of each frame.
    let total = rig.len() as u64 * (plan.frames.len() as u64 + 1);
    hooks.progress("views", total, &mut |counter| {
        let tick = || {
            counter.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        };
        let mut pano = pano.take().expect("the work runs once");
        done = Some(mirrorball_io::write_together(|| {
            let (plans, masks) = plan_views(plan, &rig, source, user_mask.as_ref(), &tick)?;
            let with_masks = plan.masks || masks.iter().any(|(_, partial)| *partial);
            // Plans that read their source as floats get floats, every frame.
            let floats = !plans.iter().all(Remap::takes_codes);
            if floats {
                pano = pano.into_floats();
            }
            let mut codes = vec![Vec::new(); rig.len()];
            let mut spare = Vec::new();
            let mut exif = Vec::new();
            // A sequence's next frame is read on its own thread while this one's views are
            // made and encoded (the files are written on this thread, which gathers them).
            std::thread::scope(|s| {
                type Read = Result<(Pano, Vec<String>), Error>;
                let mut next: Option<std::thread::ScopedJoinHandle<Read>> = None;
                for (f, (path, frame)) in plan.frames.iter().enumerate() {
                    if let Some(reading) = next.take() {
                        let (read, notes) = reading
                            .join()
                            .unwrap_or_else(|e| std::panic::resume_unwind(e))
                            .map_err(|e| input_error(path, e.message))?;
                        notes.iter().for_each(|l| hooks.note(l));
                        if read.shape() != source {
                            let (p, (w, h, _)) = read.shape();
                            let (p0, (w0, h0, _)) = source;
                            return Err(input_error(
                                path,
                                format!(
                                    "a {} {w}x{h} map, the first frame's is a {} {w0}x{h0} (every frame must have the first's projection and size)",
                                    p.name(),
                                    p0.name()
                                ),
                            ));
                        }
                        spare = std::mem::replace(&mut pano, read).into_buffer();
                    }
                    if let Some((after, _)) = plan.frames.get(f + 1) {
                        let buf = std::mem::take(&mut spare);
                        next = Some(
                            s.spawn(move || Pano::read(after, &plan.input_plan, buf, floats)),
                        );
                    }
                    let carried = write_frame(
                        plan,
                        (&rig, &plans),
                        &mut codes,
                        (&pano, path, frame),
                        &mut made,
                        &tick,
                    )?;
                    exif.extend(carried.map(|c| (frame.clone(), c)));
                    for ((_, cam), (png, _)) in rig.iter().zip(&masks).filter(|_| with_masks) {
                        let path = plan.mask_path(&cam.name, frame);
                        made.extend(make_folders(std::slice::from_ref(&path))?);
                        write_file(&path, png)?;
                    }
                }
                Ok::<_, mirrorball_io::Error>(())
            })?;
            write_cameras(plan, &rig, with_masks, exif)?;
            // The record of what mirrorball wrote here lands with the files; what an
            // earlier run wrote and this one does not is removed once they are in place.
            let mut owned = plan.owned.clone();
            let stale = owned.replace(WRITER, &plan.names(with_masks));
            owned.write()?;
            Ok((with_masks, owned, stale))
        }));
    });
    let done = done.expect("the work ran");
    // Folders made for files that did not land are removed again (when left empty).
    for dir in made.iter().rev() {
        if done.is_err() {
            let _ = std::fs::remove_dir(dir);
        }
        mirrorball_io::keep_folder(dir);
    }
    let ((with_masks, owned, stale), mut files) = done?;
    files.retain(|f| f.file_name() != Some(mirrorball_io::RECORD.as_ref()));
    let removed = owned.remove(&stale);
    if !removed.is_empty() {
        hooks.note(&format!(
            "removed {} file{} an earlier run wrote in {} that this one does not",
            removed.len(),
            if removed.len() == 1 { "" } else { "s" },
            plan.dir.display()
        ));
    }
    hooks.note(&summary(plan, &rig, with_masks, (t1 - t0, t1.elapsed())));
    Ok(Written {
        files,
        cameras: rig.into_iter().map(|(_, c)| c).collect(),
        masks: with_masks,
    })
}

/// The line saying what [`run`] wrote, and how long reading and the views took.
fn summary(
    plan: &ViewsPlan,
    rig: &[(Projection, Camera)],
    with_masks: bool,
    (read, views): (std::time::Duration, std::time::Duration),
) -> String {
    let sizes: std::collections::BTreeSet<String> = rig
        .iter()
        .map(|(_, c)| format!("{}x{}", c.size.0, c.size.1))
        .collect();
    format!(
        "wrote {} views of {}{}, {}{} and the camera files in {} (read {:.2}s, views {:.2}s)",
        rig.len(),
        plan.input,
        match plan.frames.len() {
            1 => String::new(),
            n => format!(
                " ({n} frames, each frame's rig at the same pose: the views' poses within it are exact)"
            ),
        },
        sizes.into_iter().collect::<Vec<_>>().join(", "),
        if with_masks { ", their masks" } else { "" },
        plan.dir.display(),
        read.as_secs_f64(),
        views.as_secs_f64()
    )
}

/// Makes the folders `files` need that are missing, outermost first, each marked so that an
/// interrupt removes it again when left empty (`mirrorball_io::made_folder`); the folders
/// made, in the order made.
fn make_folders(files: &[PathBuf]) -> Result<Vec<PathBuf>, mirrorball_io::Error> {
    let mut made = Vec::new();
    for f in files {
        let mut missing: Vec<&Path> = f
            .ancestors()
            .skip(1)
            .filter(|d| !d.as_os_str().is_empty())
            .take_while(|d| !d.is_dir())
            .collect();
        missing.reverse();
        for d in missing {
            std::fs::create_dir(d).map_err(|e| mirrorball_io::Error::io(d, e))?;
            mirrorball_io::made_folder(d);
            made.push(d.to_path_buf());
        }
    }
    Ok(made)
}

/// Writes the COLMAP model, the rig configuration and `transforms.json` (inside the
/// caller's `write_together`).
fn write_cameras(
    plan: &ViewsPlan,
    rig: &[(Projection, Camera)],
    with_masks: bool,
    exif: Vec<(String, serde_json::Value)>,
) -> Result<(), mirrorball_io::Error> {
    let cams: Vec<Camera> = rig.iter().map(|(_, c)| c.clone()).collect();
    let names: Vec<(usize, String, String)> = plan
        .frames
        .iter()
        .flat_map(|(_, frame)| {
            cams.iter().enumerate().map(move |(i, c)| {
                (
                    i,
                    plan.image_name(&c.name, frame),
                    plan.mask_name(&c.name, frame),
                )
            })
        })
        .collect();
    let shots: Vec<Shot> = names
        .iter()
        .map(|(i, image, mask)| Shot {
            camera: *i,
            name: image,
            mask: with_masks.then_some(mask.as_str()),
        })
        .collect();
    let mut extra = serde_json::json!({
        "source": plan.input,
        "rig": plan.rig,
    });
    if !exif.is_empty() {
        extra["exif"] = serde_json::Value::Object(exif.into_iter().collect());
    }
    let texts = [
        cameras::cameras_txt(&cams),
        cameras::images_txt(&cams, &shots),
        cameras::points3d_txt(),
        cameras::rigs_txt(&cams),
        cameras::frames_txt(&cams, &shots),
        cameras::rig_config_json(&cams),
        cameras::transforms_json(&cams, &shots, Some(extra)),
    ];
    for (name, text) in TEXT_FILES.iter().zip(texts) {
        let path = plan.dir.join(name);
        mirrorball_io::atomic_write(&path, |w| {
            std::io::Write::write_all(w, text.as_bytes())
                .map_err(|e| mirrorball_io::Error::io(&path, e))
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse() {
        use crate::size::parse_extent;
        assert_eq!(parse_extent("640").unwrap(), (640, None));
        assert_eq!(parse_extent("640x480").unwrap(), (640, Some(480)));
        assert!(parse_extent("640x").is_err());
        assert_eq!(frame_name("dir/pano{face}.exr"), "pano");
        assert_eq!(frame_name("a b.png"), "a_b");
    }

    #[test]
    fn bad_views_are_refused_before_any_work() {
        let mut r = ViewsRequest::new("missing.exr", "out");
        r.rig = "nope".into();
        assert!(ViewsPlan::new(&r).is_err());
        let bound = crate::size::pictures(Format::Png, "a view", |s| (s as u64, s as u64));
        let mut v = rig::resolve("cube").unwrap().remove(0);
        v.fov = 180.0;
        let e = plan_view(v.clone(), None, &bound).unwrap_err();
        assert!(e.message.contains("(0°, 180°)"), "{}", e.message);
        v.fov = 90.0;
        v.width = Some(0);
        assert!(plan_view(v, None, &bound).is_err());
    }
}
