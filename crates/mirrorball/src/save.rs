//! Writing an environment map: the extension picks the container, the layout packs the
//! layers, KTX2/DDS cubes get their mip chain.

use crate::error::Error;
use crate::fit::{self, Report};
use crate::load::{layer_names, FACE};
use mirrorball_core::Choice;
use mirrorball_core::{EnvMap, Image, Layout, Projection, ProjectionKind, Stereo, WorldProjection};
use mirrorball_filter::MipChain;
use mirrorball_io::{Format, Hint, MapInfo, OutputSet, Precision, WriteOptions};
use std::path::{Path, PathBuf};

/// What to write.
pub struct SaveOptions {
    /// The layout of multi-layer maps in flat images (`None`: a cross for cubes, side by
    /// side for the paraboloid).
    pub layout: Option<Layout>,
    /// Container options.
    pub write: WriteOptions,
    /// Write the full mip chain into KTX2/DDS.
    pub mips: bool,
    /// Write NaN and infinite values where the container holds them (`--keep-invalid`),
    /// instead of 0.
    pub keep_invalid: bool,
}

/// What [`save`] wrote: the files, and what their storage could not hold ([`Report`]).
pub struct Saved {
    /// The files written.
    pub files: Vec<PathBuf>,
    /// The maps written, measured against the file's storage.
    pub report: Report,
}

/// The layout used when the user names none (by layer count; an EAC map's is v360's `eac`:
/// [`Layout::default_for`]).
pub fn default_layout(layers: usize) -> Layout {
    match layers {
        6 => Layout::HorizontalCross,
        2 => Layout::HorizontalStrip,
        _ => Layout::Separate,
    }
}

/// Whether a container takes a flag.
type TakesFlag = fn(Format) -> bool;

/// The flags that only some containers take, and which: the one table their refusals are
/// made from ([`check_flags`]). `--precision` takes its values from
/// [`Format::precisions`].
const CONTAINER_FLAGS: &[(&str, TakesFlag)] = &[
    ("--compression", |f| f == Format::Exr),
    ("--mips", Format::is_cube_container),
    ("--layout", |f| !f.is_cube_container()),
    ("--tone", |f| matches!(f, Format::Png | Format::Jpeg)),
];

/// The output's container, from `out`'s extension: one mirrorball writes (its folder is
/// `guard::Files`' to check). What the container alone decides, checked before anything is read.
pub fn check_container(out: &str) -> Result<Format, Error> {
    let path = Path::new(out);
    let written: Vec<&str> = Format::ALL
        .iter()
        .filter(|f| f.is_written())
        .map(|f| f.extension())
        .collect();
    let format = Format::from_path(path).ok_or_else(|| {
        Error::request(format!(
            "{out}: unknown output extension (use {})",
            written.join(" ")
        ))
    })?;
    if !format.is_written() {
        return Err(Error::request(format!(
            "{out}: {} is read-only here; write .png",
            format.name()
        )));
    }
    Ok(format)
}

/// Refuses a container flag `out`'s container does not take (`given`: the flags given,
/// as [`CONTAINER_FLAGS`] names them), and a `precision` it does not write: each names the
/// flag, the container and the containers (or values) that take it.
pub fn check_flags(
    out: &str,
    format: Format,
    given: &[&str],
    precision: Option<Precision>,
) -> Result<(), Error> {
    let container = format!("{} ({})", format.extension(), format.name());
    for (flag, takes) in CONTAINER_FLAGS {
        if given.contains(flag) && !takes(format) {
            let which: Vec<&str> = Format::ALL
                .iter()
                .filter(|f| f.is_written() && takes(**f))
                .map(|f| f.extension())
                .collect();
            return Err(Error::request(format!(
                "{out}: {flag} applies to {} outputs, not {container}",
                which.join(" ")
            )));
        }
    }
    match (precision, format.precisions()) {
        (Some(p), takes) if !takes.contains(&p) => {
            let takes: Vec<&str> = takes.iter().map(|p| p.name()).collect();
            Err(Error::request(format!(
                "{out}: --precision {} does not apply to {container}, which {}",
                p.name(),
                match takes.len() {
                    0 => "has one precision of its own".to_string(),
                    _ => format!("takes {}", takes.join(" or ")),
                }
            )))
        }
        _ => Ok(()),
    }
}

