//! PNG, JPEG and WebP (8/16-bit, sRGB-encoded) with the `image` crate, converted to and
//! from linear light with the exact sRGB transfer functions.
//!
//! Also holds the small helpers the flat-image readers and writers share: the size check
//! against [`Limits`], the guard that turns a decoder panic into an error, and the mapping
//! of `image` crate errors.

use crate::atomic::{Dest, Written};
use crate::input::Input;
use crate::{Error, Format, Limits, Loaded, Precision, WriteOptions};
use image::codecs::jpeg::JpegEncoder;
use image::codecs::png::PngEncoder;
use image::{DynamicImage, ExtendedColorType, ImageDecoder, ImageEncoder, ImageError, ImageFormat};
use mirrorball_core::color::{linear_to_srgb, srgb_to_linear};
use mirrorball_core::Image;
use rayon::prelude::*;
use std::io::{BufRead, Cursor, Seek};
use std::path::Path;
use std::sync::OnceLock;

/// JPEG quality used when [`WriteOptions::jpeg_quality`] is 0.
const DEFAULT_JPEG_QUALITY: u8 = 92;

/// Texels per parallel work item when converting between linear and sRGB.
const CHUNK_TEXELS: usize = 1 << 14;

/// Reads a PNG, JPEG or WebP file as linear `f32` texels: RGB, or RGBA when the file has
/// alpha (grey is expanded to RGB). Colour channels are sRGB-decoded; alpha is kept
/// linear, as stored.
///
/// The declared size is checked against `limits` from the header, before any texel is
/// decoded. A PNG's `mirrorball:projection` and `mirrorball:layout` text chunks, or the
/// same `key=value` lines in a JPEG comment segment, become [`Loaded::recorded`].
pub fn read(input: &Input, format: Format, limits: &Limits) -> Result<Loaded, Error> {
    let path = input.path();
    let (mut loaded, recorded) = read_with(input, format, limits, |decoder, name| {
        let decoded =
            DynamicImage::from_decoder(decoder).map_err(|e| decode_error(path, name, e))?;
        let (image, depth, layout) = to_linear(path, decoded)?;
        Ok(Loaded {
            layers: vec![image],
            declared: None,
            recorded: None,
            format,
            description: format!("{name}, {depth} sRGB, {layout}"),
            // 8- and 16-bit texels decode to values in [0, 1].
            invalid: Some(0),
        })
    })?;
    loaded.recorded = recorded;
    Ok(loaded)
}

/// A PNG or JPEG of RGB samples read as [`read_codes`] gives it: its samples are the
/// caller's buffer, as the file holds them.
#[derive(Debug)]
pub struct CodedPicture {
    /// Texels across.
    pub width: u32,
    /// Texels down.
    pub height: u32,
    /// 16-bit samples (native byte order: on little-endian machines the little-endian
    /// codes `mirrorball_core::Codes::u16le` reads), else 8-bit.
    pub wide: bool,
    /// What the file records in mirrorball's own keys, as [`Loaded::recorded`].
    pub recorded: Option<Result<crate::MapInfo, Error>>,
    /// The container.
    pub format: Format,
    /// A one-line description for people, as [`read`] gives it: "JPEG, 8-bit sRGB, RGB".
    pub description: String,
}

/// Reads a PNG or JPEG of RGB samples (8- or 16-bit, no alpha) into `buf` as the file holds
/// them: sRGB codes, R, G, B interleaved, no float copy (a planned conversion reads them as
/// `mirrorball_core::Codes`, through [`lut8`] or [`lut16`]: the same values [`read`] gives).
/// `buf` is resized to the picture (its memory reused when it is large enough). The same
/// checks, messages and records as [`read`]; `Ok(None)`, with nothing decoded, for other
/// files (grey, alpha, WebP and the float formats): [`read`] reads those.
pub fn read_codes(
    input: &Input,
    format: Format,
    limits: &Limits,
    buf: &mut Vec<u8>,
) -> Result<Option<CodedPicture>, Error> {
    if !matches!(format, Format::Png | Format::Jpeg) {
        return Ok(None);
    }
    let path = input.path();
    if format == Format::Jpeg {
        return guard_decoder(path, "JPEG", || jpeg_codes(input, limits, buf));
    }
    let (coded, recorded) = read_with(input, format, limits, |decoder, name| {
        let wide = match decoder.color_type() {
            image::ColorType::Rgb8 => false,
            image::ColorType::Rgb16 => true,
            _ => return Ok(None),
        };
        let (width, height) = decoder.dimensions();
        let len = usize::try_from(decoder.total_bytes()).unwrap_or(usize::MAX);
        buf.resize(len, 0);
        decoder
            .read_image(buf)
            .map_err(|e| decode_error(path, name, e))?;
        let depth = if wide { "16-bit" } else { "8-bit" };
        Ok(Some(CodedPicture {
            width,
            height,
            wide,
            recorded: None,
            format,
            description: format!("{name}, {depth} sRGB, RGB"),
        }))
    })?;
    Ok(coded.map(|c| CodedPicture { recorded, ..c }))
}

