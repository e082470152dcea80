//! Environment-map files for mirrorball: OpenEXR, Radiance HDR, PNG, JPEG (and WebP in),
//! KTX2 and DDS cube maps. Everything that touches the file system lives here, so the core
//! crate stays free of I/O.
//!
//! Reading gives linear `f32` [`Image`]s (sRGB-encoded 8/16-bit files are decoded to linear
//! light); writing goes to a temporary file beside the target that is renamed into place, so
//! a failed write never leaves a half-written output, and files that belong together (an
//! [`OutputSet`]) are renamed into place together. Every error names the file and says
//! whose fault it is ([`Fault`]).
//!
//! **What a file says about its map.** Written maps record their projection with every
//! parameter ([`MapInfo`], the text of [`Projection`]'s `Display`) and, for several layers
//! packed into one picture, the [`Layout`], where the container has a place for text:
//! OpenEXR string attributes, KTX2 key/value data, PNG `tEXt` chunks, a JPEG comment
//! segment and Radiance header lines, each under the keys [`PROJECTION_KEY`] and
//! [`LAYOUT_KEY`]; a stereo pair records its arrangement in the layout text ([`MapInfo`]).
//! DDS files record nothing: DDS has no place for text.
//! Reading gives them back as [`Loaded::recorded`]. OpenEXR's own `envmap` attribute is
//! reported as [`Loaded::declared`]; its pictures follow OpenEXR's conventions, which
//! [`openexr`] converts to mirrorball's. mirrorball does not write `envmap`.
#![warn(missing_docs)]

mod alloc;
mod apng;
mod atomic;
mod babylon_env;
mod bounds;
mod dds_io;
mod destination;
mod error;
mod exr_io;
mod exr_zip;
mod gltf_ibl;
mod hdr_io;
mod input;
mod ktx1_io;
mod ktx2_io;
mod ldr_io;
mod meta_text;
pub mod openexr;
mod output;
mod owned;
mod pipe_size;
mod rgba_png;
mod sh_file;

pub use alloc::HugePages;
pub use apng::write_apng;
pub use atomic::{
    atomic_write, interrupted, keep_folder, made_folder, removed_leftovers, with_scratch,
    write_together,
};
pub use babylon_env::{read_babylon_env, write_babylon_env, BabylonEnv};
pub use dds_io::write_dds;
pub use destination::{check_writable, file_system, free_bytes, output_folder, Folders};
pub use error::{Error, Fault};
pub use gltf_ibl::{read_gltf_ibl, write_gltf_ibl, GltfIbl};
pub use hdr_io::rgbe_work;
pub use ktx1_io::{filament_sh_text, write_ktx1};
pub use ktx2_io::{write_ktx2, zstd_work, CubeWrite};
/// sRGB encoding's one home: 8-bit codes by the thresholds between codes, 16-bit codes.
pub use ldr_io::{encode16 as srgb16_code, encode8 as srgb8_code, thresholds8 as srgb8_thresholds};
pub use ldr_io::{
    encode_codes, grey_png, lut16 as srgb16_to_linear, lut8 as srgb8_to_linear, write_grey_png,
    write_jpeg_with_segments, CodedPicture,
};
pub use meta_text::read_xmp;
pub use mirrorball_encode::{Clipped, Effort, Encoding, Range, Storage};
pub use output::OutputSet;
pub use owned::{Owned, RECORD};
pub use pipe_size::{widen_pipe, PIPE_BYTES};
pub use rgba_png::Rgba8Face;
pub use sh_file::{read_sh, ShFile, SH_PROJECTION};

use atomic::Staged;
use exr_io::WriteBuffers;

use mirrorball_core::projection::ProjectionSpec;
use mirrorball_core::{Image, Layout, Projection, ProjectionKind, Stereo, WorldProjection};
use std::path::Path;

/// The key under which files record their projection (see [`MapInfo`]).
pub const PROJECTION_KEY: &str = "mirrorball:projection";
/// The key under which files record how several layers are packed into one picture.
pub const LAYOUT_KEY: &str = "mirrorball:layout";

/// What mirrorball records about the map in a file it writes: the projection with every
/// parameter, the layout of a multi-layer map packed into one picture, and whether the
/// picture is a stereo pair.
///
/// A stereo pair is recorded in the layout text, before the eye's layout and a `/`:
/// `sbs/c3x2`, `tb/separate` (the layout of each eye; see [`Stereo`]). One text keeps
/// OpenEXR headers the same from run to run (see `exr_io`), and a reader that knows no
/// stereo refuses the layout rather than misreading the picture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapInfo {
    /// The projection, recorded as its canonical text (`fisheye:fov=190:lens=equisolid:look=0,1,0`).
    pub projection: Projection,
    /// How the layers are packed into the picture (recorded only for maps of several
    /// layers, or for each eye of a stereo pair).
    pub layout: Option<Layout>,
    /// How the picture holds its eyes: [`Stereo::Mono`] for one.
    pub stereo: Stereo,
}

