//! Reading an environment map: file(s) → layers → projection and layout, and what was
//! decided reported. Without `--from`, the projection is what the file records
//! (`mirrorball:projection`, `mirrorball:layout`), else what OpenEXR's `envmap` tag says (in
//! OpenEXR's conventions), else guessed from the picture's shape.

use crate::error::Error;
use crate::spec::ProjSpec;
use mirrorball_core::{
    guess, CubeMap, EnvMap, Image, LatLong, Layout, Projection, ProjectionKind, Stereo,
    WorldProjection,
};
use mirrorball_io::{openexr, Format, Limits, Loaded};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// How to read an input: its projection and layout when the caller knows them (else they
/// are read from the file or guessed), and whether NaN, infinite and negative values are
/// kept (else set to 0 and counted).
#[derive(Clone, Debug, Default)]
pub struct InputPlan {
    /// The projection, `NAME[:key=value…]` parsed; `None`: recorded in the file or guessed.
    pub from: Option<ProjSpec>,
    /// The layout of the layers in the picture; `None`: recorded or guessed.
    pub layout: Option<mirrorball_core::Layout>,
    /// Keep NaN, infinite and negative values.
    pub keep_invalid: bool,
}

/// The placeholder for per-layer file names.
pub const FACE: &str = "{face}";

/// Per-layer file-name parts: cube faces and paraboloid halves.
pub fn layer_names(layers: usize) -> &'static [&'static str] {
    match layers {
        6 => &["px", "nx", "py", "ny", "pz", "nz"],
        2 => &["front", "back"],
        _ => &[""],
    }
}

/// An environment map read from disk, with what was decided about it.
pub struct Source {
    /// The map.
    pub env: EnvMap,
    /// How the file was read: "OpenEXR, half, ZIP compression, RGB".
    pub description: String,
    /// How projection and layout were decided (said to the user).
    pub decided: String,
    /// The right eye, when a stereo pair was read with both eyes ([`load_eyes`]); of the
    /// same projection and size as [`Source::env`], the left.
    pub right: Option<EnvMap>,
    /// How the picture held its eyes (`2d`: one).
    pub stereo: Stereo,
    /// NaN, infinite and negative values in the file(s) as read
    /// (`mirrorball_io::Loaded::invalid`): none spares [`Source::prepare`] its pass over the
    /// whole map.
    pub invalid: u64,
}

impl Source {
    /// One map, no second eye.
    fn one(env: EnvMap, description: String, decided: String, invalid: u64) -> Source {
        Source {
            env,
            description,
            decided,
            right: None,
            stereo: Stereo::Mono,
            invalid,
        }
    }

    /// What was read and decided, for the user, after replacing NaN, infinite and negative
    /// texels by 0 unless `keep_invalid` (with a warning when any were).
    pub fn prepare(&mut self, input: &str, keep_invalid: bool) -> Vec<String> {
        let env = &self.env;
        let layers = if env.layers().len() > 1 {
            format!(" x{}", env.layers().len())
        } else {
            String::new()
        };
        let mut lines = vec![format!(
            "read {input} ({}): {} {}x{}{layers} — {}",
            self.description,
            env.projection().name(),
            env.width(),
            env.height(),
            self.decided
        )];
        let maps = std::iter::once(&mut self.env).chain(self.right.as_mut());
        lines.extend(zero_invalid(input, maps, self.invalid, keep_invalid));
        lines
    }
}

/// Sets the NaN, infinite and negative colour values of `maps` (what `input` gave) to 0
/// unless `keep_invalid`, when `invalid` (counted as they were read) says there are any;
/// the warning that says so, when any were. Every reader's rule: files and raw frames.
pub fn zero_invalid<'a>(
    input: &str,
    maps: impl IntoIterator<Item = &'a mut EnvMap>,
    invalid: u64,
    keep_invalid: bool,
) -> Option<String> {
    if keep_invalid || invalid == 0 {
        return None;
    }
    let fixed: u64 = maps.into_iter().map(EnvMap::sanitize).sum();
    (fixed > 0).then(|| {
        format!(
            "warning: {input}: {fixed} NaN, infinite or negative values set to 0 (--keep-invalid keeps them)"
        )
    })
}