/// The steps [`read`] and [`read_codes`] share: the container's checks (a JPEG's markers),
/// the declared size against `limits` and the file's length, then `finish` with the
/// decoder (and the format's name), under the guard that turns a decoder's panic into an
/// error; with what the file records of its projection.
fn read_with<T>(
    input: &Input,
    format: Format,
    limits: &Limits,
    finish: impl FnOnce(Box<dyn ImageDecoder + '_>, &str) -> Result<T, Error>,
) -> Result<(T, Option<Result<crate::MapInfo, Error>>), Error> {
    let path = input.path();
    let (image_format, name) = match format {
        Format::Png => (ImageFormat::Png, "PNG"),
        Format::Jpeg => (ImageFormat::Jpeg, "JPEG"),
        Format::Webp => (ImageFormat::WebP, "WebP"),
        other => {
            return Err(Error::request(
                path,
                format!("{other:?} is not an 8/16-bit image format"),
            ))
        }
    };
    let io = |e| Error::io(path, e);
    guard_decoder(path, name, || {
        if format == Format::Png {
            let mut reader = input.reader().map_err(io)?;
            let texts = crate::meta_text::read_texts(&mut reader).map_err(io)?;
            let (t, (w, h)) = decode(input, reader, image_format, format, name, limits, finish)?;
            let get = |key: &str| texts.iter().find(|(k, _)| k == key).map(|(_, v)| v.clone());
            return Ok((t, crate::recorded(path, get, w, h)));
        }
        if format != Format::Jpeg {
            let reader = input.reader().map_err(io)?;
            let (t, _) = decode(input, reader, image_format, format, name, limits, finish)?;
            return Ok((t, None));
        }
        let (bytes, comments) = jpeg_file(input)?;
        let reader = Cursor::new(&bytes[..]);
        let (t, (w, h)) = decode(input, reader, image_format, format, name, limits, finish)?;
        let get = |key: &str| {
            comments
                .iter()
                .find(|(k, _)| k == key)
                .map(|(_, v)| v.clone())
        };
        Ok((t, crate::recorded(path, get, w, h)))
    })
}

/// A JPEG's comment segments' `key=value` lines.
type Comments = Vec<(String, String)>;

/// A JPEG file's bytes, checked for its start and end markers (decoders fill in whatever a
/// truncated file lacks), and its comment segments' `key=value` lines.
fn jpeg_file<'a>(input: &'a Input) -> Result<(std::borrow::Cow<'a, [u8]>, Comments), Error> {
    let path = input.path();
    let bytes = input.all().map_err(|e| Error::io(path, e))?;
    if !bytes.starts_with(&[0xff, 0xd8]) {
        return Err(Error::input(
            path,
            "not a valid JPEG file (no start-of-image marker)".into(),
        ));
    }
    if !jpeg_is_complete(&bytes) {
        return Err(Error::input(
            path,
            "file is truncated (the JPEG end-of-image marker is missing)".into(),
        ));
    }
    let comments = crate::meta_text::jpeg_comments(&bytes);
    Ok((bytes, comments))
}

/// [`read_codes`] of a JPEG: `image`'s decoder (zune-jpeg, with the options `image` gives
/// it) run on the file's bytes as read, straight into `buf`; three-component pictures
/// (YCbCr or RGB) only, others `None`.
fn jpeg_codes(
    input: &Input,
    limits: &Limits,
    buf: &mut Vec<u8>,
) -> Result<Option<CodedPicture>, Error> {
    use zune_core::colorspace::ColorSpace;
    let path = input.path();
    let (bytes, comments) = jpeg_file(input)?;
    let fail = |e: zune_jpeg::errors::DecodeErrors| {
        Error::input(path, format!("not a valid JPEG file ({e})"))
    };
    let options = zune_core::options::DecoderOptions::default()
        .set_strict_mode(false)
        .set_max_width(usize::MAX)
        .set_max_height(usize::MAX);
    let mut decoder = zune_jpeg::JpegDecoder::new_with_options(
        zune_core::bytestream::ZCursor::new(&bytes[..]),
        options,
    );
    decoder.decode_headers().map_err(fail)?;
    let (w, h) = decoder.dimensions().expect("headers decoded");
    let (width, height) = (w as u32, h as u32);
    check_limits(path, width as u64, height as u64, limits)?;
    check_fits_file(input, Format::Jpeg, "JPEG", width, height)?;
    match decoder.input_colorspace() {
        Some(ColorSpace::YCbCr | ColorSpace::RGB) => {}
        _ => return Ok(None),
    }
    decoder.set_options(options.jpeg_set_out_colorspace(ColorSpace::RGB));
    let len = decoder.output_buffer_size().expect("headers decoded");
    buf.resize(len, 0);
    decoder.decode_into(buf).map_err(fail)?;
    let get = |key: &str| {
        comments
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.clone())
    };
    Ok(Some(CodedPicture {
        width,
        height,
        wide: false,
        recorded: crate::recorded(path, get, width, height),
        format: Format::Jpeg,
        description: "JPEG, 8-bit sRGB, RGB".into(),
    }))
}

