//! OpenEXR reading and writing with the `exr` crate, decompressing and compressing blocks
//! on all cores.
//!
//! Reading takes the first layer (part) that has `R`, `G` and `B` channels (and `A` when
//! present), whatever their sample type (half, float or 32-bit unsigned), at its largest
//! resolution level, with any compression the `exr` crate decodes: none, RLE, ZIPS, ZIP,
//! PIZ, PXR24, B44(A) and, since `exr` 1.74.1, DWAA/DWAB. The header is read and checked
//! first: the declared size against the [`Limits`], and the compression against what the
//! crate decodes, so that neither a huge declared size nor an undecodable file (HTJ2K) gets
//! as far as allocating texels.

use crate::atomic::{Dest, Sink, Written};
use crate::input::{Input, Reader};
use crate::ldr_io::{check_limits, check_writable_size, guard_decoder};
use crate::{Error, ExrCompression, Format, Limits, Loaded, Precision, WriteOptions};
use exr::meta::attribute::{AttributeValue, EnvironmentMap, Text};
use exr::meta::header::Header;
use exr::prelude::{
    ChannelDescription, Compression, Encoding, LayerAttributes, LineOrder, ReadChannels,
    ReadLayers, SampleType, SpecificChannels, Vec2, WritableImage,
};
use mirrorball_core::simd::F32x4;
use mirrorball_core::{Image, ProjectionKind};
use mirrorball_encode::{Range, Storage};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// What half samples hold: values beyond ±65504 are written as it ([`Range::fit`]), so that a
/// bright sun does not turn into infinity. (Float's fit changes no `f32`: float samples are
/// written as they are.)
const HALF: Range = Storage::Texels(mirrorball_encode::Encoding::Rgba16F).range();

/// Reads the first RGB(A) layer of an OpenEXR file as linear `f32` texels.
///
/// The `envmap` header attribute, if present, becomes [`Loaded::declared`] (latlong or
/// cube), and the `mirrorball:projection` and `mirrorball:layout` string attributes
/// [`Loaded::recorded`]. Files using a compression the `exr` crate cannot decode (HTJ2K) are refused
/// before any texel is decoded, with a message that says how to re-save them.
pub fn read(input: &Input, limits: &Limits) -> Result<Loaded, Error> {
    guard_decoder(input.path(), "OpenEXR", || read_input(input, limits))
}

fn read_input(input: &Input, limits: &Limits) -> Result<Loaded, Error> {
    let path = input.path();
    // Headers only: nothing sized by the file is allocated yet. `Counted` remembers where
    // they end, which is where the offset table starts.
    let header_end = Arc::new(AtomicU64::new(0));
    let chunks = exr::block::read(
        Counted {
            inner: input.reader().map_err(|e| Error::io(path, e))?,
            taken: header_end.clone(),
        },
        false,
    )
    .map_err(|e| read_error(path, e))?;
    let headers = chunks.headers();
    check_headers(input, headers, limits)?;

    let layer_count = headers.len();

    // The common case (a layer of exactly R, G, B and maybe A, half or float) straight from
    // the decompressed blocks; anything else through the crate's generic image reader.
    let index = headers.iter().position(is_rgb_layer).unwrap_or(0);
    if let Some(layout) = block_layout(&headers[index]) {
        let header = headers[index].clone();
        return read_laid_out(input, chunks, &header_end, index, header, &layout);
    }
    read_generic(path, chunks, layer_count)
}

/// Checks the headers before any texel is read: there is an RGB layer; every RGB layer is
/// within the `limits` and fits the file; the first one's compression is one the crate
/// decodes; and DWAA/DWAB blocks, if any layer has them, are safe to decode.
fn check_headers(input: &Input, headers: &[Header], limits: &Limits) -> Result<(), Error> {
    let path = input.path();
    let Some(header) = headers.iter().find(|h| is_rgb_layer(h)) else {
        return Err(Error::input(path, no_rgb_layer_problem(headers)));
    };
    // The reader picks the first layer it can read, which is this one unless the file is
    // odd; checking every RGB layer guarantees nothing larger than the limits is allocated.
    for h in headers.iter().filter(|h| is_rgb_layer(h)) {
        check_limits(
            path,
            h.layer_size.width() as u64,
            h.layer_size.height() as u64,
            limits,
        )?;
        check_fits_file(input, h)?;
    }
    if let Some(problem) = undecodable_compression(header.compression) {
        return Err(Error::input(path, problem));
    }
    if headers
        .iter()
        .any(|h| matches!(h.compression, Compression::DWAA(_) | Compression::DWAB(_)))
    {
        check_dwa_blocks(input)?;
    }
    Ok(())
}

/// Reads layer `index` (`header`, whose channels `layout` places) straight from its
/// decompressed blocks: a lone single-part ZIP scan-line layer through [`read_zip_file`]
/// (which also counts the invalid samples), anything else through [`read_blocks`].
fn read_laid_out(
    input: &Input,
    chunks: exr::block::reader::Reader<Counted<Reader<'_>>>,
    header_end: &AtomicU64,
    index: usize,
    header: Header,
    layout: &[(usize, SampleType)],
) -> Result<Loaded, Error> {
    let path = input.path();
    let layer_count = chunks.headers().len();
    // A multi-part file (even one of a single part) puts a part number before each
    // block: that the crate's reader handles.
    let single_part = !chunks.meta_data().requirements.has_multiple_layers;
    let (image, invalid) = if single_part && layer_count == 1 && is_zip_scanlines(&header) {
        drop(chunks);
        read_zip_file(input, header_end.load(Ordering::Relaxed), &header, layout)
            .map(|(image, invalid)| (image, Some(invalid)))
    } else {
        read_blocks(chunks, index, &header, layout).map(|image| (image, None))
    }
    .map_err(|e| read_error(path, e))?;
    let declared = envmap_kind(header.own_attributes.environment_map);
    let recorded = recorded_info(path, &header.own_attributes, image.width(), image.height());
    let types: Vec<SampleType> = header.channels.list.iter().map(|c| c.sample_type).collect();
    let layer_name = header
        .own_attributes
        .layer_name
        .as_ref()
        .map(|n| n.to_string());
    let tiled = matches!(header.blocks, exr::meta::BlockDescription::Tiles(_));
    let description = describe(
        &types,
        header.compression,
        image.channels(),
        tiled,
        layer_count,
        layer_name,
    );
    Ok(Loaded {
        layers: vec![image],
        declared,
        recorded,
        format: Format::Exr,
        description,
        invalid,
    })
}