impl MapInfo {
    /// The texts to record under [`PROJECTION_KEY`] and [`LAYOUT_KEY`].
    pub fn texts(&self) -> (String, Option<String>) {
        let layout = self
            .layout
            .filter(|_| self.projection.layer_count() > 1 || self.stereo != Stereo::Mono)
            .map(|l| l.name().to_string());
        let layout = match self.stereo {
            Stereo::Mono => layout,
            s => Some(format!(
                "{s}/{}",
                layout.as_deref().unwrap_or(Layout::Separate.name())
            )),
        };
        (self.projection.to_string(), layout)
    }

    /// Reads the texts recorded in `path` back for a `w`×`h` picture (whose shape, an
    /// eye's for a stereo pair, fixes a Mercator map's latitude limit when the text has
    /// none). The error, the input's, names the file and says what was recorded and why it
    /// cannot be read.
    pub fn from_texts(
        path: &Path,
        projection: &str,
        layout: Option<&str>,
        w: u32,
        h: u32,
    ) -> Result<MapInfo, Error> {
        let unreadable = |key: &str, text: &str, e: &dyn std::fmt::Display| {
            Error::input(
                path,
                format!("records {key} = '{text}', which cannot be read ({e})"),
            )
        };
        let text = layout.unwrap_or_default();
        let (stereo, layout) = match layout.and_then(|l| l.split_once('/')) {
            Some((s, l)) => {
                let stereo = s
                    .trim()
                    .parse::<Stereo>()
                    .map_err(|e| unreadable(LAYOUT_KEY, text, &e))?;
                (stereo, Some(l))
            }
            None => (Stereo::Mono, layout),
        };
        let (w, h) = stereo
            .eye_extent(w, h)
            .map_err(|e| unreadable(LAYOUT_KEY, text, &e))?;
        let projection = ProjectionSpec::parse(projection)
            .and_then(|s| s.build(Some((w, h))))
            .map_err(|e| unreadable(PROJECTION_KEY, projection, &e))?;
        let layout = layout
            .map(|l| {
                l.trim()
                    .parse::<Layout>()
                    .map_err(|e| unreadable(LAYOUT_KEY, l, &e))
            })
            .transpose()?;
        Ok(MapInfo {
            projection,
            layout,
            stereo,
        })
    }
}

/// File formats mirrorball reads and writes, chosen by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// OpenEXR (`.exr`): half or float, any compression the `exr` crate decodes.
    Exr,
    /// Radiance RGBE (`.hdr`, `.pic`).
    Hdr,
    /// PNG, 8 or 16 bits, sRGB transfer.
    Png,
    /// JPEG, 8 bits, sRGB transfer.
    Jpeg,
    /// WebP (read only), sRGB transfer.
    Webp,
    /// KTX 2.0 cube map (Khronos), RGBA16F or RGBA32F, optional mip chain.
    Ktx2,
    /// DirectDraw Surface cube map (DX10 header), RGBA16F or RGBA32F, optional mip chain.
    Dds,
    /// KTX 1.1 cube map as Filament's cmgen writes it (`.ktx`; read here, written by `bake
    /// --for filament` through [`write_ktx1`]).
    Ktx1,
    /// Babylon.js environment (`.env`: RGBD PNG faces; read here, written by `bake --for
    /// babylon` through [`write_babylon_env`]).
    BabylonEnv,
    /// glTF with an `EXT_lights_image_based` light (`.gltf`; read here, written by `bake
    /// --for gltf` through [`write_gltf_ibl`]).
    GltfIbl,
}