/// Opens the `image` crate's decoder, checks the declared size, and hands the decoder to
/// `finish`; with the picture's size.
fn decode<R: BufRead + Seek, T>(
    input: &Input,
    reader: R,
    image_format: ImageFormat,
    format: Format,
    name: &str,
    limits: &Limits,
    finish: impl FnOnce(Box<dyn ImageDecoder + '_>, &str) -> Result<T, Error>,
) -> Result<(T, (u32, u32)), Error> {
    let path = input.path();
    let mut reader = image::ImageReader::with_format(reader, image_format);
    reader.limits(image_limits(limits));
    let decoder = reader.into_decoder().map_err(|e| match e {
        ImageError::Limits(_) => Error::input(
            path,
            format!(
                "declares an image larger than allowed (at most {} texels wide or high, {} in all)",
                limits.max_dimension, limits.max_texels
            ),
        ),
        e => decode_error(path, name, e),
    })?;
    let (width, height) = decoder.dimensions();
    check_limits(path, width as u64, height as u64, limits)?;
    check_fits_file(input, format, name, width, height)?;
    Ok((finish(Box::new(decoder), name)?, (width, height)))
}

/// Refuses a PNG, JPEG or WebP whose declared size its length cannot hold (see
/// [`crate::bounds`]). PNG: deflate expands a byte to at most 1032, and a 1-bit grey texel
/// takes an eighth of a raw byte, so at most 8 × 1032 (plus slack) texels a byte. JPEG
/// (Huffman-coded, as the decoder reads it): every 8×8 block of the fullest component costs
/// at least a bit for its DC value, so at most 512 texels a byte (doubled for slack).
///
/// WebP's coding has no such bound: lossless VP8L codes a picture whose every Huffman
/// group has one symbol in zero bits a texel, and lossy VP8's arithmetic-coded skip flags
/// cost a small fraction of a bit per 16×16 macroblock. So a WebP file is held to a
/// *plausible* density instead: 4096 texels a byte (real pictures, lossy or lossless, come
/// to well under 100), and every file may still declare [`crate::bounds::FLOOR_TEXELS`].
fn check_fits_file(
    input: &Input,
    format: Format,
    name: &str,
    width: u32,
    height: u32,
) -> Result<(), Error> {
    use crate::bounds::{check_texels_fit, Density};
    let (w, h) = (width as u64, height as u64);
    match format {
        Format::Png => check_texels_fit(input, w, h, Density::Most(8 * 1040), name),
        Format::Jpeg => check_texels_fit(input, w, h, Density::Most(1024), name),
        Format::Webp => check_texels_fit(input, w, h, Density::Plausible(4096), name),
        _ => Ok(()),
    }
}

/// Whether the last scan of a JPEG stream is followed by an end-of-image marker. Marker
/// bytes cannot occur inside entropy-coded data (0xFF is stuffed), so the last
/// start-of-scan is the real one; anything after the end marker is ignored.
fn jpeg_is_complete(bytes: &[u8]) -> bool {
    match bytes.windows(2).rposition(|w| w == [0xff, 0xda]) {
        Some(sos) => bytes[sos..].windows(2).any(|w| w == [0xff, 0xd9]),
        // No scan at all: the decoder says what is wrong.
        None => true,
    }
}

/// Writes `image` as PNG (8-bit, or 16-bit with [`Precision::U16`]) or JPEG (8-bit,
/// quality [`WriteOptions::jpeg_quality`], 92 when 0; alpha dropped), encoding linear light
/// to sRGB with clamping to [0, 1] and rounding to nearest. Alpha is stored linearly. A PNG
/// records [`WriteOptions::declared`] in `tEXt` chunks, a JPEG in a comment segment; a
/// lat-long or VR180 picture also gets GPano XMP (PNG `iTXt`, JPEG `APP1`).
/// Written to a temporary file that the returned [`Written`] renames into place, or to
/// memory (`dest`).
pub fn write(
    dest: Dest,
    format: Format,
    image: &Image,
    opts: &WriteOptions,
) -> Result<Written, Error> {
    let path = dest.path();
    let sixteen = sixteen_bit(path, format, opts)?;
    check_writable_size(path, image)?;
    let (w, h) = (image.width(), image.height());
    if format == Format::Jpeg && (w > u16::MAX as u32 || h > u16::MAX as u32) {
        return Err(Error::request(
            path,
            format!("JPEG images are at most 65535 texels wide and high; this one is {w}×{h}"),
        ));
    }

    if format == Format::Jpeg {
        return write_jpeg(dest, image, opts);
    }
    write_png(dest, image, opts, sixteen)
}

/// Whether [`write`] stores 16-bit samples (PNG with [`Precision::U16`]) rather than 8-bit
/// ones; an error for the precisions PNG and JPEG do not store and for other formats.
fn sixteen_bit(path: &Path, format: Format, opts: &WriteOptions) -> Result<bool, Error> {
    match (format, opts.precision) {
        (Format::Png | Format::Jpeg, None | Some(Precision::U8)) => Ok(false),
        (Format::Png, Some(Precision::U16)) => Ok(true),
        (Format::Png, Some(p)) => Err(Error::request(
            path,
            format!(
                "PNG stores 8- or 16-bit integer texels, not {}; use .exr for half or float",
                precision_name(p)
            ),
        )),
        (Format::Jpeg, Some(p)) => Err(Error::request(
            path,
            format!(
                "JPEG stores 8-bit integer texels, not {}; use .png for 16 bits or .exr \
                 for half or float",
                precision_name(p)
            ),
        )),
        (other, _) => {
            let problem = format!("writing {other:?} as an 8/16-bit image is not supported");
            Err(Error::request(path, problem))
        }
    }
}

/// Stages `image` as an 8-bit RGB JPEG at [`WriteOptions::jpeg_quality`] (92 when 0, at
/// most 100), with [`WriteOptions::declared`] in a comment segment and GPano XMP in `APP1`
/// when it is given.
fn write_jpeg(dest: Dest, image: &Image, opts: &WriteOptions) -> Result<Written, Error> {
    let path = dest.path();
    let (w, h) = (image.width(), image.height());
    let quality = match opts.jpeg_quality {
        0 => DEFAULT_JPEG_QUALITY,
        q => q.min(100),
    };
    let bytes = encode_u8(image, 3);
    let Some(info) = &opts.declared else {
        return dest.emit(|out| {
            JpegEncoder::new_with_quality(out, quality)
                .write_image(&bytes, w, h, ExtendedColorType::Rgb8)
                .map_err(|e| encode_error(path, "JPEG", e))
        });
    };
    // The projection and layout in a comment segment, spliced into the encoded file.
    let jpeg = encode_codes(path, Format::Jpeg, (w, h), (&bytes, false), quality, &[])?;
    let (projection, layout) = info.texts();
    let mut pairs = vec![(crate::PROJECTION_KEY, projection)];
    pairs.extend(layout.map(|l| (crate::LAYOUT_KEY, l)));
    let mut jpeg = crate::meta_text::with_jpeg_comment(jpeg, &pairs);
    if let Some(xmp) = panorama_xmp(info, w, h) {
        jpeg = crate::meta_text::with_jpeg_xmp(jpeg, &xmp);
    }
    dest.emit(|out| std::io::Write::write_all(out, &jpeg).map_err(|e| Error::io(path, e)))
}

/// Stages `image` as an RGB or RGBA PNG of 8-bit or (`sixteen`) 16-bit samples, with
/// [`WriteOptions::declared`] in `tEXt` chunks and GPano XMP in an `iTXt` chunk when it is
/// given.
fn write_png(
    dest: Dest,
    image: &Image,
    opts: &WriteOptions,
    sixteen: bool,
) -> Result<Written, Error> {
    let path = dest.path();
    let (w, h) = (image.width(), image.height());
    let c = image.channels();
    let (bytes, color) = if sixteen {
        let samples = encode_u16(image);
        let bytes: Vec<u8> = samples.iter().flat_map(|s| s.to_ne_bytes()).collect();
        (
            bytes,
            if c == 4 {
                ExtendedColorType::Rgba16
            } else {
                ExtendedColorType::Rgb16
            },
        )
    } else {
        (
            encode_u8(image, c),
            if c == 4 {
                ExtendedColorType::Rgba8
            } else {
                ExtendedColorType::Rgb8
            },
        )
    };
    // The projection and layout as tEXt chunks right after IHDR.
    let mut chunks = Vec::new();
    if let Some(info) = &opts.declared {
        let (projection, layout) = info.texts();
        chunks.extend(crate::meta_text::text_chunk(
            crate::PROJECTION_KEY,
            &projection,
        ));
        if let Some(l) = layout {
            chunks.extend(crate::meta_text::text_chunk(crate::LAYOUT_KEY, &l));
        }
        if let Some(xmp) = panorama_xmp(info, w, h) {
            let key = mirrorball_spherical::gpano::PNG_KEYWORD;
            chunks.extend(crate::meta_text::itxt_chunk(key, &xmp));
        }
    } else if let Some(note) = opts.note {
        chunks.extend(crate::meta_text::text_chunk(
            crate::CONTENT_KEY,
            note.text(),
        ));
    }
    dest.emit(|out| {
        PngEncoder::new(crate::meta_text::WithText::new(out, chunks))
            .write_image(&bytes, w, h, color)
            .map_err(|e| encode_error(path, "PNG", e))
    })
}

/// Writes `w`×`h` 8-bit grey samples (a mask: 255 where a pixel counts, 0 where not) as a
/// one-channel PNG, stored as given (no transfer function), through the atomic writes.
pub fn write_grey_png(path: &Path, (w, h): (u32, u32), samples: &[u8]) -> Result<(), Error> {
    let png = grey_png(path, (w, h), samples)?;
    crate::atomic::land(crate::atomic::stage(path, |out| {
        std::io::Write::write_all(out, &png).map_err(|e| Error::io(path, e))
    })?)
}

/// [`write_grey_png`]'s file in memory (`path` names it in messages).
pub fn grey_png(path: &Path, (w, h): (u32, u32), samples: &[u8]) -> Result<Vec<u8>, Error> {
    if samples.len() != w as usize * h as usize {
        return Err(Error::request(
            path,
            format!("{} grey samples for a {w}×{h} picture", samples.len()),
        ));
    }
    let mut png = Vec::new();
    PngEncoder::new(&mut png)
        .write_image(samples, w, h, ExtendedColorType::L8)
        .map_err(|e| encode_error(path, "PNG", e))?;
    Ok(png)
}

/// A PNG or JPEG file in memory of `w`×`h` RGB sRGB codes as they are (`samples.0`: 8-bit,
/// or with `samples.1` 16-bit in the machine's byte order, PNG only), `path` naming it in
/// messages: a JPEG at `quality` (92 when 0, at most 100) with `segments` (complete JPEG
/// marker segments, such as an EXIF `APP1`) after the encoder's own header segments (SOI
/// and JFIF's `APP0`); a PNG with no text chunks (`segments` must be empty). The same
/// encoders [`write`] uses, fed the codes it would make of a float image.
pub fn encode_codes(
    path: &Path,
    format: Format,
    (w, h): (u32, u32),
    (samples, wide): (&[u8], bool),
    quality: u8,
    segments: &[u8],
) -> Result<Vec<u8>, Error> {
    let expected = w as usize * h as usize * 3 * if wide { 2 } else { 1 };
    if samples.len() != expected {
        return Err(Error::request(
            path,
            format!(
                "{} bytes of samples for a {w}×{h} RGB picture",
                samples.len()
            ),
        ));
    }
    let mut out = Vec::new();
    match format {
        Format::Jpeg if !wide => {
            if w > u16::MAX as u32 || h > u16::MAX as u32 {
                return Err(Error::request(
                    path,
                    format!(
                        "JPEG images are at most 65535 texels wide and high; this one is {w}×{h}"
                    ),
                ));
            }
            let quality = match quality {
                0 => DEFAULT_JPEG_QUALITY,
                q => q.min(100),
            };
            JpegEncoder::new_with_quality(&mut out, quality)
                .write_image(samples, w, h, ExtendedColorType::Rgb8)
                .map_err(|e| encode_error(path, "JPEG", e))?;
            // After SOI, and after APP0 (JFIF) when the encoder wrote one first.
            let mut at = 2;
            if out.len() > 6 && out[2] == 0xFF && out[3] == 0xE0 {
                at = 4 + u16::from_be_bytes([out[4], out[5]]) as usize;
            }
            out.splice(at..at, segments.iter().copied());
        }
        Format::Png if segments.is_empty() => {
            let color = if wide {
                ExtendedColorType::Rgb16
            } else {
                ExtendedColorType::Rgb8
            };
            PngEncoder::new(&mut out)
                .write_image(samples, w, h, color)
                .map_err(|e| encode_error(path, "PNG", e))?;
        }
        other => {
            let what = if wide { "16-bit" } else { "8-bit" };
            return Err(Error::request(
                path,
                format!("{other:?} is not written from {what} codes with these segments"),
            ));
        }
    }
    Ok(out)
}

/// Writes `image` as an 8-bit RGB JPEG at `quality` (92 when 0, at most 100) with
/// `segments` (complete JPEG marker segments, such as an EXIF `APP1`) placed after the
/// encoder's own header segments (SOI and JFIF's `APP0`), through the atomic writes.
pub fn write_jpeg_with_segments(
    path: &Path,
    image: &Image,
    quality: u8,
    segments: &[u8],
) -> Result<(), Error> {
    check_writable_size(path, image)?;
    let size = (image.width(), image.height());
    let codes = encode_u8(image, 3);
    let jpeg = encode_codes(path, Format::Jpeg, size, (&codes, false), quality, segments)?;
    crate::atomic::land(crate::atomic::stage(path, |out| {
        std::io::Write::write_all(out, &jpeg).map_err(|e| Error::io(path, e))
    })?)
}

/// The GPano XMP packet of a lat-long or VR180 picture of `w`×`h` texels (none for other
/// projections and for stereo pairs): 360° viewers show such photos as panoramas.
fn panorama_xmp(info: &crate::MapInfo, w: u32, h: u32) -> Option<String> {
    mirrorball_spherical::gpano::for_picture(&info.projection, info.layout, info.stereo, w, h)
}

// ---------------------------------------------------------------------------------------
// sRGB tables, from `mirrorball_core::color`'s transfer functions.

/// Linear light of each 8-bit sRGB code (what PNG and JPEG samples decode to; raw 8-bit
/// frames through the CLI's pipes too).
pub fn lut8() -> &'static [f32; 256] {
    static LUT: OnceLock<[f32; 256]> = OnceLock::new();
    LUT.get_or_init(|| std::array::from_fn(|k| srgb_to_linear(k as f64 / 255.0) as f32))
}