/// Reads `input` as `plan` says and prepares it ([`Source::prepare`]): the map, and the
/// lines saying what was read and decided (the first steps of `prefilter` and `bake`).
pub fn read_prepared(input: &str, plan: &InputPlan) -> Result<(EnvMap, Vec<String>), Error> {
    let limits = Limits::default();
    let mut src = load(input, plan.from.as_ref(), plan.layout, &limits)?;
    let notes = src.prepare(input, plan.keep_invalid);
    Ok((src.env, notes))
}

/// Reads `input`: one file, or one per layer when the name holds `{face}`.
pub fn load(
    input: &str,
    from: Option<&ProjSpec>,
    layout: Option<Layout>,
    limits: &Limits,
) -> Result<Source, Error> {
    load_eyes(input, from, layout, (None, Stereo::Mono), limits)
}

/// [`load`] for a picture that may be a stereo pair: arranged as `stereo.0` says, else as
/// the file records, else one eye (`2d`). The eyes a conversion to `stereo.1` needs are read
/// (`Stereo::eyes_read`): the left into [`Source::env`], the right into
/// [`Source::right`]. Each eye is interpreted as `from` and `layout` say (or as the file
/// records or its shape says), the same way. A pair is one picture: a cube container or
/// `{face}` files are refused, and so is a picture that does not halve evenly.
pub fn load_eyes(
    input: &str,
    from: Option<&ProjSpec>,
    layout: Option<Layout>,
    (asked, output): (Option<Stereo>, Stereo),
    limits: &Limits,
) -> Result<Source, Error> {
    let one_picture = |stereo: Stereo, what: &str| {
        Error::request(format!(
            "{input}: --in-stereo {stereo} splits one picture into eyes, but {what}"
        ))
    };
    if input.contains(FACE) {
        if let Some(s) = asked.filter(|s| *s != Stereo::Mono) {
            return Err(one_picture(s, &format!("{FACE} names one file per layer")));
        }
        return load_layers(input, from, limits);
    }
    let loaded = mirrorball_io::read(Path::new(input), limits)?;
    interpret_loaded(input, loaded, from, layout, (asked, output))
}

/// Reads a file's contents held in memory as [`load`] reads the file (the same reader, the
/// same projection and layout decisions): `name` is the file's name, whose extension says
/// the container (else the bytes' signature does) and which messages name.
///
/// ```
/// use mirrorball::core::{EnvMap, Image, LatLong, Projection};
/// use mirrorball::{load, save, SaveOptions};
/// let env = EnvMap::new(Projection::LatLong(LatLong), vec![Image::new(16, 8, 3)]).unwrap();
/// let opts = SaveOptions { layout: None, write: Default::default(), mips: false, keep_invalid: false };
/// let (bytes, _) = save::to_bytes(&env, "sky.exr", &opts).unwrap();
/// let back = load::from_bytes("upload.exr", &bytes, None, None, &Default::default()).unwrap();
/// assert_eq!(back.env.projection().name(), "latlong");
/// ```
pub fn from_bytes(
    name: &str,
    bytes: &[u8],
    from: Option<&ProjSpec>,
    layout: Option<Layout>,
    limits: &Limits,
) -> Result<Source, Error> {
    let loaded = mirrorball_io::read_bytes(bytes, mirrorball_io::Hint::Name(name), limits)?;
    interpret_loaded(name, loaded, from, layout, (None, Stereo::Mono))
}