/// Checks that `out` can hold a map of `kind` before any work starts.
pub fn check(out: &str, kind: ProjectionKind, layout: Option<Layout>) -> Result<Format, Error> {
    let format = check_container(out)?;
    if format.is_cube_container() && kind != ProjectionKind::Cube {
        return Err(Error::request(format!(
            "{out}: KTX2 and DDS files are sampled by GPUs as OpenGL/Direct3D cube maps, so they hold --to cube only (not {kind})"
        )));
    }
    let layers = kind.default_projection().layer_count();
    if out.contains(FACE) && (layers == 1 || format.is_cube_container()) {
        return Err(Error::request(format!(
            "{out}: {FACE} in the name writes one file per layer, but {}",
            if layers == 1 {
                format!("a {kind} map has one layer; leave {FACE} out")
            } else {
                "KTX2 and DDS hold all six faces in one file; leave it out".to_string()
            }
        )));
    }
    if let Some(l) = layout {
        if let Some(why) = l.refusal(kind, "--to") {
            return Err(Error::request(format!("--layout {why}")));
        }
        if l != Layout::Separate && out.contains(FACE) {
            return Err(Error::request(format!(
                "{out}: {FACE} in the name writes one file per layer, which --layout {l} does not"
            )));
        }
    }
    Ok(format)
}

/// The folder of `out` made when missing (`Folders::MakeOne` checked it can be): the
/// folder, when this call made it, marked so that an interrupt removes it again if it is
/// left empty (`mirrorball_io::made_folder`).
pub fn make_folder(out: &Path) -> Result<Option<PathBuf>, Error> {
    let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) else {
        return Ok(None);
    };
    match std::fs::create_dir(dir) {
        Ok(()) => {
            mirrorball_io::made_folder(dir);
            Ok(Some(dir.to_path_buf()))
        }
        // Made meanwhile (another shard), or there already.
        Err(_) if dir.is_dir() => Ok(None),
        Err(e) => Err(Error::system(format!(
            "{}: cannot make the folder: {e}",
            dir.display()
        ))),
    }
}

/// The width and height of each picture `out` (checked by [`check`]) holds of a map of
/// `projection` at `size` (as `--size`), its eyes arranged as `stereo` says: a cube face in
/// a KTX2/DDS file, a layer in one file a layer, else the packed (and joined) picture.
pub fn picture_extent(
    out: &str,
    projection: Projection,
    size: u32,
    opts: &SaveOptions,
    stereo: Stereo,
) -> (u64, u64) {
    picture_extent_of(out, projection, projection.layer_extent(size), opts, stereo)
}

/// [`picture_extent`] of a map of `projection` whose layers are `w`×`h`.
fn picture_extent_of(
    out: &str,
    projection: Projection,
    (w, h): (u32, u32),
    opts: &SaveOptions,
    stereo: Stereo,
) -> (u64, u64) {
    let n = projection.layer_count();
    let format = Format::from_path(Path::new(out));
    if format.is_some_and(Format::is_cube_container) || layer_files(out, n, opts).is_some() {
        return (w as u64, h as u64);
    }
    let layout = match opts.layout {
        None if projection.kind() == ProjectionKind::Eac && !out.contains(FACE) => {
            Layout::default_for(projection.kind())
        }
        _ => output_layout(out, n, opts),
    };
    let (pw, ph) = layout.extent(n, w, h);
    let (sw, sh) = stereo.extent(pw, ph);
    (sw as u64, sh as u64)
}

/// The sizes (`--size`) of a map of `projection` that `out` holds and mirrorball reads back
/// ([`crate::size::pictures`]).
pub fn size_bound(
    out: &str,
    projection: Projection,
    opts: &SaveOptions,
    stereo: Stereo,
) -> crate::size::Bound {
    let format = Format::from_path(Path::new(out)).unwrap_or(Format::Exr);
    let what = match format.is_cube_container() {
        true => format!("{out}'s cube face"),
        false => format!("{out}'s picture"),
    };
    crate::size::pictures(format, &what, |s| {
        picture_extent(out, projection, s, opts, stereo)
    })
}