/// Linear light of each 16-bit sRGB code.
pub fn lut16() -> &'static [f32] {
    static LUT: OnceLock<Vec<f32>> = OnceLock::new();
    LUT.get_or_init(|| {
        (0..=u16::MAX)
            .map(|k| srgb_to_linear(k as f64 / 65535.0) as f32)
            .collect()
    })
}

/// The linear values halfway between consecutive 8-bit codes: code k covers
/// `[T[k-1], T[k])`, so encoding is a binary search that rounds to nearest exactly. The one
/// home of 8-bit sRGB encoding: PNG, JPEG and raw `rgb24` frames all follow it.
pub fn thresholds8() -> &'static [f32; 255] {
    static T: OnceLock<[f32; 255]> = OnceLock::new();
    T.get_or_init(|| std::array::from_fn(|k| srgb_to_linear((k as f64 + 0.5) / 255.0) as f32))
}

/// Linear light to the nearest 8-bit sRGB code, clamping to [0, 1] (NaN gives 0).
#[inline]
pub fn encode8(l: f32, t: &[f32; 255]) -> u8 {
    t.partition_point(|&x| x <= l) as u8
}

/// Linear light to the nearest 16-bit sRGB code, clamping to [0, 1] (NaN gives 0): the one
/// home of 16-bit sRGB encoding (PNG and raw `rgb48le` frames).
#[inline]
pub fn encode16(l: f32) -> u16 {
    if l > 0.0 {
        (linear_to_srgb(l.min(1.0) as f64) * 65535.0 + 0.5) as u16
    } else {
        0
    }
}