/// What a file records (see `mirrorball_io::MapInfo`): unreadable, it matters only when
/// nothing else says the projection (`from`).
fn recorded_info(
    input: &str,
    recorded: Option<Result<mirrorball_io::MapInfo, mirrorball_io::Error>>,
    from: Option<&ProjSpec>,
) -> Result<Option<mirrorball_io::MapInfo>, Error> {
    match recorded {
        Some(Err(e)) if from.is_none() => Err(Error::input(format!(
            "{input}: {}; say the projection with --from",
            e.problem()
        ))),
        Some(r) => Ok(r.ok()),
        None => Ok(None),
    }
}

/// A one-picture map whose texels are sRGB codes in the caller's buffer ([`read_coded`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CodedMap {
    /// The projection, decided as [`load`] decides it.
    pub projection: Projection,
    /// Texels across and down.
    pub extent: (u32, u32),
    /// 16-bit codes (little-endian on the machines this runs on), else 8-bit.
    pub wide: bool,
}

impl CodedMap {
    /// The codes in `bytes` (what [`read_coded`] left there) as core reads them, through
    /// io's sRGB tables: the same values [`load`] decodes.
    pub fn codes<'a>(&self, bytes: &'a [u8]) -> Option<mirrorball_core::Codes<'a>> {
        if self.wide && cfg!(target_endian = "little") {
            let table = mirrorball_io::srgb16_to_linear();
            mirrorball_core::Codes::u16le(bytes, table, self.extent).ok()
        } else if self.wide {
            None
        } else {
            let table = mirrorball_io::srgb8_to_linear();
            mirrorball_core::Codes::u8(bytes, table, self.extent).ok()
        }
    }
}

/// Reads `input` as [`read_prepared`] does, but into `buf` as the file's sRGB codes with no
/// float copy, where the file is a PNG or JPEG of RGB samples that is one layer as it is
/// (no `{face}` files, no stereo pair, no packed layout): the map's shape and the lines
/// saying what was read and decided (8- and 16-bit samples hold no invalid values).
/// `Ok(None)` for any other input: [`read_prepared`] reads it.
pub fn read_coded(
    input: &str,
    plan: &InputPlan,
    buf: &mut Vec<u8>,
) -> Result<Option<(CodedMap, Vec<String>)>, Error> {
    if input.contains(FACE) {
        return Ok(None);
    }
    let limits = Limits::default();
    let Some(pic) = mirrorball_io::read_codes(Path::new(input), &limits, buf)? else {
        return Ok(None);
    };
    let from = plan.from.as_ref();
    let recorded = recorded_info(input, pic.recorded, from)?;
    if recorded.as_ref().is_some_and(|r| r.stereo != Stereo::Mono) {
        return Ok(None);
    }
    let records_other = |p: &Projection| match &recorded {
        Some(info) if info.projection != *p => format!("; the file records {}", info.projection),
        _ => String::new(),
    };
    let (w, h) = (pic.width, pic.height);
    let (projection, layout, decided) = decide(
        input,
        (w, h),
        from,
        plan.layout,
        recorded,
        None,
        records_other,
    )?;
    if layout != Layout::Separate || projection.layer_count() != 1 {
        return Ok(None);
    }
    let note = format!(
        "read {input} ({}): {} {w}x{h} — {decided}",
        pic.description,
        projection.name()
    );
    let map = CodedMap {
        projection,
        extent: (w, h),
        wide: pic.wide,
    };
    Ok(Some((map, vec![note])))
}