/// Reads the first valid RGB(A) layer through the crate's generic image reader (at its
/// largest resolution level, on this thread) and describes it; `layer_count` is the
/// number of layers in the file.
fn read_generic(
    path: &Path,
    chunks: exr::block::reader::Reader<Counted<Reader<'_>>>,
    layer_count: usize,
) -> Result<Loaded, Error> {
    // On this thread: the crate's parallel decoding runs blocks on a pool of its own, where
    // a decoder's panic aborts the process instead of reaching `guard_decoder`.
    let exr_image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(create_texels, set_texel)
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_chunks(chunks)
        .map_err(|e| read_error(path, e))?;

    // Describe the layer that was read (the first readable RGB one).
    let layer = exr_image.layer_data;
    let declared = envmap_kind(layer.attributes.environment_map);
    let recorded = recorded_info(
        path,
        &layer.attributes,
        layer.size.width() as u32,
        layer.size.height() as u32,
    );
    let compression = layer.encoding.compression;
    let tiled = matches!(layer.encoding.blocks, exr::image::Blocks::Tiles(_));
    let layer_name = layer.attributes.layer_name.as_ref().map(|n| n.to_string());
    let channels = layer.channel_data.channels;
    let texels = layer.channel_data.pixels;
    let (width, height) = (layer.size.width(), layer.size.height());
    let nchannels = texels.channels;
    let image = Image::from_vec(width as u32, height as u32, nchannels, texels.data)
        .ok_or_else(|| Error::input(path, "the decoded layer has an inconsistent size".into()))?;

    let mut sample_types = vec![
        channels.0.sample_type,
        channels.1.sample_type,
        channels.2.sample_type,
    ];
    if let Some(alpha) = &channels.3 {
        sample_types.push(alpha.sample_type);
    }
    let description = describe(
        &sample_types,
        compression,
        nchannels,
        tiled,
        layer_count,
        layer_name,
    );

    Ok(Loaded {
        invalid: None,
        layers: vec![image],
        declared,
        recorded,
        format: Format::Exr,
        description,
    })
}

/// The kind OpenEXR's `envmap` attribute names.
fn envmap_kind(envmap: Option<EnvironmentMap>) -> Option<ProjectionKind> {
    envmap.map(|m| match m {
        EnvironmentMap::LatitudeLongitude => ProjectionKind::LatLong,
        EnvironmentMap::Cube => ProjectionKind::Cube,
    })
}

/// [`Loaded::recorded`] from the string attributes of a layer of `path`.
fn recorded_info(
    path: &Path,
    attributes: &LayerAttributes,
    w: u32,
    h: u32,
) -> Option<Result<crate::MapInfo, Error>> {
    let get = |key: &str| match attributes.other.get(&Text::new_or_panic(key)) {
        Some(AttributeValue::Text(t)) => Some(t.to_string()),
        _ => None,
    };
    crate::recorded(path, get, w, h)
}

/// The string attribute `key = value` (the texts are ASCII, which OpenEXR's strings hold).
fn text_attribute(key: &str, value: String) -> Option<(Text, AttributeValue)> {
    Some((
        Text::new_or_none(key)?,
        AttributeValue::Text(Text::new_or_none(value)?),
    ))
}

/// Layer attributes for a written file: the projection as a string attribute
/// ([`crate::PROJECTION_KEY`]). No `envmap` attribute: OpenEXR's lat-long and cube
/// conventions are not mirrorball's (see [`crate::openexr`]), and pictures are written in
/// mirrorball's.
fn layer_attributes(opts: &WriteOptions) -> LayerAttributes {
    let mut attributes = LayerAttributes::default();
    if let Some(info) = &opts.declared {
        attributes
            .other
            .extend(text_attribute(crate::PROJECTION_KEY, info.texts().0));
    } else if let Some(note) = opts.note {
        // Alone in its map (no projection is declared), so the header's bytes stay the same
        // from run to run.
        attributes
            .other
            .extend(text_attribute(crate::CONTENT_KEY, note.text().to_string()));
    }
    attributes
}

/// The [`crate::CONTENT_KEY`] text of the OpenEXR file at `path`, from its header alone.
pub(crate) fn content_text(path: &Path) -> Option<String> {
    let meta = exr::meta::MetaData::read_from_file(path, false).ok()?;
    let key = Text::new_or_panic(crate::CONTENT_KEY);
    meta.headers
        .iter()
        .find_map(|h| match h.own_attributes.other.get(&key) {
            Some(AttributeValue::Text(t)) => Some(t.to_string()),
            _ => None,
        })
}

/// The layout attribute ([`crate::LAYOUT_KEY`]) of a written file, given to the image's
/// attributes: the `exr` crate keeps each set of extra attributes in a hash map, which
/// orders them differently from run to run, so with one in each the header's bytes are the
/// same every time. (Readers find both in the one header.)
fn image_other(opts: &WriteOptions) -> std::collections::HashMap<Text, AttributeValue> {
    let layout = opts.declared.as_ref().and_then(|info| info.texts().1);
    layout
        .and_then(|l| text_attribute(crate::LAYOUT_KEY, l))
        .into_iter()
        .collect()
}