impl Format {
    /// The format of `path`'s extension, case-insensitively.
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "exr" => Format::Exr,
            "hdr" | "pic" | "rgbe" => Format::Hdr,
            "png" => Format::Png,
            "jpg" | "jpeg" => Format::Jpeg,
            "webp" => Format::Webp,
            "ktx2" => Format::Ktx2,
            "dds" => Format::Dds,
            "ktx" => Format::Ktx1,
            "env" => Format::BabylonEnv,
            "gltf" => Format::GltfIbl,
            _ => return None,
        })
    }

    /// Whether the format holds a whole cube (six faces) in one file that [`write_cube`]
    /// writes (the engines' bundles, [`Format::is_bundle`], are written by `bake`).
    pub fn is_cube_container(self) -> bool {
        matches!(self, Format::Ktx2 | Format::Dds)
    }

    /// Whether the format is an engine's lighting bundle, read for its level-0 cube and
    /// written only by `bake`: KTX1, Babylon's `.env`, glTF's image-based light.
    pub fn is_bundle(self) -> bool {
        matches!(self, Format::Ktx1 | Format::BabylonEnv | Format::GltfIbl)
    }

    /// How a file of this format written with `precision` (`None`: its natural one) stores
    /// colour values: its writer writes each as this storage's [`Range::fit`] makes it.
    pub fn storage(self, precision: Option<Precision>) -> Storage {
        match (self, precision) {
            (Format::Hdr, _) => Storage::Rgbe,
            (Format::Png, Some(Precision::U16)) => Storage::Display16,
            (Format::Png | Format::Jpeg | Format::Webp, _) => Storage::Display8,
            (_, Some(Precision::Float)) => Storage::Texels(Encoding::Rgba32F),
            _ => Storage::Texels(Encoding::Rgba16F),
        }
    }
    /// The largest side of a picture (of a cube face, for KTX2 and DDS) a file of this
    /// format holds: a JPEG's 16-bit fields; for the GPU containers [`MAX_CUBE_FACE`]; the
    /// others' fields are 32-bit (mirrorball's reading bounds, [`Limits`], are tighter).
    pub fn max_side(self) -> u64 {
        match self {
            Format::Jpeg => u16::MAX as u64,
            Format::Ktx2 | Format::Dds => MAX_CUBE_FACE as u64,
            Format::Ktx1 | Format::BabylonEnv | Format::GltfIbl => MAX_CUBE_FACE as u64,
            Format::Exr | Format::Hdr | Format::Png | Format::Webp => u32::MAX as u64,
        }
    }

    /// About how many bytes `texels` texels of `channels` channels take in a file of this
    /// format at `precision` (the format's default when `None`), before compression: an
    /// upper bound for EXR, PNG and JPEG, about the size for Radiance HDR (four bytes a
    /// texel), KTX2 and DDS (four channels). For the room an output needs on disk.
    pub fn bytes_estimate(self, texels: u64, channels: u64, precision: Option<Precision>) -> u64 {
        let per_channel = match precision {
            Some(Precision::Float) => 4,
            Some(Precision::Half | Precision::U16) => 2,
            Some(Precision::U8) => 1,
            None if matches!(self, Format::Png | Format::Jpeg | Format::Webp) => 1,
            None => 2,
        };
        let per_texel = match self {
            Format::Hdr => 4,
            Format::Jpeg => 3,
            Format::Ktx2 | Format::Dds => 4 * per_channel,
            _ => channels * per_channel,
        };
        texels.saturating_mul(per_texel)
    }

    /// Every format, in the order messages list them.
    pub const ALL: [Format; 10] = [
        Format::Exr,
        Format::Hdr,
        Format::Png,
        Format::Jpeg,
        Format::Webp,
        Format::Ktx2,
        Format::Dds,
        Format::Ktx1,
        Format::BabylonEnv,
        Format::GltfIbl,
    ];

    /// The usual extension, with its dot: `.exr`.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Exr => ".exr",
            Format::Hdr => ".hdr",
            Format::Png => ".png",
            Format::Jpeg => ".jpg",
            Format::Webp => ".webp",
            Format::Ktx2 => ".ktx2",
            Format::Dds => ".dds",
            Format::Ktx1 => ".ktx",
            Format::BabylonEnv => ".env",
            Format::GltfIbl => ".gltf",
        }
    }

    /// The container's name for people: `OpenEXR`, `Radiance HDR`.
    pub fn name(self) -> &'static str {
        match self {
            Format::Exr => "OpenEXR",
            Format::Hdr => "Radiance HDR",
            Format::Png => "PNG",
            Format::Jpeg => "JPEG",
            Format::Webp => "WebP",
            Format::Ktx2 => "KTX2",
            Format::Dds => "DDS",
            Format::Ktx1 => "KTX1",
            Format::BabylonEnv => "Babylon.js .env",
            Format::GltfIbl => "glTF image-based light",
        }
    }

    /// Whether `convert` writes it (WebP it only reads; the engines' bundles only `bake`
    /// writes).
    pub fn is_written(self) -> bool {
        self != Format::Webp && !self.is_bundle()
    }

    /// The precisions its writer takes, its default first: half or float for OpenEXR, KTX2
    /// and DDS, 8 or 16 bits for PNG, 8 for JPEG; none to choose for Radiance HDR (always
    /// RGBE) and WebP (not written).
    pub fn precisions(self) -> &'static [Precision] {
        match self {
            Format::Exr | Format::Ktx2 | Format::Dds => &[Precision::Half, Precision::Float],
            Format::Png => &[Precision::U8, Precision::U16],
            Format::Jpeg => &[Precision::U8],
            Format::Hdr | Format::Webp => &[],
            Format::Ktx1 | Format::BabylonEnv | Format::GltfIbl => &[],
        }
    }
}

/// The largest cube face written into a GPU container: what Direct3D 11 and 12 take
/// (`D3D11_REQ_TEXTURECUBE_DIMENSION`), and what Vulkan and OpenGL devices commonly take.
pub const MAX_CUBE_FACE: u32 = 16384;

/// Bounds checked against a file's declared size before anything is allocated.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Largest texel count of one image or face (default 2²⁸ ≈ 268 million: a
    /// 23170×11585 lat-long).
    pub max_texels: u64,
    /// Largest width or height (default 65536).
    pub max_dimension: u32,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_texels: 1 << 28,
            max_dimension: 65536,
        }
    }
}

/// Numeric precision of the written texels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Precision {
    /// 16-bit float (EXR, KTX2, DDS). The default for HDR containers.
    #[default]
    Half,
    /// 32-bit float (EXR, KTX2, DDS).
    Float,
    /// 8-bit sRGB-encoded integer (PNG, JPEG).
    U8,
    /// 16-bit sRGB-encoded integer (PNG).
    U16,
}

/// OpenEXR compression for written files.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ExrCompression {
    /// No compression.
    None,
    /// Run-length.
    Rle,
    /// zlib, one scan line per block.
    Zips,
    /// zlib, 16 scan lines per block (the default).
    #[default]
    Zip,
    /// Wavelet (PIZ).
    Piz,
    /// Lossy 24-bit float (PXR24).
    Pxr24,
}