/// Alpha (linear, clamped to [0, 1]) to an integer of `max`.
#[inline]
fn encode_alpha(a: f32, max: f32) -> f32 {
    if a > 0.0 {
        (a.min(1.0) * max + 0.5).floor()
    } else {
        0.0
    }
}

/// 8-bit sRGB samples of `image` with `out_channels` channels (3 drops alpha).
fn encode_u8(image: &Image, out_channels: usize) -> Vec<u8> {
    let c = image.channels();
    let t = thresholds8();
    let texels = image.data().len() / c;
    let mut out = vec![0u8; texels * out_channels];
    out.par_chunks_mut(CHUNK_TEXELS * out_channels)
        .zip(image.data().par_chunks(CHUNK_TEXELS * c))
        .for_each(|(dst, src)| {
            for (d, s) in dst.chunks_exact_mut(out_channels).zip(src.chunks_exact(c)) {
                d[0] = encode8(s[0], t);
                d[1] = encode8(s[1], t);
                d[2] = encode8(s[2], t);
                if out_channels == 4 {
                    d[3] = encode_alpha(s[3], 255.0) as u8;
                }
            }
        });
    out
}

/// 16-bit sRGB samples of `image`, RGB or RGBA as the image is.
fn encode_u16(image: &Image) -> Vec<u16> {
    let c = image.channels();
    let mut out = vec![0u16; image.data().len()];
    out.par_chunks_mut(CHUNK_TEXELS * c)
        .zip(image.data().par_chunks(CHUNK_TEXELS * c))
        .for_each(|(dst, src)| {
            for (d, s) in dst.chunks_exact_mut(c).zip(src.chunks_exact(c)) {
                d[0] = encode16(s[0]);
                d[1] = encode16(s[1]);
                d[2] = encode16(s[2]);
                if c == 4 {
                    d[3] = encode_alpha(s[3], 65535.0) as u16;
                }
            }
        });
    out
}