/// About the work of writing `maps` to `out` as [`save`] and [`save_eyes`] do (a cube
/// container's mips included), in the units the writers count (`mirrorball_io::write_work`):
/// what a bar over the writing runs to.
pub fn write_work(out: &str, maps: &[&EnvMap], opts: &SaveOptions) -> u64 {
    let Some(format) = Format::from_path(Path::new(out)) else {
        return 0;
    };
    // Each map's pictures: its faces in a cube container or one file a layer, else the
    // packed picture (a cross's empty cells are written too), its layers copied into it
    // first.
    let (mut written, mut packed) = (0u64, 0u64);
    for m in maps {
        let (w, h) = (m.width(), m.height());
        let layers = m.layers().len() as u64;
        let (pw, ph) = picture_extent_of(out, *m.projection(), (w, h), opts, Stereo::Mono);
        if format.is_cube_container() || layer_files(out, m.layers().len(), opts).is_some() {
            written += pw * ph * layers;
        } else {
            written += pw * ph;
            packed += w as u64 * h as u64 * layers;
        }
    }
    // A cube container's mips are made first (`MipChain::resampled`).
    let mut mips = 0;
    if opts.mips && format.is_cube_container() {
        written = written * 4 / 3;
        mips = maps.iter().map(|m| MipChain::resampled_work(m)).sum();
    }
    match mirrorball_io::write_work(format, written, &opts.write) {
        // Writers that count nothing: no bar at all, the packing alone would mislead it.
        0 => 0,
        w => w + mirrorball_core::work::PACK * packed + mips,
    }
}

/// The layout `out` gets for a map of `layers` layers.
fn output_layout(out: &str, layers: usize, opts: &SaveOptions) -> Layout {
    match opts.layout {
        Some(l) => l,
        None if out.contains(FACE) => Layout::Separate,
        None => default_layout(layers),
    }
}

/// The file of each layer, in layer order, when `out` (checked by [`check`]) takes a map of
/// `layers` layers as one file a layer (`{face}` in the name, or `--layout separate`);
/// `None` when it takes the whole map in one file.
pub fn layer_files(out: &str, layers: usize, opts: &SaveOptions) -> Option<Vec<PathBuf>> {
    let format = Format::from_path(Path::new(out))?;
    (!format.is_cube_container()
        && layers > 1
        && output_layout(out, layers, opts) == Layout::Separate)
        .then(|| {
            layer_names(layers)
                .iter()
                .map(|nm| layer_path(out, nm))
                .collect()
        })
}

/// The file for layer `name` of a separate-layout output.
fn layer_path(out: &str, name: &str) -> PathBuf {
    per_part_path(out, FACE, name)
}

/// `out` with `placeholder` replaced by `part`, or, without the placeholder, `_part` added
/// before the extension (`sky.exr` → `sky_px.exr`).
pub fn per_part_path(out: &str, placeholder: &str, part: &str) -> PathBuf {
    if out.contains(placeholder) {
        return PathBuf::from(out.replace(placeholder, part));
    }
    let p = Path::new(out);
    let stem = p
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ext = p
        .extension()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    p.with_file_name(format!("{stem}_{part}.{ext}"))
}

/// Writes `env` to `out`; returns the files written and what they could not hold.
pub fn save(env: &EnvMap, out: &str, opts: &SaveOptions) -> Result<Saved, Error> {
    save_eyes(std::slice::from_ref(env), Stereo::Mono, out, opts)
}