/// The map in what the reader gave for `input` (a file, or bytes so named): [`load_eyes`]
/// once the container is read.
fn interpret_loaded(
    input: &str,
    loaded: Loaded,
    from: Option<&ProjSpec>,
    layout: Option<Layout>,
    (asked, output): (Option<Stereo>, Stereo),
) -> Result<Source, Error> {
    let one_picture = |stereo: Stereo, what: &str| {
        Error::request(format!(
            "{input}: --in-stereo {stereo} splits one picture into eyes, but {what}"
        ))
    };
    let invalid = loaded.invalid();
    let Loaded {
        layers,
        declared,
        recorded,
        format,
        description,
        ..
    } = loaded;
    let recorded = recorded_info(input, recorded, from)?;
    // Said after "as asked" when the file says something else.
    let records_other = |p: &Projection| match (&recorded, declared) {
        (Some(info), _) if info.projection != *p => {
            format!("; the file records {}", info.projection)
        }
        (None, Some(kind)) if format == Format::Exr => {
            format!("; the file's envmap={kind} tag (OpenEXR's convention) is not followed")
        }
        _ => String::new(),
    };
    let stereo = asked
        .or(recorded.as_ref().map(|r| r.stereo))
        .unwrap_or_default();
    if layers.len() == 6 && stereo != Stereo::Mono {
        return Err(one_picture(stereo, "the file holds six cube faces"));
    }
    if layers.len() == 6 {
        let (env, decided) = cube_container(input, layers, from, &recorded, records_other)?;
        return Ok(Source::one(env, description, decided, invalid));
    }
    let image = layers
        .into_iter()
        .next()
        .ok_or_else(|| Error::input(format!("{input}: no image")))?;
    // OpenEXR's `envmap` tag, when it alone says the projection: its pictures follow
    // OpenEXR's conventions (ImfEnvmap), turned into mirrorball's here.
    let tagged = stereo == Stereo::Mono
        && from.is_none()
        && layout.is_none()
        && recorded.is_none()
        && format == Format::Exr;
    if let Some((env, decided)) = declared
        .filter(|_| tagged)
        .map(|kind| openexr_tagged(input, &image, kind))
        .transpose()?
        .flatten()
    {
        return Ok(Source::one(env, description, decided.into(), invalid));
    }
    let (env, right, decided) = interpret_eyes(
        input,
        image,
        (stereo, stereo.eyes_read(output)),
        from,
        layout,
        recorded,
        declared,
        records_other,
    )?;
    Ok(Source {
        env,
        description,
        decided,
        right,
        stereo,
        invalid,
    })
}

/// [`interpret`] for a picture arranged as `stereo.0`: split into its first `stereo.1` eyes
/// (a size that does not halve is the request's error, naming `input`), each eye
/// interpreted alike. Returns the left eye, the right when read, and the decision's words.
#[allow(clippy::too_many_arguments)]
pub fn interpret_eyes(
    input: &str,
    image: Image,
    (stereo, eyes): (Stereo, usize),
    from: Option<&ProjSpec>,
    layout: Option<Layout>,
    recorded: Option<mirrorball_io::MapInfo>,
    declared: Option<ProjectionKind>,
    records_other: impl Fn(&Projection) -> String,
) -> Result<(EnvMap, Option<EnvMap>, String), Error> {
    let (w, h) = (image.width(), image.height());
    let mut pictures = stereo
        .split(image, eyes)
        .map_err(|e| Error::request(format!("{input}: --in-stereo {stereo}: {e}")))?
        .into_iter();
    let left = pictures.next().expect("a picture has an eye");
    let (env, decided) = interpret(
        input,
        left,
        from,
        layout,
        recorded,
        declared,
        &records_other,
    )?;
    let right = pictures
        .next()
        .map(|eye| interpret(input, eye, from, layout, recorded, declared, &records_other))
        .transpose()?
        .map(|r| r.0);
    let decided = match stereo {
        Stereo::Mono => decided,
        _ => {
            let (ew, eh) = stereo.extent(1, 1);
            format!(
                "a {stereo} stereo pair, eyes {}x{} of {w}x{h}{}; each eye {decided}",
                w / ew,
                h / eh,
                if right.is_none() {
                    " (the left eye read)"
                } else {
                    ""
                }
            )
        }
    };
    Ok((env, right, decided))
}