/// Writes `image` as a single-part scan-line OpenEXR file: half texels unless
/// `opts.precision` asks for float, compressed with `opts.exr_compression`, RGB or RGBA by
/// the image's channel count. Blocks are compressed on all cores, into a temporary file
/// that the returned [`Written`] renames into place, or to memory (`dest`). `buffers` are kept between
/// files.
///
/// Half output writes finite values beyond ±65504 (the largest half) as it instead of
/// overflowing to infinity ([`Range::fit`]; NaN and infinities are kept).
pub fn write(
    dest: Dest,
    image: &Image,
    opts: &WriteOptions,
    buffers: &mut WriteBuffers,
) -> Result<Written, Error> {
    let path = dest.path();
    let sample_type = match opts.precision {
        None | Some(Precision::Half) => SampleType::F16,
        Some(Precision::Float) => SampleType::F32,
        Some(other) => {
            return Err(Error::request(
                path,
                format!(
                    "OpenEXR stores half or float texels, not {}; use .png for integer texels",
                    crate::ldr_io::precision_name(other)
                ),
            ))
        }
    };
    check_writable_size(path, image)?;
    let compression = match opts.exr_compression {
        ExrCompression::None => Compression::Uncompressed,
        ExrCompression::Rle => Compression::RLE,
        ExrCompression::Zips => Compression::ZIP1,
        ExrCompression::Zip => Compression::ZIP16,
        ExrCompression::Piz => Compression::PIZ,
        ExrCompression::Pxr24 => Compression::PXR24,
    };
    let encoding = Encoding {
        compression,
        blocks: exr::image::Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let size = Vec2(image.width() as usize, image.height() as usize);
    let width = size.width();
    let data = image.data();
    let half = sample_type == SampleType::F16;
    let describe = |name: &str| ChannelDescription::named(name, sample_type);
    // Half fits its range; float passes values through (its fit changes none).
    let fit = move |v: f32| if half { HALF.fit(0, v) } else { v };

    if image.channels() == 4 {
        let texels = SpecificChannels {
            channels: (describe("R"), describe("G"), describe("B"), describe("A")),
            pixels: move |p: Vec2<usize>| {
                let i = (p.y() * width + p.x()) * 4;
                (
                    fit(data[i]),
                    fit(data[i + 1]),
                    fit(data[i + 2]),
                    fit(data[i + 3]),
                )
            },
        };
        let layer = exr::image::Layer::new(size, layer_attributes(opts), encoding, texels);
        let mut exr_image = exr::image::Image::from_layer(layer);
        exr_image.attributes.other = image_other(opts);
        dest.emit(|out| {
            write_layer(out, exr_image.write(), image, buffers).map_err(|e| write_error(path, e))
        })
    } else {
        let texels = SpecificChannels {
            channels: (describe("R"), describe("G"), describe("B")),
            pixels: move |p: Vec2<usize>| {
                let i = (p.y() * width + p.x()) * 3;
                (fit(data[i]), fit(data[i + 1]), fit(data[i + 2]))
            },
        };
        let layer = exr::image::Layer::new(size, layer_attributes(opts), encoding, texels);
        let mut exr_image = exr::image::Image::from_layer(layer);
        exr_image.attributes.other = image_other(opts);
        dest.emit(|out| {
            write_layer(out, exr_image.write(), image, buffers).map_err(|e| write_error(path, e))
        })
    }
}

/// The work of packing (and, for ZIP, compressing) one texel as mirrorball's own writers
/// do, in [`mirrorball_core::work`]'s units: what they count (PIZ, B44 and the others are
/// written by the `exr` crate, which counts nothing).
pub(crate) const EXR_WORK: u64 = 60;

/// Bytes [`write`] holds besides `image` (`w`×`h`, `c` channels) while it writes it: for
/// ZIP and ZIPS, a batch of 32 blocks compressed (at most their packed size) and each
/// thread's packed block; uncompressed, its two line buffers; for the other compressions,
/// which the `exr` crate writes, as much as the packed picture.
pub(crate) fn write_buffer_bytes(w: u32, h: u32, c: usize, opts: &WriteOptions) -> u64 {
    let sample = match opts.precision {
        Some(Precision::Float) => 4,
        _ => 2,
    };
    let line = w as u64 * c as u64 * sample;
    let threads = rayon::current_num_threads() as u64;
    let lines = match opts.exr_compression {
        ExrCompression::Zip => (32 + threads) * 16,
        ExrCompression::Zips => 32 + threads,
        ExrCompression::None => return 2 * line.max(2 << 20),
        _ => h as u64,
    };
    lines.min(h as u64) * line
}

/// Writes a one-layer image: uncompressed, ZIP and ZIPS blocks made here on all cores (ZIP
/// compressed with libdeflate, [`crate::exr_zip`]), each block's samples taken straight
/// from `image` (half samples clamped as `fit` in [`write`] does); the `exr` crate writes
/// the header and offset table, and blocks of other compressions.
fn write_layer<'i, L, F>(
    out: &mut dyn Sink,
    writer: exr::image::write::WriteImageWithOptions<'i, L, F>,
    image: &Image,
    buffers: &mut WriteBuffers,
) -> exr::error::UnitResult
where
    L: exr::image::write::layers::WritableLayers<'i>,
    F: FnMut(f64),
{
    use exr::block::chunk::{Chunk, CompressedBlock, CompressedScanLineBlock};
    use rayon::prelude::*;
    let headers = writer.infer_meta_data();
    let header = &headers[0];
    let zip = matches!(header.compression, Compression::ZIP1 | Compression::ZIP16);
    // Each channel of the file, in its order, as an index into a texel and a sample type.
    let layout = match block_layout(header) {
        Some(l)
            if (zip || header.compression == Compression::Uncompressed)
                && matches!(header.blocks, exr::meta::BlockDescription::ScanLines) =>
        {
            l
        }
        _ => return writer.to_buffered(out),
    };
    if !zip {
        return write_uncompressed(out, &headers, image, &layout, buffers);
    }
    let (w, c) = (image.width() as usize, image.channels());
    let data = image.data();
    let y0 = header.own_attributes.layer_position.y();
    exr::block::write(out, headers, true, |meta, chunks| {
        use exr::block::writer::ChunksWriter;
        let blocks: Vec<(usize, exr::block::BlockIndex)> =
            meta.enumerate_ordered_header_block_indices().collect();
        let line_bytes = line_bytes(w, &layout);
        // A batch of blocks compressed in parallel, then written in order.
        for batch in blocks.chunks(32) {
            let packed: Vec<Chunk> = batch
                .par_iter()
                .map_init(
                    || (Vec::new(), Vec::new(), (Vec::new(), Vec::new())),
                    |(raw, scratch, lanes), (_, block)| {
                        let (by, bh) = (block.pixel_position.y(), block.pixel_size.y());
                        // Every byte is packed below: resizing a kept buffer writes nothing.
                        raw.resize(bh * line_bytes, 0);
                        let rows = &data[by * w * c..(by + bh) * w * c];
                        pack_lines(rows, w, c, &layout, raw, lanes);
                        let mut packed = Vec::new();
                        crate::exr_zip::THREAD_ZIP.with_borrow_mut(|deflater| {
                            crate::exr_zip::compress(raw, scratch, deflater, &mut packed)
                        });
                        mirrorball_core::work::add(EXR_WORK * (bh * w) as u64);
                        Chunk {
                            layer_index: 0,
                            compressed_block: CompressedBlock::ScanLine(CompressedScanLineBlock {
                                y_coordinate: y0 + by as i32,
                                compressed_pixels_le: packed,
                            }),
                        }
                    },
                )
                .collect();
            for ((index, _), chunk) in batch.iter().zip(packed) {
                chunks.write_chunk(*index, chunk)?;
            }
        }
        Ok(())
    })
}

/// Writes a one-layer uncompressed scan-line file (`headers`, from the `exr` crate, which
/// also writes their bytes): the offset table follows from the line size, and the lines
/// (each its `y`, its byte count and its samples, [`pack_lines`]) are packed on all cores a
/// batch of about 2 MiB at a time straight into a buffer, which goes to the file as one
/// write while the next batch is packed into a second. (Through the crate's chunk writer
/// each line was a fresh zeroed buffer, then copied again into the file's buffer: 150 MB of
/// memory traffic for a 6×1024² float cube.)
/// The bytes are exactly those the `exr` crate writes (a test compares them).
fn write_uncompressed(
    out: &mut dyn Sink,
    headers: &[Header],
    image: &Image,
    layout: &[(usize, SampleType)],
    buffers: &mut WriteBuffers,
) -> exr::error::UnitResult {
    use exr::meta::{magic_number, MetaData};
    use rayon::prelude::*;
    let header = &headers[0];
    let (w, h, c) = (
        image.width() as usize,
        image.height() as usize,
        image.channels(),
    );
    debug_assert_eq!(header.chunk_count, h, "one line a block");
    let y0 = header.own_attributes.layer_position.y() as i64;
    let line = line_bytes(w, layout);
    // A line's record: its y (i32), its byte count (i32), its samples.
    let record = 8 + line;
    let size = i32::try_from(line)
        .map_err(|_| exr::error::Error::Invalid("a line too long for OpenEXR".into()))?;
    let mut head = Vec::new();
    let requirements = MetaData::validate(headers, true)?;
    magic_number::write(&mut head)?;
    requirements.write(&mut head)?;
    Header::write_all(headers, &mut head, requirements.has_multiple_layers)?;
    let first = (head.len() + 8 * h) as u64;
    for y in 0..h as u64 {
        head.extend_from_slice(&(first + y * record as u64).to_le_bytes());
    }
    out.write_all(&head)?;
    let batch = ((2 << 20) / record).clamp(1, h.max(1));
    let data = image.data();
    // Packs the lines from `start` into `buf` (every byte is written: resizing a buffer
    // that held a batch before writes nothing).
    let pack = |start: usize, buf: &mut Vec<u8>| {
        let lines = batch.min(h - start);
        buf.resize(lines * record, 0);
        buf.par_chunks_mut(record).enumerate().for_each_init(
            || (Vec::new(), Vec::new()),
            |lanes, (k, rec)| {
                let y = start + k;
                rec[..4].copy_from_slice(&((y0 + y as i64) as i32).to_le_bytes());
                rec[4..8].copy_from_slice(&size.to_le_bytes());
                mirrorball_core::work::add(EXR_WORK * w as u64);
                pack_lines(
                    &data[y * w * c..(y + 1) * w * c],
                    w,
                    c,
                    layout,
                    &mut rec[8..],
                    lanes,
                );
            },
        );
    };
    // Two buffers: each batch is handed to the kernel while the next is packed.
    let [ready, next] = &mut buffers.lines;
    pack(0, ready);
    for start in (batch..h).step_by(batch) {
        let (written, ()) = rayon::join(|| out.write_all(ready), || pack(start, next));
        written?;
        std::mem::swap(ready, next);
    }
    out.write_all(ready)?;
    Ok(())
}