impl mirrorball_core::Choice for Precision {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (Precision::Half, &["half", "f16", "16f"]),
        (Precision::Float, &["float", "f32", "32f", "full"]),
        (Precision::U8, &["8", "u8", "8bit"]),
        (Precision::U16, &["16", "u16", "16bit"]),
    ];
}
mirrorball_core::choice_traits!(Precision);

impl mirrorball_core::Choice for ExrCompression {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (ExrCompression::None, &["none", "uncompressed"]),
        (ExrCompression::Rle, &["rle"]),
        (ExrCompression::Zips, &["zips"]),
        (ExrCompression::Zip, &["zip"]),
        (ExrCompression::Piz, &["piz"]),
        (ExrCompression::Pxr24, &["pxr24"]),
    ];
}
mirrorball_core::choice_traits!(ExrCompression);

/// How to write a file.
#[derive(Clone, Copy, Debug, Default)]
pub struct WriteOptions {
    /// Texel precision; `None` picks the format's natural one (half for EXR/KTX2/DDS, 8-bit
    /// for PNG/JPEG; Radiance HDR is always RGBE).
    pub precision: Option<Precision>,
    /// EXR compression.
    pub exr_compression: ExrCompression,
    /// JPEG quality 1..=100 (default 92 when 0).
    pub jpeg_quality: u8,
    /// The projection (and packing) of the picture, recorded where the container has a place
    /// for it (see the crate documentation).
    pub declared: Option<MapInfo>,
    /// What a picture that is no environment map is ([`Picture`]: a preview sheet, a BRDF
    /// table), recorded under [`CONTENT_KEY`] in PNG and OpenEXR files that declare no
    /// projection, so that `info` names it.
    pub note: Option<Picture>,
}

/// The key under which a picture that is no environment map records what it is.
pub const CONTENT_KEY: &str = "mirrorball:content";

/// Pictures mirrorball writes that are no environment map (see [`WriteOptions::note`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Picture {
    /// `prefilter`'s preview sheet: each level as a lat-long thumbnail, four to a row.
    PreviewSheet,
    /// The split-sum BRDF table (A, B in red and green over N·V and roughness).
    BrdfTable,
}

impl Picture {
    /// Every kind, and the text each records.
    pub const ALL: [(Picture, &'static str); 2] = [
        (Picture::PreviewSheet, "preview-sheet"),
        (Picture::BrdfTable, "brdf-table"),
    ];

    /// The text recorded under [`CONTENT_KEY`].
    pub fn text(self) -> &'static str {
        Picture::ALL
            .iter()
            .find(|(p, _)| *p == self)
            .expect("listed")
            .1
    }

    /// What `info` names as its projection: the thumbnails' lat-long for the sheet, none
    /// for the table (it is a function of two numbers, not of a direction).
    pub fn projection(self) -> &'static str {
        match self {
            Picture::PreviewSheet => "latlong",
            Picture::BrdfTable => "none",
        }
    }

    /// For people.
    pub fn describe(self) -> &'static str {
        match self {
            Picture::PreviewSheet => {
                "prefilter's preview sheet: each level as a 256x128 lat-long thumbnail, four to a row"
            }
            Picture::BrdfTable => {
                "the split-sum BRDF table: A and B in red and green over N.V (across) and roughness (down); no environment map"
            }
        }
    }
}

/// What the picture at `path` records it is ([`CONTENT_KEY`]: PNG `tEXt`, OpenEXR string
/// attribute), reading only its header; `None` for other files and those that record none.
pub fn picture_of(path: &Path) -> Option<Picture> {
    let text = match Format::from_path(path)? {
        Format::Png => {
            let mut f = std::io::BufReader::new(std::fs::File::open(path).ok()?);
            let texts = meta_text::read_texts(&mut f).ok()?;
            texts.into_iter().find(|(k, _)| k == CONTENT_KEY)?.1
        }
        Format::Exr => exr_io::content_text(path)?,
        _ => return None,
    };
    Picture::ALL
        .iter()
        .find(|(_, t)| *t == text.trim())
        .map(|(p, _)| *p)
}

/// What [`read`] found in a file.
#[derive(Clone, Debug)]
pub struct Loaded {
    /// The pictures: one for flat images; the six cube faces (level 0, OpenGL order) from a
    /// KTX2 or DDS cube.
    pub layers: Vec<Image>,
    /// The projection the container's own conventions declare, if they do: OpenEXR's
    /// `envmap` attribute (latlong or cube, in OpenEXR's conventions: see [`openexr`]), or
    /// cube for KTX2/DDS cube maps.
    pub declared: Option<ProjectionKind>,
    /// What the file records in mirrorball's own keys ([`PROJECTION_KEY`], [`LAYOUT_KEY`]):
    /// `None` when it records nothing, an error (saying what was recorded) when the record
    /// cannot be read.
    pub recorded: Option<Result<MapInfo, Error>>,
    /// The container.
    pub format: Format,
    /// A one-line description for people: "OpenEXR, half, ZIP compression, RGB".
    pub description: String,
    /// [`Loaded::invalid`], once counted: readers that decode block by block count as they
    /// go, while the block is in cache (ZIP-compressed scan-line OpenEXR files, the common
    /// download), or know there are none (RGBE, 8- and 16-bit files); [`read`] counts the
    /// others' texels.
    invalid: Option<u64>,
}