/// The map in one picture read from `input` (a file, or a raw frame from a pipe): its
/// projection and layout as asked (`from`, `layout`), else as `recorded` in the file, else
/// guessed from its shape (`declared` by the container helps the guess); `note` adds what
/// the file says otherwise to the decision's words. Returns the map and those words.
pub fn interpret(
    input: &str,
    image: Image,
    from: Option<&ProjSpec>,
    layout: Option<Layout>,
    recorded: Option<mirrorball_io::MapInfo>,
    declared: Option<ProjectionKind>,
    records_other: impl Fn(&Projection) -> String,
) -> Result<(EnvMap, String), Error> {
    let (w, h) = (image.width(), image.height());
    let (proj, layout, decided) = decide(
        input,
        (w, h),
        from,
        layout,
        recorded,
        declared,
        records_other,
    )?;
    let env = layout
        .unpack_owned(image, proj)
        .map_err(|e| Error::input(format!("{input}: {e}")))?;
    Ok((env, decided))
}

/// What [`interpret`] decides of a `w`×`h` picture before it is unpacked: its projection
/// and layout, checked against its shape, and the decision's words (a picture held as codes
/// is decided so with no float copy of it).
pub fn decide(
    input: &str,
    (w, h): (u32, u32),
    from: Option<&ProjSpec>,
    layout: Option<Layout>,
    recorded: Option<mirrorball_io::MapInfo>,
    declared: Option<ProjectionKind>,
    records_other: impl Fn(&Projection) -> String,
) -> Result<(Projection, Layout, String), Error> {
    let (proj, layout, decided) = match (from, layout, recorded) {
        (Some(spec), Some(l), _) => {
            if let Some(why) = l.refusal(spec.kind, "--from") {
                return Err(Error::request(format!("--in-layout {why}")));
            }
            let proj = build_from(spec, w, h)?;
            let note = records_other(&proj);
            (proj, l, format!("as asked{note}"))
        }
        (Some(spec), None, _) => {
            let (l, _, _) = Layout::from_extent_of(w, h, spec.kind)
                .ok_or_else(|| no_layout(input, w, h, spec.kind))?;
            let proj = build_from(spec, w, h)?;
            let note = records_other(&proj);
            (proj, l, format!("as asked; {w}x{h} fits {l}{note}"))
        }
        (None, asked, Some(info)) => {
            let proj = info.projection;
            let n = proj.layer_count();
            let l = match asked.or(info.layout) {
                Some(l) => l,
                None => {
                    Layout::from_extent(w, h, n)
                        .ok_or_else(|| no_layout(input, w, h, proj.kind()))?
                        .0
                }
            };
            let how = if n == 1 {
                String::new()
            } else if asked.is_some() {
                format!(", {l} as asked")
            } else {
                format!(", {l}")
            };
            (proj, l, format!("{proj}{how}, recorded in the file"))
        }
        (None, _, None) => {
            let g = guess(w, h, declared).ok_or_else(|| {
                Error::input(format!(
                    "{input}: cannot tell the projection of a {w}x{h} picture (2:1 is lat-long, 4:3, 3:4, 6:1 and 1:6 are cube layouts, 1:1 a sphere map); say it with --from"
                ))
            })?;
            let l = layout.unwrap_or(g.layout);
            let proj = build_from(&ProjSpec::of(g.kind), w, h)?;
            let note = records_other(&proj);
            (
                proj,
                l,
                format!(
                    "guessed {} {}: {} (override with --from/--in-layout){note}",
                    g.kind, g.layout, g.reason
                ),
            )
        }
    };
    if layout == Layout::Separate && proj.layer_count() > 1 {
        return Err(Error::request(format!(
            "{input}: a {} map has {} layers; give one file per layer with {FACE} in the name, or a packed layout",
            proj.kind(),
            proj.layer_count()
        )));
    }
    check_shape(input, &proj, w, h, layout)?;
    Ok((proj, layout, decided))
}