/// What the writer keeps from one file to the next: the uncompressed writer's two batch
/// buffers (~2 MiB each). Freed, they would go back to the kernel (the allocator maps and
/// unmaps blocks this large), and the next file's would be fresh memory, zeroed and mapped
/// a page at a time on first touch. An [`crate::OutputSet`] keeps one for its files.
#[derive(Debug, Default)]
pub(crate) struct WriteBuffers {
    lines: [Vec<u8>; 2],
}

/// Lays out `rows` (interleaved texels, `w` a row, `c` channels) as a scan-line block's raw
/// little-endian bytes in `out` (exactly the block's size): each line its channels one after
/// another, in the file's order and sample types (`layout`, see [`block_layout`]). Half
/// samples are fitted to half's range ([`Range::fit`]) and converted a line at a time
/// (F16C where the processor has it). `lanes` are buffers kept between calls.
fn pack_lines(
    rows: &[f32],
    w: usize,
    c: usize,
    layout: &[(usize, SampleType)],
    out: &mut [u8],
    (lane, halves): &mut (Vec<f32>, Vec<half::f16>),
) {
    use half::slice::HalfFloatSliceExt;
    if all_float(layout) {
        return pack_float_lines(rows, w, c, layout, out);
    }
    lane.resize(w, 0.0);
    halves.resize(w, half::f16::ZERO);
    let mut at = 0;
    for row in rows.chunks_exact(w * c) {
        for &(k, st) in layout {
            for (d, px) in lane.iter_mut().zip(row.chunks_exact(c)) {
                *d = px[k];
            }
            if st == SampleType::F16 {
                for v in lane.iter_mut() {
                    *v = HALF.fit(0, *v);
                }
                halves.convert_from_f32_slice(lane);
                for (d, h) in out[at..at + 2 * w].chunks_exact_mut(2).zip(halves.iter()) {
                    d.copy_from_slice(&h.to_le_bytes());
                }
                at += 2 * w;
            } else {
                for (d, v) in out[at..at + 4 * w].chunks_exact_mut(4).zip(lane.iter()) {
                    d.copy_from_slice(&v.to_le_bytes());
                }
                at += 4 * w;
            }
        }
    }
}

/// The decoded texels of one layer, interleaved RGB or RGBA, top row first.
struct Texels {
    width: usize,
    channels: usize,
    data: Vec<f32>,
}

/// Allocates the texels of a layer whose size was checked against the limits.
fn create_texels(size: Vec2<usize>, channels: &exr::image::RgbaChannels) -> Texels {
    let nchannels = if channels.3.is_some() { 4 } else { 3 };
    Texels {
        width: size.width(),
        channels: nchannels,
        data: vec![0.0; size.area() * nchannels],
    }
}

/// What [`Loaded::description`] says of an EXR layer.
fn describe(
    sample_types: &[SampleType],
    compression: Compression,
    nchannels: usize,
    tiled: bool,
    layer_count: usize,
    layer_name: Option<String>,
) -> String {
    let mut description = format!(
        "OpenEXR, {}, {}, {}",
        sample_type_names(sample_types),
        compression_description(compression),
        if nchannels == 4 { "RGBA" } else { "RGB" }
    );
    if tiled {
        description.push_str(", tiled");
    }
    if layer_count > 1 {
        match layer_name {
            Some(name) => description.push_str(&format!(", layer \"{name}\" of {layer_count}")),
            None => description.push_str(&format!(", first RGB layer of {layer_count}")),
        }
    }
    description
}

/// For a layer of exactly `R`, `G`, `B` (and `A`), each half or float and fully sampled:
/// for each channel in the file's order (sorted by name), its index in an interleaved
/// texel and its sample type. `None` for any other layer.
fn block_layout(header: &Header) -> Option<Vec<(usize, SampleType)>> {
    let list = &header.channels.list;
    let mut layout = Vec::with_capacity(list.len());
    for c in list.iter() {
        let index = match c.name.to_string().as_str() {
            "R" => 0,
            "G" => 1,
            "B" => 2,
            "A" => 3,
            _ => return None,
        };
        if !matches!(c.sample_type, SampleType::F16 | SampleType::F32) || c.sampling != Vec2(1, 1) {
            return None;
        }
        layout.push((index, c.sample_type));
    }
    let n = layout.len();
    let mut seen = [false; 4];
    for &(i, _) in &layout {
        seen[i] = true;
    }
    let ok = (n == 3 && seen[..3] == [true; 3] && !seen[3]) || (n == 4 && seen == [true; 4]);
    ok.then_some(layout)
}

/// Reads layer `index` (laid out as `layout`, see [`block_layout`]) from its decompressed
/// blocks, decompressed on all cores, each block's lines of per-channel samples
/// interleaved straight into the texels. Blocks that do not fit the layer are an error,
/// never a panic.
///
/// The blocks are decompressed here, a batch at a time with rayon, rather than by the
/// crate's `decompress_parallel`: that runs each block on a thread pool of its own, where
/// a decoder panicking on a malformed block (B44 overflowed on one in the hostile corpus)
/// aborts the whole process, while a panic under `par_iter` comes back to this thread,
/// where [`guard_decoder`] turns it into an error.
fn read_blocks<R: std::io::Read + std::io::Seek + Send>(
    chunks: exr::block::reader::Reader<R>,
    index: usize,
    header: &Header,
    layout: &[(usize, SampleType)],
) -> Result<Image, exr::error::Error> {
    use exr::block::reader::ChunksReader;
    let (w, h) = (header.layer_size.width(), header.layer_size.height());
    let n = layout.len();
    let reader = chunks.filter_chunks(false, |_, _, block| {
        block.layer == index && block.level == Vec2(0, 0)
    })?;
    let mut data = vec![0.0f32; w * h * n];
    let meta = reader.meta_data().clone();
    let mut insert = |block: exr::block::UncompressedBlock| {
        let (bx, by) = (
            block.index.pixel_position.x(),
            block.index.pixel_position.y(),
        );
        let (bw, bh) = (block.index.pixel_size.x(), block.index.pixel_size.y());
        if bx + bw > w || by + bh > h {
            return Err(outside());
        }
        scatter(
            &block.data,
            &mut data[(by * w) * n..((by + bh - 1) * w + bx + bw) * n],
            w,
            bx,
            bw,
            bh,
            layout,
            true,
        )
    };
    use rayon::prelude::*;
    let mut chunks = reader.peekable();
    // Enough blocks in a batch to keep every core busy, few enough to bound the memory.
    let batch = rayon::current_num_threads() * 4;
    while chunks.peek().is_some() {
        let taken: Vec<exr::block::chunk::Chunk> =
            chunks.by_ref().take(batch).collect::<Result<_, _>>()?;
        let blocks: Vec<exr::block::UncompressedBlock> = taken
            .into_par_iter()
            .map(|chunk| exr::block::UncompressedBlock::decompress_chunk(chunk, &meta, false))
            .collect::<Result<_, _>>()?;
        for block in blocks {
            insert(block)?;
        }
    }
    Image::from_vec(w as u32, h as u32, n, data)
        .ok_or_else(|| exr::error::Error::Invalid("inconsistent layer size".into()))
}