impl Loaded {
    /// How many colour values of the layers are NaN, infinite or negative: those
    /// [`mirrorball_core::EnvMap::sanitize`] would set to 0 (see
    /// [`mirrorball_core::count_invalid`]). A caller need not scan a map read with none.
    pub fn invalid(&self) -> u64 {
        self.invalid
            .expect("read counts the invalid values of every file")
    }
}

/// Reads an image or cube map, checking declared sizes against `limits` before allocating.
///
/// ```
/// use mirrorball_core::Image;
/// use mirrorball_io::{read, write_image, Fault, Limits, WriteOptions};
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("map.exr");
/// let mut img = Image::new(8, 4, 3);
/// img.set(1, 2, &[0.25, 0.5, 4.0]);
/// write_image(&path, &img, &WriteOptions::default()).unwrap();
/// let loaded = read(&path, &Limits::default()).unwrap();
/// assert_eq!(loaded.layers[0].get(1, 2), &[0.25, 0.5, 4.0]);
/// // A missing file is an error that names it and says whose fault it is.
/// let e = read(&dir.path().join("none.exr"), &Limits::default()).unwrap_err();
/// assert!(e.to_string().starts_with(&dir.path().join("none.exr").display().to_string()));
/// assert_ne!(e.fault(), Fault::Request);
/// ```
pub fn read(path: &Path, limits: &Limits) -> Result<Loaded, Error> {
    let mut loaded = read_format(path, limits)?;
    count_invalid(&mut loaded);
    Ok(loaded)
}

/// Counts [`Loaded::invalid`] where the reader did not.
fn count_invalid(loaded: &mut Loaded) {
    if loaded.invalid.is_none() {
        use rayon::prelude::*;
        let count = loaded
            .layers
            .iter()
            .map(|img| {
                let rgba = img.channels() == 4;
                img.data()
                    .par_chunks(img.channels() * 16384)
                    .map(|block| mirrorball_core::count_invalid(block, rgba))
                    .sum::<u64>()
            })
            .sum();
        loaded.invalid = Some(count);
    }
}

/// Reads a PNG or JPEG of RGB samples (8- or 16-bit, no alpha) into `buf` as the file holds
/// them, sRGB codes with no float copy ([`CodedPicture`]; [`srgb8_to_linear`] and
/// [`srgb16_to_linear`] are their linear values, the ones [`read`] gives), with [`read`]'s
/// checks and messages; `Ok(None)` for every other file, which [`read`] reads.
///
/// ```
/// use mirrorball_core::Image;
/// use mirrorball_io::{read, read_codes, srgb8_to_linear, write_image, Limits, WriteOptions};
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("a.png");
/// let mut img = Image::new(4, 2, 3);
/// img.set(1, 1, &[0.25, 0.5, 1.0]);
/// write_image(&path, &img, &WriteOptions::default()).unwrap();
/// let mut buf = Vec::new();
/// let coded = read_codes(&path, &Limits::default(), &mut buf).unwrap().unwrap();
/// assert_eq!((coded.width, coded.height, coded.wide), (4, 2, false));
/// let floats = read(&path, &Limits::default()).unwrap();
/// let decoded: Vec<f32> = buf.iter().map(|&k| srgb8_to_linear()[k as usize]).collect();
/// assert_eq!(decoded, floats.layers[0].data());
/// ```
pub fn read_codes(
    path: &Path,
    limits: &Limits,
    buf: &mut Vec<u8>,
) -> Result<Option<CodedPicture>, Error> {
    Error::check_input(path)?;
    match Format::from_path(path) {
        Some(format @ (Format::Png | Format::Jpeg)) => {
            ldr_io::read_codes(&input::Input::open(path)?, format, limits, buf)
        }
        _ => Ok(None),
    }
}

/// [`read`]'s reader for `path`'s format, once `path` is a file with bytes in it.
fn read_format(path: &Path, limits: &Limits) -> Result<Loaded, Error> {
    Error::check_input(path)?;
    let format = Format::from_path(path).ok_or_else(|| Error::request(path, unknown_ext()))?;
    if format == Format::GltfIbl {
        // A glTF light names its images, other files beside it.
        return gltf_ibl::read(path, limits);
    }
    decode(&input::Input::open(path)?, format, limits)
}

/// The one decoder of `format`, reading a file or bytes.
fn decode(input: &input::Input, format: Format, limits: &Limits) -> Result<Loaded, Error> {
    let path = input.path();
    match format {
        Format::Exr => exr_io::read(input, limits),
        Format::Hdr => hdr_io::read(input, limits),
        Format::Png | Format::Jpeg | Format::Webp => ldr_io::read(input, format, limits),
        // The header parsers are other crates' (`ktx2` 0.5 panics on a DFD block dimension
        // of 255): a panic becomes an error.
        Format::Ktx2 => ldr_io::guard_decoder(path, "KTX2", || ktx2_io::read(input, limits)),
        Format::Dds => ldr_io::guard_decoder(path, "DDS", || dds_io::read(input, limits)),
        Format::Ktx1 => ktx1_io::read(input, limits),
        Format::BabylonEnv => babylon_env::read(input, limits),
        Format::GltfIbl => Err(Error::request(
            path,
            "a glTF light names its images in files beside it: read it from a path".into(),
        )),
    }
}