/// Expands `src` (with `sc` interleaved channels: 1 grey, 2 grey+alpha, 3 RGB, 4 RGBA) to
/// linear RGB or RGBA through `lut`, alpha divided by `max`.
fn decode_samples<T: Copy + Into<usize> + Sync>(
    src: &[T],
    sc: usize,
    lut: &[f32],
    max: f32,
) -> Vec<f32> {
    let alpha = sc == 2 || sc == 4;
    let dc = if alpha { 4 } else { 3 };
    let texels = src.len() / sc;
    let mut out = vec![0.0f32; texels * dc];
    let lookup = |v: T| lut.get(v.into()).copied().unwrap_or(1.0);
    out.par_chunks_mut(CHUNK_TEXELS * dc)
        .zip(src.par_chunks(CHUNK_TEXELS * sc))
        .for_each(|(dst, src)| {
            for (d, s) in dst.chunks_exact_mut(dc).zip(src.chunks_exact(sc)) {
                if sc >= 3 {
                    d[0] = lookup(s[0]);
                    d[1] = lookup(s[1]);
                    d[2] = lookup(s[2]);
                } else {
                    let g = lookup(s[0]);
                    d[0] = g;
                    d[1] = g;
                    d[2] = g;
                }
                if alpha {
                    d[3] = s[sc - 1].into() as f32 / max;
                }
            }
        });
    out
}