/// Refuses an output that cannot hold a stereo pair before any work starts: a pair
/// (`stereo` not `2d`) is one picture, so neither a KTX2/DDS cube nor one file a layer.
pub fn check_stereo(
    out: &str,
    layers: usize,
    stereo: Stereo,
    opts: &SaveOptions,
) -> Result<(), Error> {
    if stereo == Stereo::Mono {
        return Ok(());
    }
    let format = Format::from_path(Path::new(out));
    if format.is_some_and(Format::is_cube_container) {
        return Err(Error::request(format!(
            "{out}: --stereo {stereo} packs both eyes into one picture, which a KTX2 or DDS cube cannot hold; write .exr .hdr .png or .jpg"
        )));
    }
    if layer_files(out, layers, opts).is_some() {
        return Err(Error::request(format!(
            "{out}: --stereo {stereo} packs both eyes into one picture, not one file a layer; give a packed --layout (hcross, c3x2, hstrip, …) and no {FACE}"
        )));
    }
    Ok(())
}

/// The picture of `eyes` (one per eye of `stereo`, each of one projection and size): each
/// eye packed in `layout`, the eyes joined as `stereo` arranges them.
pub fn pack_eyes(eyes: &[EnvMap], stereo: Stereo, layout: Layout) -> Result<Image, Error> {
    let n = eyes[0].layers().len();
    let pictures = eyes
        .iter()
        .map(|e| layout.pack(e))
        .collect::<Option<Vec<Image>>>()
        .ok_or_else(|| {
            Error::request(format!(
                "layout {layout} does not fit a map of {}",
                mirrorball_core::count(n as u64, "layer")
            ))
        })?;
    stereo.join(pictures).ok_or_else(|| {
        Error::request(format!(
            "a {stereo} picture needs {} eye(s) of one size",
            stereo.eyes()
        ))
    })
}

/// Writes `eyes` (one map per eye of `stereo`; one map for `2d`) to `out`; returns the
/// files written and what their storage could not hold (each map measured before it is
/// written: [`fit::measure_maps`]). The file records one eye's projection and layout.
pub fn save_eyes(
    eyes: &[EnvMap],
    stereo: Stereo,
    out: &str,
    opts: &SaveOptions,
) -> Result<Saved, Error> {
    save_to(eyes, stereo, out, opts, None)
}

/// The bytes of the file [`save`] writes to `out` (a file name: its extension picks the
/// container, and messages name it), made by the same encoder, and what their storage
/// could not hold. One file a layer (`{face}`, `--layout separate`) is several files: refused.
pub fn to_bytes(env: &EnvMap, out: &str, opts: &SaveOptions) -> Result<(Vec<u8>, Report), Error> {
    let mut bytes = Vec::new();
    let saved = save_to(
        std::slice::from_ref(env),
        Stereo::Mono,
        out,
        opts,
        Some(&mut bytes),
    )?;
    Ok((bytes, saved.report))
}

/// [`save_eyes`] to the file `out`, or into `memory` (no file is written; [`Saved::files`]
/// is empty).
fn save_to(
    eyes: &[EnvMap],
    stereo: Stereo,
    out: &str,
    opts: &SaveOptions,
    memory: Option<&mut Vec<u8>>,
) -> Result<Saved, Error> {
    let env = &eyes[0];
    let path = Path::new(out);
    let format = check(out, env.projection().kind(), opts.layout)?;
    check_stereo(out, env.layers().len(), stereo, opts)?;
    let storage = format.storage(opts.write.precision);
    if format.is_cube_container() {
        let chain_made;
        let chain: &[EnvMap] = if opts.mips {
            chain_made = MipChain::resampled(env).into_levels();
            &chain_made
        } else {
            std::slice::from_ref(env)
        };
        let (chain, report) = fit::measure_maps(chain, storage, opts.keep_invalid);
        let levels: Vec<Vec<Image>> = chain.iter().map(|l| l.layers().to_vec()).collect();
        let mut write = opts.write;
        write.declared = Some(MapInfo {
            projection: *env.projection(),
            layout: None,
            stereo: Default::default(),
        });
        let files = match memory {
            Some(bytes) => {
                *bytes = mirrorball_io::write_bytes(&levels, Hint::Name(out), &write)?;
                vec![]
            }
            None => {
                mirrorball_io::write_cube(path, &levels, &write)?;
                vec![path.to_path_buf()]
            }
        };
        return Ok(Saved { files, report });
    }
    let (eyes, mut report) = fit::measure_maps(eyes, storage, opts.keep_invalid);
    report.part = "eye";
    let env = &eyes[0];
    let n = env.layers().len();
    let kind = env.projection().kind();
    let layout = match opts.layout {
        None if kind == ProjectionKind::Eac && !out.contains(FACE) => Layout::default_for(kind),
        _ => output_layout(out, n, opts),
    };
    if let Some(paths) = layer_files(out, n, opts) {
        if memory.is_some() {
            return Err(Error::request(format!(
                "{out}: one file a layer is several files; give one picture's layout (hcross, c3x2, …) and no {FACE}"
            )));
        }
        // Renamed into place together: a failed or interrupted run leaves the set as it was.
        let mut set = OutputSet::new(&per_layer_write(&opts.write, *env.projection()));
        set.push_all(&paths, env.layers())?;
        let files = set.finish()?;
        return Ok(Saved { files, report });
    }
    let mut write = opts.write;
    // Recorded in the file, so that reading it back needs no --from.
    write.declared = Some(MapInfo {
        projection: *env.projection(),
        layout: Some(layout),
        stereo,
    });
    let img = pack_eyes(&eyes, stereo, layout).map_err(|e| e.context(out))?;
    let files = match memory {
        Some(bytes) => {
            *bytes = mirrorball_io::write_bytes(&[vec![img]], Hint::Name(out), &write)?;
            vec![]
        }
        None => {
            mirrorball_io::write_image(path, &img, &write)?;
            vec![path.to_path_buf()]
        }
    };
    Ok(Saved { files, report })
}