/// How [`read_bytes`] and [`write_bytes`] know the container: named outright, by a file
/// name's extension, or (reading) by the content's first bytes ([`Format::from_magic`]).
#[derive(Clone, Copy, Debug)]
pub enum Hint<'a> {
    /// This container.
    Format(Format),
    /// The container of this file name's extension (`upload.exr`); messages name it.
    Name(&'a str),
    /// Whatever the bytes' signature says (reading only).
    Content,
}

impl Hint<'_> {
    /// The format and the name messages give the bytes: the file name, or the container's
    /// name and "data" (`OpenEXR data`).
    fn resolve(self, bytes: Option<&[u8]>) -> Result<(Format, std::path::PathBuf), Error> {
        let named = |f: Format| std::path::PathBuf::from(format!("{} data", f.name()));
        match self {
            Hint::Format(f) => Ok((f, named(f))),
            Hint::Name(name) => {
                let path = Path::new(name);
                match Format::from_path(path).or_else(|| bytes.and_then(Format::from_magic)) {
                    Some(f) => Ok((f, path.to_path_buf())),
                    None => Err(Error::request(path, unknown_ext())),
                }
            }
            Hint::Content => match bytes.and_then(Format::from_magic) {
                Some(f) => Ok((f, named(f))),
                None => Err(Error::input(
                    Path::new("data"),
                    "not a file format mirrorball reads (its first bytes are no known \
                     signature: OpenEXR, Radiance HDR, PNG, JPEG, WebP, KTX2, DDS, KTX1, \
                     Babylon.js .env)"
                        .into(),
                )),
            },
        }
    }
}

/// Reads a file's contents held in memory, as [`read`] reads the file: the same decoder,
/// the same checks of declared sizes against `limits` and against the bytes' length before
/// anything is allocated, the same messages (naming the file name of `hint`, else the
/// container: `PNG data: ...`). A glTF light (it names other files) is read only from a path.
///
/// ```
/// use mirrorball_core::Image;
/// use mirrorball_io::{read_bytes, write_bytes, Fault, Format, Hint, Limits, WriteOptions};
/// let mut img = Image::new(8, 4, 3);
/// img.set(1, 2, &[0.25, 0.5, 4.0]);
/// let bytes = write_bytes(&[vec![img]], Hint::Format(Format::Exr), &WriteOptions::default()).unwrap();
/// let loaded = read_bytes(&bytes, Hint::Content, &Limits::default()).unwrap();
/// assert_eq!(loaded.layers[0].get(1, 2), &[0.25, 0.5, 4.0]);
/// let e = read_bytes(&bytes[..100], Hint::Name("map.exr"), &Limits::default()).unwrap_err();
/// assert_eq!(e.fault(), Fault::Input);
/// ```
pub fn read_bytes(bytes: &[u8], hint: Hint<'_>, limits: &Limits) -> Result<Loaded, Error> {
    let (format, name) = hint.resolve(Some(bytes))?;
    if bytes.is_empty() {
        return Err(Error::input(
            &name,
            format!("the {} data is empty (0 bytes)", format.name()),
        ));
    }
    let mut loaded = decode(&input::Input::bytes(&name, bytes), format, limits)?;
    count_invalid(&mut loaded);
    Ok(loaded)
}

/// Writes a file's contents to memory, as [`write_image`] (one level of one layer) or
/// [`write_cube`] (KTX2 and DDS: `levels` as it takes them) write the file: the same
/// encoder, the same bytes. The container is `hint`'s ([`Hint::Content`] is refused).
///
/// ```
/// use mirrorball_core::Image;
/// use mirrorball_io::{write_bytes, write_image, Format, Hint, WriteOptions};
/// let dir = tempfile::tempdir().unwrap();
/// let img = Image::new(4, 2, 3);
/// let path = dir.path().join("a.png");
/// write_image(&path, &img, &WriteOptions::default()).unwrap();
/// let bytes = write_bytes(&[vec![img]], Hint::Name("a.png"), &WriteOptions::default()).unwrap();
/// assert_eq!(std::fs::read(&path).unwrap(), bytes);
/// ```
pub fn write_bytes(
    levels: &[Vec<Image>],
    hint: Hint<'_>,
    opts: &WriteOptions,
) -> Result<Vec<u8>, Error> {
    let (format, name) = match hint {
        Hint::Content => {
            return Err(Error::request(
                Path::new("data"),
                "writing needs a format or a file name, not the content's".into(),
            ))
        }
        hint => hint.resolve(None)?,
    };
    let dest = atomic::Dest::Memory(&name);
    if format.is_cube_container() {
        return write_cube_to(dest, format, levels, opts).map(atomic::Written::bytes);
    }
    match levels {
        [level] if level.len() == 1 => {
            write_image_to(dest, format, &level[0], opts, &mut WriteBuffers::default())
                .map(atomic::Written::bytes)
        }
        _ => Err(Error::request(
            &name,
            format!(
                "a {} file holds one picture: pack the layers (a layout) first",
                format.name()
            ),
        )),
    }
}