/// Bytes a sample of a [`block_layout`] channel takes: float or half.
fn sample_bytes(st: SampleType) -> usize {
    if st == SampleType::F32 {
        4
    } else {
        2
    }
}

/// Bytes a line of `w` texels laid out as `layout` takes in a block.
fn line_bytes(w: usize, layout: &[(usize, SampleType)]) -> usize {
    w * layout
        .iter()
        .map(|&(_, st)| sample_bytes(st))
        .sum::<usize>()
}

fn outside() -> exr::error::Error {
    exr::error::Error::Invalid("a block lies outside its layer or is too short".into())
}

/// Interleaves the samples of a block's lines (`bh` lines of `bw` texels from column `bx`;
/// each line its channels in the file's order, as `layout` gives them) into `rows`, the
/// layer's texels from the block's first line on (`w` texels a row). `native`: the samples
/// are in this machine's byte order (the `exr` crate converts them), else little-endian.
#[allow(clippy::too_many_arguments)]
fn scatter(
    bytes: &[u8],
    rows: &mut [f32],
    w: usize,
    bx: usize,
    bw: usize,
    bh: usize,
    layout: &[(usize, SampleType)],
    native: bool,
) -> Result<(), exr::error::Error> {
    let n = layout.len();
    let mut off = 0;
    for y in 0..bh {
        let row = rows
            .get_mut((y * w + bx) * n..(y * w + bx + bw) * n)
            .ok_or_else(outside)?;
        for &(c, st) in layout {
            let size = sample_bytes(st);
            let src = bytes.get(off..off + bw * size).ok_or_else(outside)?;
            off += bw * size;
            let dst = row.iter_mut().skip(c).step_by(n);
            match (size, native) {
                (4, true) => {
                    for (d, s) in dst.zip(src.chunks_exact(4)) {
                        *d = f32::from_ne_bytes([s[0], s[1], s[2], s[3]]);
                    }
                }
                (4, false) => {
                    for (d, s) in dst.zip(src.chunks_exact(4)) {
                        *d = f32::from_le_bytes([s[0], s[1], s[2], s[3]]);
                    }
                }
                (_, true) => {
                    for (d, s) in dst.zip(src.chunks_exact(2)) {
                        *d = half::f16::from_bits(u16::from_ne_bytes([s[0], s[1]])).to_f32();
                    }
                }
                (_, false) => {
                    for (d, s) in dst.zip(src.chunks_exact(2)) {
                        *d = half::f16::from_bits(u16::from_le_bytes([s[0], s[1]])).to_f32();
                    }
                }
            }
        }
    }
    Ok(())
}

/// Whether a layer is ZIP or ZIPS compressed scan lines, which [`read_zip_file`] reads.
fn is_zip_scanlines(header: &Header) -> bool {
    matches!(header.compression, Compression::ZIP1 | Compression::ZIP16)
        && matches!(header.blocks, exr::meta::BlockDescription::ScanLines)
}

/// A reader that keeps count of the bytes taken from it (in `taken`), so that after the
/// `exr` crate has read the headers through it, the count is where the offset table starts.
/// (The crate's own reader hides its position; it reads the headers' closing null byte and
/// nothing after it.)
struct Counted<R> {
    inner: R,
    taken: Arc<AtomicU64>,
}

impl<R: std::io::Read> std::io::Read for Counted<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.taken.fetch_add(n as u64, Ordering::Relaxed);
        Ok(n)
    }
}

impl<R: std::io::Seek> std::io::Seek for Counted<R> {
    fn seek(&mut self, to: std::io::SeekFrom) -> std::io::Result<u64> {
        let at = self.inner.seek(to)?;
        self.taken.store(at, Ordering::Relaxed);
        Ok(at)
    }
}

/// Reads a single-part file of ZIP or ZIPS scan lines (layer `header`, laid out as `layout`)
/// whose offset table starts at byte `table_at`: the blocks are read, inflated with
/// libdeflate ([`crate::exr_zip`]) and interleaved into their rows on all cores at once,
/// each core reading its blocks with positioned reads into buffers it keeps, so nothing is
/// read twice, nothing is allocated per block and no core waits for a reader. Every block
/// must sit at its place in the layer exactly once; blocks past the end of the file, or
/// larger than their lines, are errors, never a panic or an allocation.
fn read_zip_file(
    input: &Input,
    table_at: u64,
    header: &Header,
    layout: &[(usize, SampleType)],
) -> Result<(Image, u64), exr::error::Error> {
    use rayon::prelude::*;
    use std::cell::RefCell;
    use std::sync::Mutex;
    /// A thread's buffers (compressed block, inflated stream, raw lines); its inflater is
    /// [`crate::exr_zip::THREAD_ZIP`].
    type Scratch = (Vec<u8>, Vec<u8>, Vec<u8>);
    thread_local! {
        static SCRATCH: RefCell<Scratch> =
            const { RefCell::new((Vec::new(), Vec::new(), Vec::new())) };
    }
    let file_len = input.len();
    let (w, h) = (header.layer_size.width(), header.layer_size.height());
    let n = layout.len();
    let lines = header.compression.scan_lines_per_block();
    let line_bytes = line_bytes(w, layout);
    let float = all_float(layout);
    let top = header.own_attributes.layer_position.y() as i64;
    // The offset table: one u64 a block (the count follows from the header's size, which
    // the caller has checked against the limits).
    let count = h.div_ceil(lines);
    let table = read_offset_table(input, table_at, count, file_len)?;
    // Zeroed texels in huge pages where the system has them (see `Image::new`): a 4096×2048
    // float source would otherwise take ~25,000 page faults as the blocks land.
    let mut image = Image::new(w as u32, h as u32, n);
    let rows: Vec<Mutex<Option<&mut [f32]>>> = image
        .data_mut()
        .chunks_mut(w * n * lines)
        .map(|r| Mutex::new(Some(r)))
        .collect();
    let invalid = AtomicU64::new(0);
    table
        .par_chunks_exact(8)
        .try_for_each(|entry| -> Result<(), exr::error::Error> {
            let (at, y, size) = read_block_head(input, entry, file_len)?;
            let out = claim_block_rows(&rows, y, top, lines)?;
            let bh = out.len() / (w * n);
            let expected = bh * line_bytes;
            let size = checked_block_size(size, expected, y, at, file_len)?;
            SCRATCH.with_borrow_mut(|(block, inflated, raw)| {
                block.resize(size, 0);
                input.read_at(block, at + 8)?;
                let lines = crate::exr_zip::THREAD_ZIP
                    .with_borrow_mut(|zip| crate::exr_zip::inflate(block, expected, inflated, zip))
                    .map_err(|e| exr::error::Error::Invalid(e.into()))?;
                // Counted as the texels are laid out, or while the block is in cache: a clean
                // map then needs no other pass.
                let bad = match lines {
                    crate::exr_zip::Lines::Split { evens, odds } if float => {
                        scatter_split_f32(evens, odds, out, w, bh, layout)
                    }
                    _ => {
                        scatter(lines.to_bytes(raw), out, w, 0, w, bh, layout, false)?;
                        mirrorball_core::count_invalid(out, n == 4)
                    }
                };
                invalid.fetch_add(bad, Ordering::Relaxed);
                Ok(())
            })
        })?;
    check_no_missing_block(&rows, top, lines)?;
    drop(rows);
    Ok((image, invalid.into_inner()))
}