/// Bytes [`save_eyes`] makes besides the maps it writes (`eyes` maps, each of `layers`
/// layers of `w`×`h` texels of `channels` `f32` channels, in projection `kind`): for a
/// KTX2/DDS cube, the levels copied for the writer (the mip chain first made when
/// `opts.mips`); for one file, the packed picture (a cross's empty cells included; a pair's
/// eyes packed and then joined) and the encoder's buffers; for one file a layer, nothing.
pub fn write_bytes(
    out: &str,
    kind: ProjectionKind,
    (w, h, layers): (u32, u32, usize),
    (eyes, channels): (usize, usize),
    opts: &SaveOptions,
) -> u64 {
    let texel = channels as u64 * 4;
    let map = w as u64 * h as u64 * layers as u64 * texel;
    let format = Format::from_path(Path::new(out));
    if format.is_some_and(Format::is_cube_container) {
        return match opts.mips {
            true => 2 * map * 4 / 3,
            false => map,
        };
    }
    if layer_files(out, layers, opts).is_some() {
        return 0;
    }
    let layout = match opts.layout {
        None if kind == ProjectionKind::Eac && !out.contains(FACE) => Layout::default_for(kind),
        _ => output_layout(out, layers, opts),
    };
    let (pw, ph) = layout.extent(layers, w, h);
    let pictures = pw as u64 * ph as u64 * eyes as u64 * texel;
    let (jw, jh) = match eyes {
        1 => (pw, ph),
        _ => Stereo::SideBySide.extent(pw, ph),
    };
    let encoder =
        mirrorball_io::write_buffer_bytes(Path::new(out), (jw, jh, channels), &opts.write);
    // A pair's eyes are packed, then joined into one picture: both held at once.
    encoder
        + match eyes {
            1 => pictures,
            _ => 2 * pictures,
        }
}

/// The options for one file a layer of a `projection` map: each file records the projection
/// (and the `separate` layout), so that `{face}` reads the set back without `--from`.
pub fn per_layer_write(
    write: &WriteOptions,
    projection: mirrorball_core::Projection,
) -> WriteOptions {
    WriteOptions {
        declared: Some(MapInfo {
            projection,
            layout: Some(Layout::Separate),
            stereo: Default::default(),
        }),
        ..*write
    }
}

/// The natural default edge for a conversion from `src` to `kind`
/// ([`EnvMap::natural_size`]: the power of two that keeps the source's texels per
/// steradian).
pub fn default_size(src: &EnvMap, kind: ProjectionKind) -> u32 {
    src.natural_size(kind)
}