impl Format {
    /// The format whose signature `bytes` start with: OpenEXR's magic number, `#?` (Radiance),
    /// PNG's, JPEG's start of image, RIFF…WEBP, KTX 2.0's and KTX 1.1's identifiers, `DDS `,
    /// Babylon's `.env` magic. `None` for anything else (glTF is JSON: name it).
    pub fn from_magic(bytes: &[u8]) -> Option<Format> {
        let starts = |m: &[u8]| bytes.starts_with(m);
        Some(if starts(&[0x76, 0x2f, 0x31, 0x01]) {
            Format::Exr
        } else if starts(b"#?") {
            Format::Hdr
        } else if starts(b"\x89PNG\r\n\x1a\n") {
            Format::Png
        } else if starts(&[0xff, 0xd8]) {
            Format::Jpeg
        } else if starts(b"RIFF") && bytes.get(8..12) == Some(b"WEBP") {
            Format::Webp
        } else if starts(b"\xabKTX 20\xbb") {
            Format::Ktx2
        } else if starts(b"\xabKTX 11\xbb") {
            Format::Ktx1
        } else if starts(b"DDS ") {
            Format::Dds
        } else if starts(&babylon_env::MAGIC) {
            Format::BabylonEnv
        } else {
            return None;
        })
    }
}

/// About the work of writing `texels` texels (every layer and level) as `format` with
/// `opts`, in [`mirrorball_core::work`]'s units: what the writers count as they go, so a
/// progress bar runs to it. 0 for what no writer counts (PNG, JPEG, OpenEXR written by the
/// `exr` crate: PIZ, RLE, PXR24).
pub fn write_work(format: Format, texels: u64, opts: &WriteOptions) -> u64 {
    match format {
        Format::Exr => match opts.exr_compression {
            ExrCompression::Zip | ExrCompression::Zips | ExrCompression::None => {
                exr_io::EXR_WORK * texels
            }
            _ => 0,
        },
        Format::Hdr => hdr_io::rgbe_work(texels),
        Format::Ktx2 | Format::Dds => match opts.precision {
            Some(Precision::Float) => Encoding::Rgba32F.work(texels),
            _ => Encoding::Rgba16F.work(texels),
        },
        Format::Png | Format::Jpeg | Format::Webp => 0,
        Format::Ktx1 | Format::BabylonEnv | Format::GltfIbl => 0,
    }
}

/// Writes one flat image (EXR, HDR, PNG or JPEG), atomically. (Several files that belong
/// together: [`OutputSet`].)
pub fn write_image(path: &Path, image: &Image, opts: &WriteOptions) -> Result<(), Error> {
    atomic::land(stage_image(
        path,
        image,
        opts,
        &mut WriteBuffers::default(),
    )?)
}

/// Bytes writing a `w`×`h` image of `c` channels to `path` (as [`write_image`] does) holds
/// besides the image: the encoder's buffers where they grow with the picture (OpenEXR's
/// batches of compressed blocks); 0 where they do not.
pub fn write_buffer_bytes(path: &Path, (w, h, c): (u32, u32, usize), opts: &WriteOptions) -> u64 {
    match Format::from_path(path) {
        Some(Format::Exr) => exr_io::write_buffer_bytes(w, h, c, opts),
        _ => 0,
    }
}

/// Writes one flat image as [`write_image`] does, to a temporary file beside `path` that
/// [`Staged::commit`] renames into place (dropped uncommitted, it is removed). `buffers`
/// are the encoders' buffers, kept from one file to the next.
pub(crate) fn stage_image(
    path: &Path,
    image: &Image,
    opts: &WriteOptions,
    buffers: &mut WriteBuffers,
) -> Result<Staged, Error> {
    let format = Format::from_path(path).ok_or_else(|| Error::request(path, unknown_ext()))?;
    write_image_to(atomic::Dest::File(path), format, image, opts, buffers)
        .map(atomic::Written::staged)
}

/// The one encoder of each flat-image `format`, into a file or memory.
fn write_image_to(
    dest: atomic::Dest,
    format: Format,
    image: &Image,
    opts: &WriteOptions,
    buffers: &mut WriteBuffers,
) -> Result<atomic::Written, Error> {
    let path = dest.path();
    check_channels(path, std::slice::from_ref(image))?;
    match format {
        Format::Exr => exr_io::write(dest, image, opts, buffers),
        Format::Hdr => hdr_io::write(dest, image, opts),
        Format::Png | Format::Jpeg => ldr_io::write(dest, format, image, opts),
        Format::Webp => Err(Error::request(
            path,
            "writing WebP is not supported; use .png".into(),
        )),
        Format::Ktx2 | Format::Dds => Err(Error::request(
            path,
            "KTX2 and DDS hold cube maps: convert with --to cube".into(),
        )),
        Format::Ktx1 | Format::BabylonEnv | Format::GltfIbl => Err(Error::request(
            path,
            format!("{} files are written by bake", format.name()),
        )),
    }
}