/// The decoded picture as linear light, with its bit depth and channel layout for the
/// description.
fn to_linear(
    path: &Path,
    decoded: DynamicImage,
) -> Result<(Image, &'static str, &'static str), Error> {
    let (w, h) = (decoded.width(), decoded.height());
    let (data, depth, layout, channels) = match decoded {
        DynamicImage::ImageLuma8(b) => (
            decode_samples(b.as_raw(), 1, lut8(), 255.0),
            "8-bit",
            "grey",
            3,
        ),
        DynamicImage::ImageLumaA8(b) => (
            decode_samples(b.as_raw(), 2, lut8(), 255.0),
            "8-bit",
            "grey with alpha",
            4,
        ),
        DynamicImage::ImageRgb8(b) => (
            decode_samples(b.as_raw(), 3, lut8(), 255.0),
            "8-bit",
            "RGB",
            3,
        ),
        DynamicImage::ImageRgba8(b) => (
            decode_samples(b.as_raw(), 4, lut8(), 255.0),
            "8-bit",
            "RGBA",
            4,
        ),
        DynamicImage::ImageLuma16(b) => (
            decode_samples(b.as_raw(), 1, lut16(), 65535.0),
            "16-bit",
            "grey",
            3,
        ),
        DynamicImage::ImageLumaA16(b) => (
            decode_samples(b.as_raw(), 2, lut16(), 65535.0),
            "16-bit",
            "grey with alpha",
            4,
        ),
        DynamicImage::ImageRgb16(b) => (
            decode_samples(b.as_raw(), 3, lut16(), 65535.0),
            "16-bit",
            "RGB",
            3,
        ),
        DynamicImage::ImageRgba16(b) => (
            decode_samples(b.as_raw(), 4, lut16(), 65535.0),
            "16-bit",
            "RGBA",
            4,
        ),
        other => {
            // Not produced by the PNG, JPEG or WebP decoders today; go through 16 bits.
            if other.color().has_alpha() {
                let b = other.to_rgba16();
                (
                    decode_samples(b.as_raw(), 4, lut16(), 65535.0),
                    "16-bit",
                    "RGBA",
                    4,
                )
            } else {
                let b = other.to_rgb16();
                (
                    decode_samples(b.as_raw(), 3, lut16(), 65535.0),
                    "16-bit",
                    "RGB",
                    3,
                )
            }
        }
    };
    let image = Image::from_vec(w, h, channels, data)
        .ok_or_else(|| Error::input(path, "the decoded image has an inconsistent size".into()))?;
    Ok((image, depth, layout))
}