/// The projection `spec` names, for a `w`×`h` picture.
fn build_from(spec: &ProjSpec, w: u32, h: u32) -> Result<Projection, Error> {
    spec.build(Some((w, h)))
        .map_err(|e| Error::request(format!("--from: {e}")))
}

fn no_layout(input: &str, w: u32, h: u32, kind: ProjectionKind) -> Error {
    Error::input(format!(
        "{input}: a {w}x{h} picture fits no layout of a {kind} map (six square faces: 4:3 or 3:4 cross, 6:1 or 1:6 strip; two halves: 2:1 or 1:2)"
    ))
}

/// Single-layer projections have a natural shape; refuse pictures far from it.
fn check_shape(
    input: &str,
    proj: &mirrorball_core::Projection,
    w: u32,
    h: u32,
    layout: Layout,
) -> Result<(), Error> {
    if layout != Layout::Separate || proj.layer_count() != 1 {
        return Ok(());
    }
    let (ew, eh) = proj.layer_extent(w);
    let ratio_err = ((h as f64) - (eh as f64)).abs() / eh as f64;
    if proj.kind() != ProjectionKind::Mercator && ratio_err > 0.01 {
        return Err(Error::input(format!(
            "{input}: a {} map is {}:{} ({ew}x{eh} for this width) but the picture is {w}x{h}; use --from to read it as another projection",
            proj.name(),
            ew / gcd(ew, eh),
            eh / gcd(ew, eh)
        )));
    }
    Ok(())
}

fn gcd(a: u32, b: u32) -> u32 {
    if b == 0 {
        a.max(1)
    } else {
        gcd(b, a % b)
    }
}

/// The projection of a multi-layer input: as asked, or a cube.
fn multi_layer(from: Option<&ProjSpec>) -> Result<(ProjSpec, Projection), Error> {
    let spec = from
        .cloned()
        .unwrap_or_else(|| ProjSpec::of(ProjectionKind::Cube));
    let proj = spec
        .build(None)
        .map_err(|e| Error::request(format!("--from: {e}")))?;
    Ok((spec, proj))
}

/// A cube container's six faces (KTX2, DDS) as the map `from` or the file's record says.
fn cube_container(
    input: &str,
    layers: Vec<Image>,
    from: Option<&ProjSpec>,
    recorded: &Option<mirrorball_io::MapInfo>,
    records_other: impl Fn(&Projection) -> String,
) -> Result<(EnvMap, String), Error> {
    // A cube container: KTX2 or DDS.
    let (spec, proj) = match (recorded, from) {
        (Some(info), None) if info.projection.layer_count() == 6 => {
            (info.projection.spec(), info.projection)
        }
        _ => multi_layer(from)?,
    };
    if proj.layer_count() != 6 {
        return Err(Error::request(format!(
            "{input}: holds six cube faces, which cannot be read as {}",
            spec.kind
        )));
    }
    let decided = match (recorded, from) {
        (Some(_), None) => format!("{proj}, recorded in the file"),
        _ => format!(
            "{} (six faces in the container){}",
            spec.kind,
            records_other(&proj)
        ),
    };
    let env = EnvMap::new(proj, layers).map_err(|e| Error::input(format!("{input}: {e}")))?;
    Ok((env, decided))
}