/// Writes a cube map with its mip chain to KTX2 or DDS, atomically. `levels[0]` holds the
/// six level-0 faces in OpenGL order (+X −X +Y −Y +Z −Z), `levels[i]` the faces of level i,
/// each half the size of the one before (rounded down, at least 1).
///
/// ```
/// use mirrorball_core::Image;
/// use mirrorball_io::{read, write_cube, Limits, WriteOptions};
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("sky.ktx2");
/// let levels: Vec<Vec<Image>> = [4u32, 2, 1]
///     .iter()
///     .map(|&n| (0..6).map(|_| Image::new(n, n, 3)).collect())
///     .collect();
/// write_cube(&path, &levels, &WriteOptions::default()).unwrap();
/// assert_eq!(read(&path, &Limits::default()).unwrap().layers.len(), 6);
/// ```
pub fn write_cube(path: &Path, levels: &[Vec<Image>], opts: &WriteOptions) -> Result<(), Error> {
    let format = Format::from_path(path).ok_or_else(|| Error::request(path, unknown_ext()))?;
    write_cube_to(atomic::Dest::File(path), format, levels, opts)?
        .land()
        .map(|_| ())
}

/// The one encoder of each cube container, into a file or memory.
fn write_cube_to(
    dest: atomic::Dest,
    format: Format,
    levels: &[Vec<Image>],
    opts: &WriteOptions,
) -> Result<atomic::Written, Error> {
    for level in levels {
        check_channels(dest.path(), level)?;
    }
    match format {
        Format::Ktx2 => ktx2_io::write(dest, levels, opts),
        Format::Dds => dds_io::write(dest, levels, opts),
        _ => Err(Error::request(
            dest.path(),
            "only .ktx2 and .dds hold a whole cube map".into(),
        )),
    }
}

/// Refuses pictures every writer cannot take: files hold RGB or RGBA (a one-channel plane,
/// which core's images may be, is for the caller to expand or pack).
fn check_channels(path: &Path, images: &[Image]) -> Result<(), Error> {
    match images.iter().find(|i| !matches!(i.channels(), 3 | 4)) {
        Some(i) => Err(Error::request(
            path,
            format!(
                "a picture of {} channel{}: files are written with 3 (RGB) or 4 (RGBA)",
                i.channels(),
                if i.channels() == 1 { "" } else { "s" }
            ),
        )),
        None => Ok(()),
    }
}

/// Whether `a` and `b` name the same file (the same device and inode, through hard links,
/// symbolic links, `..` and relative names alike). `false` when either does not exist.
///
/// ```
/// let dir = tempfile::tempdir().unwrap();
/// let a = dir.path().join("a.exr");
/// std::fs::write(&a, b"x").unwrap();
/// assert!(mirrorball_io::same_file(&a, &dir.path().join(".").join("a.exr")));
/// assert!(!mirrorball_io::same_file(&a, &dir.path().join("b.exr")));
/// ```
///
/// On Unix the files' metadata is compared, so that neither is opened: opening a FIFO
/// waits for a writer, and a command's plan reads nothing.
pub fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (std::fs::metadata(a), std::fs::metadata(b)) {
            (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        same_file::is_same_file(a, b).unwrap_or(false)
    }
}

fn unknown_ext() -> String {
    "unknown file extension (known: .exr .hdr .png .jpg .jpeg .webp .ktx2 .dds .ktx .env .gltf)"
        .to_string()
}

/// [`Loaded::recorded`] from the text metadata of `path` (`get` looks a key up) for a
/// `w`×`h` picture: nothing unless the projection key is there.
pub(crate) fn recorded(
    path: &Path,
    get: impl Fn(&str) -> Option<String>,
    w: u32,
    h: u32,
) -> Option<Result<MapInfo, Error>> {
    let projection = get(PROJECTION_KEY)?;
    let layout = get(LAYOUT_KEY);
    Some(MapInfo::from_texts(
        path,
        projection.trim(),
        layout.as_deref().map(str::trim),
        w,
        h,
    ))
}

/// The layer names of files that hold one layer each, as `{face}` in a name reads them:
/// a cube's faces, OpenGL order, and a paraboloid's halves.
pub const LAYER_NAMES: [&[&str]; 2] = [&["px", "nx", "py", "ny", "pz", "nz"], &["front", "back"]];

/// The `{face}` pattern of the set of one-layer files `path` is one of, when its stem ends
/// in a layer name ([`LAYER_NAMES`]: `px`, … `nz`, `front`, `back`, alone or after `_`, `-`
/// or `.`) and every file of the set is there: `cube/px.hdr` → `cube/{face}.hdr` (three's
/// background), `lighting_specular_0_nz.png` → `lighting_specular_0_{face}.png` (a glTF
/// light's level). A face alone is not a picture of the sphere: read the set.
pub fn layer_set(path: &str) -> Option<String> {
    let p = Path::new(path);
    let stem = p.file_stem()?.to_str()?;
    let ext = p.extension().and_then(|e| e.to_str());
    for names in LAYER_NAMES {
        for name in names {
            let Some(head) = stem.strip_suffix(name) else {
                continue;
            };
            if !(head.is_empty() || head.ends_with(['_', '-', '.'])) {
                continue;
            }
            let file = match ext {
                Some(e) => format!("{head}{{face}}.{e}"),
                None => format!("{head}{{face}}"),
            };
            let pattern = p.with_file_name(file).to_str()?.to_string();
            let all = names
                .iter()
                .all(|n| Path::new(&pattern.replace("{face}", n)).is_file());
            return all.then_some(pattern);
        }
    }
    None
}