/// The error for a block or table that reaches past the end of the file.
fn truncated_zip_file() -> exr::error::Error {
    exr::error::Error::Invalid("missing bytes: the file is truncated".into())
}

/// Reads the offset table of a [`read_zip_file`] layer: `count` little-endian u64s at
/// byte `table_at`, which must lie inside the file's `file_len` bytes.
fn read_offset_table(
    input: &Input,
    table_at: u64,
    count: usize,
    file_len: u64,
) -> Result<Vec<u8>, exr::error::Error> {
    let table_len = count as u64 * 8;
    if table_at
        .checked_add(table_len)
        .is_none_or(|end| end > file_len)
    {
        return Err(truncated_zip_file());
    }
    let mut table = vec![0u8; count * 8];
    input.read_at(&mut table, table_at)?;
    Ok(table)
}

/// Reads the 8 bytes at the offset an offset table `entry` gives: the block's first line
/// (y) and its compressed size. Returns the offset, y and the size as declared.
fn read_block_head(
    input: &Input,
    entry: &[u8],
    file_len: u64,
) -> Result<(u64, i64, i32), exr::error::Error> {
    let at = u64::from_le_bytes(entry.try_into().expect("8 bytes"));
    let mut head = [0u8; 8];
    if at.checked_add(8).is_none_or(|end| end > file_len) {
        return Err(truncated_zip_file());
    }
    input.read_at(&mut head, at)?;
    let y = i32::from_le_bytes(head[..4].try_into().expect("4 bytes")) as i64;
    let size = i32::from_le_bytes(head[4..].try_into().expect("4 bytes"));
    Ok((at, y, size))
}

/// Takes the rows of texels the block of `lines` lines from `y` fills (the layer starting
/// at line `top`): an error when `y` is not the first line of one of `rows`, or when
/// another block has taken them already.
fn claim_block_rows<'a>(
    rows: &[std::sync::Mutex<Option<&'a mut [f32]>>],
    y: i64,
    top: i64,
    lines: usize,
) -> Result<&'a mut [f32], exr::error::Error> {
    let dy = y - top;
    let k = usize::try_from(dy / lines as i64)
        .ok()
        .filter(|_| dy >= 0 && dy % lines as i64 == 0);
    let slot = k.and_then(|k| rows.get(k)).ok_or_else(outside)?;
    slot.lock()
        .unwrap_or_else(|p| p.into_inner())
        .take()
        .ok_or_else(|| {
            exr::error::Error::Invalid(format!("two blocks claim the lines from {y}").into())
        })
}

/// The compressed `size` of the block of lines from `y` at byte `at`, checked: at most the
/// `expected` bytes of its raw lines (a ZIP block is never larger: the writer stores those
/// instead), and inside the file's `file_len` bytes.
fn checked_block_size(
    size: i32,
    expected: usize,
    y: i64,
    at: u64,
    file_len: u64,
) -> Result<usize, exr::error::Error> {
    let size = usize::try_from(size)
        .ok()
        .filter(|&s| s <= expected)
        .ok_or_else(|| {
            exr::error::Error::Invalid(
                format!("the block of lines from {y} declares an impossible size").into(),
            )
        })?;
    if (at + 8)
        .checked_add(size as u64)
        .is_none_or(|end| end > file_len)
    {
        return Err(truncated_zip_file());
    }
    Ok(size)
}

/// Fails, naming its first line, if any block of `lines` lines (the layer starting at line
/// `top`) was never filled.
fn check_no_missing_block(
    rows: &[std::sync::Mutex<Option<&mut [f32]>>],
    top: i64,
    lines: usize,
) -> Result<(), exr::error::Error> {
    if let Some(k) = rows
        .iter()
        .position(|r| r.lock().unwrap_or_else(|p| p.into_inner()).is_some())
    {
        return Err(exr::error::Error::Invalid(
            format!(
                "the block of lines from {} is missing (a truncated file?)",
                top + (k * lines) as i64
            )
            .into(),
        ));
    }
    Ok(())
}

/// [`pack_lines`] for float channels (`layout` all [`SampleType::F32`], `c` 3 or 4): each
/// texel's samples stored straight into their channels' planes, four texels a step (a
/// transpose of RGB(A) into R, G, B (and A) lanes), the rest one at a time.
fn pack_float_lines(
    rows: &[f32],
    w: usize,
    c: usize,
    layout: &[(usize, SampleType)],
    out: &mut [u8],
) {
    // Where each texel channel's plane starts within a line's bytes.
    let mut plane = [0usize; 4];
    for (pos, &(k, _)) in layout.iter().enumerate() {
        plane[k] = pos * 4 * w;
    }
    for (row, line) in rows
        .chunks_exact(w * c)
        .zip(out.chunks_exact_mut(c * 4 * w))
    {
        let mut x = 0;
        if line.len() == c * 4 * w && row.len() == w * c {
            let mut put = |k: usize, x: usize, v: F32x4| {
                v.store_le_bytes(&mut line[plane[k] + 4 * x..]);
            };
            while x + 4 <= w {
                let p = &row[x * c..];
                if c == 4 {
                    let [r, g, b, a] =
                        F32x4::transpose(std::array::from_fn(|k| F32x4::load(&p[4 * k..])));
                    put(3, x, a);
                    put(0, x, r);
                    put(1, x, g);
                    put(2, x, b);
                } else {
                    let [r, g, b] =
                        F32x4::deinterleave3(std::array::from_fn(|k| F32x4::load(&p[4 * k..])));
                    put(0, x, r);
                    put(1, x, g);
                    put(2, x, b);
                }
                x += 4;
            }
        }
        for x in x..w {
            for k in 0..c {
                let at = plane[k] + 4 * x;
                line[at..at + 4].copy_from_slice(&row[x * c + k].to_le_bytes());
            }
        }
    }
}

/// Whether every channel of a [`block_layout`] is 32-bit float.
fn all_float(layout: &[(usize, SampleType)]) -> bool {
    layout.iter().all(|&(_, st)| st == SampleType::F32)
}