/// A picture whose OpenEXR `envmap` tag alone says its projection, in OpenEXR's conventions
/// (ImfEnvmap) turned into mirrorball's, with what was decided; `None` for other tags.
fn openexr_tagged(
    input: &str,
    image: &Image,
    kind: ProjectionKind,
) -> Result<Option<(EnvMap, &'static str)>, Error> {
    let bad = |e: &dyn std::fmt::Display| Error::input(format!("{input}: {e}"));
    Ok(match kind {
        ProjectionKind::LatLong => Some((
            EnvMap::new(LatLong.into(), vec![openexr::latlong_to_mirrorball(image)])
                .map_err(|e| bad(&e))?,
            "the file is tagged envmap=latlong: OpenEXR's lat-long (+Z at the centre), turned half a turn into mirrorball's (--from latlong reads the picture as mirrorball's)",
        )),
        ProjectionKind::Cube => Some((
            EnvMap::new(
                CubeMap.into(),
                openexr::cube_to_faces(image, Path::new(input))?,
            )
            .map_err(|e| bad(&e))?,
            "the file is tagged envmap=cube: OpenEXR's vertical strip of faces, read into OpenGL's faces (--from cube --layout vstrip reads the picture as mirrorball's strip)",
        )),
        _ => None,
    })
}

/// Reads one file per layer: `{face}` becomes px nx py ny pz nz (cube) or front back.
///
/// Without `--from`: the projection the files record (each face file mirrorball writes
/// records it), else a cube, or a dual paraboloid when only `front`/`back` files exist.
fn load_layers(input: &str, from: Option<&ProjSpec>, limits: &Limits) -> Result<Source, Error> {
    let guessed = from.is_none()
        && !Path::new(&input.replace(FACE, "px")).exists()
        && Path::new(&input.replace(FACE, "front")).exists();
    let (spec, proj) = if guessed {
        let spec = ProjSpec::of(ProjectionKind::Paraboloid);
        let proj = spec
            .build(None)
            .map_err(|e| Error::request(format!("--from: {e}")))?;
        (spec, proj)
    } else {
        multi_layer(from)?
    };
    let names = layer_names(proj.layer_count());
    if names.len() < 2 {
        return Err(Error::request(format!("{input}: {FACE} files need a projection with several layers (cube, continuous-cube, paraboloid), not {}", spec.kind)));
    }
    let paths: Vec<PathBuf> = names
        .iter()
        .map(|n| PathBuf::from(input.replace(FACE, n)))
        .collect();
    let loaded: Vec<Loaded> = paths
        .par_iter()
        .map(|p| mirrorball_io::read(p, limits))
        .collect::<Result<_, _>>()?;
    // Counted in every file, or not known.
    let invalid = loaded.iter().map(Loaded::invalid).sum();
    // The projection every file records, when they agree and it has this many layers.
    let recorded = match (from, &loaded[0].recorded) {
        (None, Some(Ok(info)))
            if info.projection.layer_count() == proj.layer_count()
                && loaded.iter().all(
                    |l| matches!(&l.recorded, Some(Ok(i)) if i.projection == info.projection),
                ) =>
        {
            Some(info.projection)
        }
        _ => None,
    };
    let (proj, decided) = match recorded {
        Some(p) => (
            p,
            format!("{p} from one file per layer, recorded in the files"),
        ),
        None => (
            proj,
            format!(
                "{} from one file per layer{}",
                spec.kind,
                if from.is_some() {
                    ""
                } else {
                    " (guessed from the file names; --from overrides)"
                }
            ),
        ),
    };
    let mut layers: Vec<Image> = Vec::new();
    for (l, p) in loaded.into_iter().zip(&paths) {
        let img = l
            .layers
            .into_iter()
            .next()
            .ok_or_else(|| Error::input(format!("{}: no image", p.display())))?;
        if img.width() != img.height() {
            return Err(Error::input(format!(
                "{}: a face must be square, this one is {}x{}",
                p.display(),
                img.width(),
                img.height()
            )));
        }
        layers.push(img);
    }
    let c = layers.iter().map(|l| l.channels()).max().unwrap_or(3);
    let layers: Vec<Image> = layers.iter().map(|l| l.with_channels(c)).collect();
    let env = EnvMap::new(proj, layers).map_err(|e| Error::input(format!("{input}: {e}")))?;
    Ok(Source {
        env,
        description: format!("{} files", names.len()),
        decided,
        right: None,
        stereo: Stereo::Mono,
        invalid,
    })
}