// ---------------------------------------------------------------------------------------
// Shared by the flat-image readers and writers.

/// Checks a declared width × height against `limits` (and that it is not empty), before
/// anything of that size is allocated.
pub(crate) fn check_limits(
    path: &Path,
    width: u64,
    height: u64,
    limits: &Limits,
) -> Result<(), Error> {
    if width == 0 || height == 0 {
        return Err(Error::input(
            path,
            format!("declares an empty {width}×{height} image"),
        ));
    }
    let max_dim = limits.max_dimension as u64;
    if width > max_dim || height > max_dim {
        return Err(Error::input(
            path,
            format!(
                "declares a {width}×{height} image; the largest width or height allowed is \
                 {max_dim}"
            ),
        ));
    }
    let texels = width.saturating_mul(height);
    if texels > limits.max_texels {
        return Err(Error::input(
            path,
            format!(
                "declares a {width}×{height} image ({texels} texels); at most {} texels are \
                 allowed",
                limits.max_texels
            ),
        ));
    }
    Ok(())
}

/// Refuses to write an empty image.
pub(crate) fn check_writable_size(path: &Path, image: &Image) -> Result<(), Error> {
    if image.width() == 0 || image.height() == 0 {
        return Err(Error::request(
            path,
            format!(
                "cannot write an empty {}×{} image",
                image.width(),
                image.height()
            ),
        ));
    }
    Ok(())
}

/// Runs a decoder, turning a panic inside it (a bug the malformed file triggered) into an
/// input error instead of bringing the program down.
pub(crate) fn guard_decoder<T>(
    path: &Path,
    format_name: &str,
    decode: impl FnOnce() -> Result<T, Error>,
) -> Result<T, Error> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(decode)).unwrap_or_else(|_| {
        Err(Error::input(
            path,
            format!("the {format_name} decoder failed on malformed data"),
        ))
    })
}

/// How a [`Precision`] is named in messages.
pub(crate) fn precision_name(p: Precision) -> &'static str {
    match p {
        Precision::Half => "half",
        Precision::Float => "float",
        Precision::U8 => "8-bit",
        Precision::U16 => "16-bit",
    }
}

/// The `image` crate's limits matching ours (its own check happens while it reads the
/// header; ours, with a clearer message, right after).
fn image_limits(limits: &Limits) -> image::Limits {
    let mut l = image::Limits::default();
    l.max_image_width = Some(limits.max_dimension);
    l.max_image_height = Some(limits.max_dimension);
    // 16-bit RGBA output plus room for the decoder's own buffers.
    l.max_alloc = Some(limits.max_texels.saturating_mul(16).max(64 << 20));
    l
}

/// Turns an `image` crate decoding error into an input error naming the problem.
pub(crate) fn decode_error(path: &Path, format_name: &str, e: ImageError) -> Error {
    match e {
        ImageError::IoError(io) => match io.kind() {
            std::io::ErrorKind::UnexpectedEof => Error::io(path, io),
            std::io::ErrorKind::InvalidData
            | std::io::ErrorKind::InvalidInput
            | std::io::ErrorKind::Other => {
                Error::input(path, format!("not a valid {format_name} file ({io})"))
            }
            _ => Error::io(path, io),
        },
        ImageError::Limits(l) => {
            Error::input(path, format!("declares an image larger than allowed ({l})"))
        }
        ImageError::Unsupported(u) => Error::input(
            path,
            format!("uses a {format_name} feature mirrorball cannot read ({u})"),
        ),
        other => {
            let msg = other.to_string();
            let lower = msg.to_ascii_lowercase();
            if ["eof", "end of file", "not enough bytes", "truncated"]
                .iter()
                .any(|s| lower.contains(s))
            {
                Error::input(path, format!("file is truncated ({msg})"))
            } else {
                Error::input(path, format!("not a valid {format_name} file ({msg})"))
            }
        }
    }
}

/// Turns an `image` crate encoding error into an error naming the problem.
pub(crate) fn encode_error(path: &Path, format_name: &str, e: ImageError) -> Error {
    match e {
        ImageError::IoError(io) => Error::io(path, io),
        other => Error::request(
            path,
            format!("cannot write this image as {format_name} ({other})"),
        ),
    }
}