/// [`scatter`] for a ZIP block of float lines (`layout` all [`SampleType::F32`], 3 or 4
/// channels) still split into even- and odd-offset bytes ([`crate::exr_zip::Lines`]):
/// each float is put together from the two halves as it is stored, so the raw bytes are
/// never written out. Four texels a step: each channel's four floats from one byte
/// interleave, then transposed into RGB(A) order.
fn scatter_split_f32(
    evens: &[u8],
    odds: &[u8],
    rows: &mut [f32],
    w: usize,
    bh: usize,
    layout: &[(usize, SampleType)],
) -> u64 {
    let n = layout.len();
    // NaN, infinite and negative colour values, counted as they go by (see
    // `mirrorball_core::count_invalid`).
    let mut invalid = 0u64;
    // Where each texel channel's plane starts within a line, in the halves (2w bytes a plane).
    let mut plane = [0usize; 4];
    for (pos, &(c, _)) in layout.iter().enumerate() {
        plane[c] = pos * 2 * w;
    }
    let half_line = n * 2 * w;
    // Float x of the plane at `p` (an offset into the halves) of a line.
    let float_at = |p: usize, x: usize| {
        let k = p + 2 * x;
        f32::from_le_bytes([evens[k], odds[k], evens[k + 1], odds[k + 1]])
    };
    for (y, row) in rows.chunks_exact_mut(w * n).take(bh).enumerate() {
        let base = y * half_line;
        let p = plane.map(|o| base + o);
        let mut x = 0;
        if evens.len() >= base + half_line && odds.len() >= base + half_line {
            let four = |c: usize, x: usize| {
                let at = p[c] + 2 * x;
                let e: &[u8; 8] = evens[at..at + 8].try_into().unwrap();
                let o: &[u8; 8] = odds[at..at + 8].try_into().unwrap();
                F32x4::from_split_bytes(e, o)
            };
            let (zero, inf) = (F32x4::splat(0.0), F32x4::splat(f32::INFINITY));
            // Lanes of `v` that are NaN, infinite or negative (`v ≥ 0` fails for NaN).
            let bad = |v: F32x4| u64::from(((v.ge(zero) & v.lt(inf)).bitmask() ^ 0xF).count_ones());
            while x + 4 <= w {
                let (r, g, b) = (four(0, x), four(1, x), four(2, x));
                invalid += bad(r) + bad(g) + bad(b);
                let dst = &mut row[x * n..];
                if n == 4 {
                    let t = F32x4::transpose([r, g, b, four(3, x)]);
                    for (k, v) in t.into_iter().enumerate() {
                        v.store(&mut dst[4 * k..]);
                    }
                } else {
                    for (k, v) in F32x4::interleave3([r, g, b]).into_iter().enumerate() {
                        v.store(&mut dst[4 * k..]);
                    }
                }
                x += 4;
            }
        }
        for x in x..w {
            for c in 0..n {
                let v = float_at(p[c], x);
                row[x * n + c] = v;
                invalid += u64::from(c < 3 && !(0.0..f32::INFINITY).contains(&v));
            }
        }
    }
    invalid
}

/// Stores one decoded texel (the crate has already converted a whole line of samples).
#[inline]
fn set_texel(texels: &mut Texels, p: Vec2<usize>, (r, g, b, a): (f32, f32, f32, f32)) {
    let c = texels.channels;
    let i = (p.y() * texels.width + p.x()) * c;
    if let Some(dst) = texels.data.get_mut(i..i + c) {
        if c == 4 {
            dst.copy_from_slice(&[r, g, b, a]);
        } else {
            dst.copy_from_slice(&[r, g, b]);
        }
    }
}

/// Whether a header is a flat layer with red, green and blue channels.
fn is_rgb_layer(header: &Header) -> bool {
    let has = |name: &str| header.channels.list.iter().any(|c| c.name.eq(name));
    !header.deep && has("R") && has("G") && has("B")
}

fn no_rgb_layer_problem(headers: &[Header]) -> String {
    let names: Vec<String> = headers
        .iter()
        .flat_map(|h| h.channels.list.iter().map(|c| c.name.to_string()))
        .collect();
    if headers.iter().all(|h| h.deep) {
        "holds only deep data, which mirrorball cannot use".to_string()
    } else {
        format!(
            "has no layer with R, G and B channels (channels found: {}); mirrorball reads RGB \
             or RGBA images",
            if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            }
        )
    }
}

/// The problem with a compression the linked `exr` crate does not decode, if it is one.
fn undecodable_compression(compression: Compression) -> Option<String> {
    match compression {
        Compression::HTJ2K32 | Compression::HTJ2K256 => {
            Some(undecodable_message(compression_name(compression)))
        }
        _ => None,
    }
}

fn undecodable_message(name: &str) -> String {
    format!(
        "uses {name} compression, which mirrorball cannot decode; re-save it with ZIP or PIZ \
         compression (for example `oiiotool in.exr --compression zip -o out.exr`, or export it \
         as OpenEXR with ZIP compression from Blender, Photoshop or GIMP)"
    )
}

/// The OpenEXR name of a compression method.
fn compression_name(compression: Compression) -> &'static str {
    match compression {
        Compression::Uncompressed => "no",
        Compression::RLE => "RLE",
        Compression::ZIP1 => "ZIPS",
        Compression::ZIP16 => "ZIP",
        Compression::PIZ => "PIZ",
        Compression::PXR24 => "PXR24",
        Compression::B44 => "B44",
        Compression::B44A => "B44A",
        Compression::DWAA(_) => "DWAA",
        Compression::DWAB(_) => "DWAB",
        Compression::HTJ2K32 => "HTJ2K32",
        Compression::HTJ2K256 => "HTJ2K256",
    }
}

fn compression_description(compression: Compression) -> String {
    match compression {
        Compression::Uncompressed => "uncompressed".to_string(),
        Compression::B44 | Compression::B44A | Compression::DWAA(_) | Compression::DWAB(_) => {
            format!("{} compression (lossy)", compression_name(compression))
        }
        other => format!("{} compression", compression_name(other)),
    }
}

fn sample_type_name(t: SampleType) -> &'static str {
    match t {
        SampleType::F16 => "half",
        SampleType::F32 => "float",
        SampleType::U32 => "uint",
    }
}

/// "half", or "mixed half/float" when the channels differ.
fn sample_type_names(types: &[SampleType]) -> String {
    let mut names: Vec<&str> = Vec::new();
    for &t in types {
        let name = sample_type_name(t);
        if !names.contains(&name) {
            names.push(name);
        }
    }
    if names.len() == 1 {
        names[0].to_string()
    } else {
        format!("mixed {}", names.join("/"))
    }
}

/// Refuses a layer (of a size within the limits) whose samples the file is too short to
/// hold, by the most its compression expands a byte (see [`crate::bounds`]): 1 stored raw,
/// 64 for RLE (a count and a byte for a run of up to 128), 1032 for deflate (ZIP, ZIPS,
/// PXR24) and taken for PIZ too (a Huffman run code of at least 9 bits stands for at most
/// 255 16-bit values, under 460:1), 11 for B44(A)
/// (a flat 4×4 block of halves in 3 bytes). DWAA/DWAB have no useful bound (a constant
/// image's DC values deflate 1032:1 and stand for 64 samples each); their blocks are checked
/// one by one instead ([`check_dwa_blocks`]).
fn check_fits_file(input: &Input, header: &Header) -> Result<(), Error> {
    let ratio = match header.compression {
        Compression::Uncompressed => 1,
        Compression::RLE => 64,
        Compression::ZIP1 | Compression::ZIP16 | Compression::PXR24 | Compression::PIZ => 1032,
        Compression::B44 | Compression::B44A => 11,
        _ => return Ok(()),
    };
    let raw = header.total_pixel_bytes() as u64;
    let what = format!("{} compression", compression_name(header.compression));
    crate::bounds::check_raw_bytes_fit(input, raw, ratio, &what)
}

/// Checks the counters at the start of every DWAA/DWAB block against what the block's
/// pixels can need, before the `exr` crate decodes any block: the crate sizes its buffers
/// from these counters (the AC coefficient count, for one, becomes a `Vec::with_capacity`),
/// so a 3 KB file whose block claims 2⁴⁰ coefficients would make it ask for 2 TB and
/// abort. The blocks are read here through the crate's own chunk reader (each block's bytes
/// bounded by the largest block the header allows), found through the offset tables as
/// the decoder finds them, so the bytes checked are the bytes decoded; a DWA file is
/// therefore read twice. Blocks of other compressions are skipped.
fn check_dwa_blocks(input: &Input) -> Result<(), Error> {
    let path = input.path();
    // A reader of its own: the caller's is part way through the file.
    let reader = input.reader().map_err(|e| Error::io(path, e))?;
    let reader = exr::block::read(reader, false).map_err(|e| read_error(path, e))?;
    let headers: Vec<Header> = reader.headers().to_vec();
    let chunks = reader
        .filter_chunks(false, |_, _, _| true)
        .map_err(|e| read_error(path, e))?;
    for (k, chunk) in chunks.enumerate() {
        let chunk = chunk.map_err(|e| read_error(path, e))?;
        let Some(header) = headers.get(chunk.layer_index) else {
            continue; // the decoder reports a bad layer index
        };
        if !matches!(
            header.compression,
            Compression::DWAA(_) | Compression::DWAB(_)
        ) {
            continue;
        }
        use exr::block::chunk::CompressedBlock;
        let bytes = match &chunk.compressed_block {
            CompressedBlock::ScanLine(b) => &b.compressed_pixels_le,
            CompressedBlock::Tile(b) => &b.compressed_pixels_le,
            _ => continue, // deep data: refused by the decoder
        };
        // The block's place exactly as the decoder works it out; a bad one it reports.
        let Ok(size) = header
            .get_block_data_indices(&chunk.compressed_block)
            .and_then(|t| header.get_absolute_block_pixel_coordinates(t))
            .map(|b| b.size)
        else {
            continue;
        };
        if let Some(problem) = dwa_block_problem(bytes, header, size) {
            return Err(Error::input(
                path,
                format!("not a valid OpenEXR file (DWA block {k}: {problem})"),
            ));
        }
    }
    Ok(())
}

/// What is wrong with the counters of a DWA block of `size` pixels (`bytes` as stored),
/// if anything: each must fit the block. The bounds are loose (a valid writer stays well
/// inside them) but keep every buffer the decoder sizes from them within a small multiple
/// of the block's raw size. Blocks stored raw (exactly the raw size) or empty have no
/// counters; a block too short for them the decoder reports as truncated.
fn dwa_block_problem(bytes: &[u8], header: &Header, size: Vec2<usize>) -> Option<String> {
    /// The counters (`DataSizesSingle` in OpenEXR's `internal_dwa_compressor.h`): eleven
    /// little-endian u64 at the start of the block.
    const NAMES: [&str; 11] = [
        "version",
        "unknownUncompressedSize",
        "unknownCompressedSize",
        "acCompressedSize",
        "dcCompressedSize",
        "rleCompressedSize",
        "rleUncompressedSize",
        "rleRawSize",
        "totalAcUncompressedCount",
        "totalDcUncompressedCount",
        "acCompression",
    ];
    let raw = (size.area() as u64).saturating_mul(header.channels.bytes_per_pixel as u64);
    if bytes.is_empty() || bytes.len() as u64 == raw || bytes.len() < 8 * NAMES.len() {
        return None;
    }
    let counter =
        |i: usize| u64::from_le_bytes(bytes[8 * i..8 * i + 8].try_into().expect("8 bytes"));
    // Samples of the block with each channel padded to whole 8×8 DCT blocks: at most 64
    // coefficients (63 AC, 1 DC) each.
    let padded: u64 = header
        .channels
        .list
        .iter()
        .map(|c| {
            let w = size.x().div_ceil(c.sampling.x().max(1)).div_ceil(8) as u64 * 8;
            let h = size.y().div_ceil(c.sampling.y().max(1)).div_ceil(8) as u64 * 8;
            w * h
        })
        .sum();
    // (counter, the most it may be): raw bytes of the unknown and RLE channels; the RLE
    // stream (a count byte per run, so at most twice its bytes); a u16 per AC coefficient
    // (at most 64 per 8×8 block) and per DC value (one per 8×8 block).
    let bounds = [
        (1, raw),
        (6, raw.saturating_mul(2).saturating_add(64)),
        (7, raw),
        (8, padded),
        (9, padded / 64),
    ];
    for (i, most) in bounds {
        let v = counter(i);
        if v > most {
            return Some(format!(
                "{} is {v}, but a block of {}×{} pixels needs at most {most}",
                NAMES[i],
                size.x(),
                size.y()
            ));
        }
    }
    None
}

/// Turns an `exr` reading error into an input error naming the problem.
fn read_error(path: &Path, e: exr::error::Error) -> Error {
    use exr::error::Error as E;
    match e {
        // A seek to an offset the file's tables give that the system refuses (negative,
        // or past what a file can be): the file's fault, not the system's.
        E::Io(io) if io.kind() == std::io::ErrorKind::InvalidInput => Error::input(
            path,
            format!("not a valid OpenEXR file (it points outside itself: {io})"),
        ),
        E::Io(io) => Error::io(path, io),
        E::Invalid(msg) if msg.contains("missing bytes") => Error::input(
            path,
            "file is truncated (unexpected end of file)".to_string(),
        ),
        E::Invalid(msg) => Error::input(path, format!("not a valid OpenEXR file ({msg})")),
        E::NotSupported(msg) => {
            // Older `exr` versions report undecodable compressions only when they meet the
            // first block; name them the way the header check does.
            let lower = msg.to_ascii_lowercase();
            for name in ["dwaa", "dwab", "b44a", "b44", "htj2k", "ht j2k"] {
                if lower.contains(name) && lower.contains("compression") {
                    return Error::input(
                        path,
                        undecodable_message(&name.replace(' ', "").to_ascii_uppercase()),
                    );
                }
            }
            Error::input(
                path,
                format!("uses an OpenEXR feature mirrorball cannot read ({msg})"),
            )
        }
        E::Aborted => Error::input(path, "reading was cancelled".to_string()),
    }
}

/// Turns an `exr` writing error into an error naming the problem.
fn write_error(path: &Path, e: exr::error::Error) -> Error {
    use exr::error::Error as E;
    match e {
        E::Io(io) => Error::io(path, io),
        E::Invalid(msg) | E::NotSupported(msg) => {
            Error::request(path, format!("cannot write this image as OpenEXR ({msg})"))
        }
        E::Aborted => Error::request(path, "writing was cancelled".to_string()),
    }
}
