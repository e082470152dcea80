//! # mirrorball-video
//!
//! 360° video files through the system's FFmpeg libraries (`ffmpeg-next`): `mirrorball
//! convert in.mp4 out.mp4 --to eac`.
//!
//! - The video stream is decoded, each frame converted in its own planar YUV, plane by
//!   plane at each plane's size ([`planes`]: one [`Remap`](mirrorball_core::Remap) for Y,
//!   one for U and V), and encoded (H.264 by `libx264` unless `--codec`), on three threads
//!   joined by bounded channels: decode, convert, encode and write.
//! - Timestamps are kept (each frame's, in the input stream's time base), so the frame
//!   rate and duration are the input's; audio and subtitle streams are copied packet for
//!   packet, untouched.
//! - The input's Spherical Video metadata (V2, else V1) gives the projection and the
//!   stereo arrangement unless `--from` and `--in-stereo` do; every MP4/MOV written gets
//!   V2 (and V1 for lat-long) through `mirrorball-spherical`, when it can state the output.
//! - The file is muxed into a scratch file beside the output and lands by rename only when
//!   complete ([`mirrorball_io::with_scratch`], [`mirrorball_io::atomic_write`]): a failure
//!   or Ctrl-C leaves no half file.

mod matroska;
pub mod planes;

extern crate ffmpeg_next as ffmpeg;

use ffmpeg::{codec, encoder, format, frame, media, Dictionary, Packet, Rational};
use mirrorball::convert::{ConvertPlan, ConvertRequest};
use mirrorball::spherical::{self, Change, Mapping};
use mirrorball::{Error, Hooks, ProjSpec};
use mirrorball_core::{Layout, ProjectionKind, WorldProjection};
use planes::{Converter, PlaneFormat, Planes, Reading, Target};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::sync::Arc;
use std::time::Instant;

/// File extensions read and written as video.
pub const EXTENSIONS: &[&str] = &["mp4", "m4v", "mov", "mkv", "webm"];

/// Whether `path` names a video file by its extension.
pub fn is_video(path: &str) -> bool {
    Path::new(path)
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
}

/// A video conversion: `convert`'s request and the encoder's settings.
#[derive(Clone, Debug, Default)]
pub struct VideoRequest {
    /// What to convert to, as for pictures.
    pub convert: ConvertRequest,
    /// The encoder, by FFmpeg's name (`-c:v`): `libx264` (the default; `libvpx-vp9` for
    /// WebM), `libx265`, `libvpx-vp9`, `libaom-av1`, …
    pub codec: Option<String>,
    /// Constant rate factor (`-crf`); `None`: the encoder's default.
    pub crf: Option<u32>,
    /// The encoder's preset (`-preset`), for encoders that have one.
    pub preset: Option<String>,
}

/// Frames in flight between two threads.
const IN_FLIGHT: usize = 2;

/// Frames' planes handed back by the stage that used them to the stage that fills them,
/// so that a long video allocates (and the kernel zeroes) no fresh pages a frame.
#[derive(Clone, Default)]
#[allow(clippy::vec_box)] // the boxes travel through the channels as they are
struct Pool(Arc<std::sync::Mutex<Vec<Box<Planes>>>>);

impl Pool {
    /// Planes to fill: one handed back, else new.
    fn take(&self) -> Box<Planes> {
        let mut held = self.0.lock().unwrap_or_else(|e| e.into_inner());
        held.pop().unwrap_or_default()
    }

    /// Planes done with, kept for the next frame (as many as can be in flight).
    fn give(&self, planes: Box<Planes>) {
        let mut held = self.0.lock().unwrap_or_else(|e| e.into_inner());
        if held.len() <= 2 * IN_FLIGHT + 2 {
            held.push(planes);
        }
    }
}

/// What the reader hands on: a decoded frame, or a packet of a stream copied as it is.
enum Item {
    Frame {
        pts: Option<i64>,
        duration: i64,
        planes: Box<Planes>,
    },
    Copied {
        packet: Packet,
        stream: usize,
        time_base: Rational,
    },
}

fn container(path: &str) -> &'static str {
    let ext = Path::new(path)
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "mov" => "mov",
        "mkv" => "matroska",
        "webm" => "webm",
        _ => "mp4",
    }
}

/// Whether the file is an ISO BMFF file that carries Spherical Video metadata (tagged
/// after muxing by `mirrorball-spherical`).
fn takes_metadata(path: &str) -> bool {
    matches!(container(path), "mp4" | "mov")
}

/// Whether the file is Matroska or WebM, whose 360° metadata FFmpeg muxes and demuxes as
/// the video stream's side data ([`matroska`]).
fn is_matroska(path: &str) -> bool {
    matches!(container(path), "matroska" | "webm")
}

fn ff_input(input: &str, what: &str, e: ffmpeg::Error) -> Error {
    Error::input(format!("{input}: {what}: {e}"))
}

/// Converts the video `r.convert.input` into `r.convert.output`.
pub fn run(r: &VideoRequest, hooks: &dyn Hooks) -> Result<(), Error> {
    let c = &r.convert;
    let (input, output) = (c.input.as_str(), c.output.as_str());
    check_request(c)?;
    ffmpeg::init().map_err(|e| Error::system(format!("FFmpeg: {e}")))?;
    ffmpeg::log::set_level(ffmpeg::log::Level::Error);
    let ictx =
        format::input(&input).map_err(|e| ff_input(input, "cannot be read as a video", e))?;
    let vstream = ictx
        .streams()
        .best(media::Type::Video)
        .ok_or_else(|| Error::input(format!("{input}: has no video stream")))?;
    let vindex = vstream.index();
    let in_tb = vstream.time_base();
    let rate = vstream.avg_frame_rate();
    let decoder = codec::context::Context::from_parameters(vstream.parameters())
        .and_then(|d| d.decoder().video())
        .map_err(|e| ff_input(input, "its video cannot be decoded", e))?;
    let pix = decoder.format();
    let pix_name = pix.descriptor().map(|d| d.name()).unwrap_or("none");
    let fmt = PlaneFormat::named(pix_name).ok_or_else(|| {
        Error::input(format!(
            "{input}: its frames are {pix_name}; mirrorball converts planar YUV ({})",
            planes::FORMATS
                .iter()
                .map(|f| f.name)
                .collect::<Vec<_>>()
                .join(", ")
        ))
    })?;
    let extent = (decoder.width(), decoder.height());
    let total = match vstream.frames() {
        n if n > 0 => n as u64,
        _ => {
            let secs = ictx.duration() as f64 / f64::from(ffmpeg::ffi::AV_TIME_BASE);
            (secs * f64::from(rate)).max(0.0).round() as u64
        }
    };

    // What the file's metadata says, unless the flags say it.
    let mut req = c.clone();
    said_by_file(&mut req, &vstream, extent, hooks);
    // The picture's plan, checked as for a frame written as PNG (what its layout, size and
    // stereo arrangement may be).
    let mut as_picture = req.clone();
    as_picture.output = Path::new(output)
        .with_extension("png")
        .to_string_lossy()
        .into_owned();
    let plan = ConvertPlan::unwritten(&as_picture)?;
    let dst = plan.projection()?;
    let layout = plan.save.layout.unwrap_or(match dst.kind() {
        // The cube as YouTube and v360 lay it (c3x2), which Spherical Video V2 states.
        ProjectionKind::Cube => Layout::Cells(Mapping::CUBE_CELLS),
        k => Layout::default_for(k),
    });
    let in_stereo = req.in_stereo.unwrap_or_default();
    let reading = Reading {
        input: input.to_string(),
        from: req.input_plan.from.clone(),
        layout: req.input_plan.layout,
        stereo: (in_stereo, in_stereo.eyes_read(plan.stereo)),
    };
    let target = Target {
        dst,
        size: plan.size,
        layout,
        stereo: plan.stereo,
        resample: plan.resample.clone(),
    };
    let converter = Converter::new(fmt, extent, reading, &target)?;
    hooks.note(&format!("{input}: {}", converter.said));
    let (w, h) = converter.out_extent;
    let (tagged, muxed) = stating(output, (&dst, layout), ((w, h), plan.stereo), hooks);

    let out_path = PathBuf::from(output);
    let started = Instant::now();
    let mut source = Some((ictx, decoder));
    let frames = mirrorball_io::with_scratch(&out_path, "mux", |scratch| {
        let mut result = Err(Error::system("the conversion did not run"));
        hooks.progress("video", total, &mut |counter| {
            result = transcode(
                r,
                (source.take(), scratch),
                (&converter, muxed),
                (vindex, in_tb, rate, pix),
                counter,
            );
        });
        let frames = result?;
        land(scratch, &out_path, tagged, plan.stereo)?;
        Ok::<_, Error>(frames)
    })?;
    let secs = started.elapsed().as_secs_f64();
    hooks.note(&format!(
        "wrote {output}: {frames} frames, {w}x{h} {}, {}{} in {secs:.1} s ({:.1} frames/s)",
        fmt.name,
        r.codec.as_deref().unwrap_or(default_codec(output)),
        match (tagged, muxed) {
            (Some(m), _) => format!(", Spherical Video V2 {m:?}, {}", plan.stereo),
            (_, Some((m, stereo, _))) => format!(", Matroska Projection {m:?}, {stereo}"),
            _ => String::new(),
        },
        frames as f64 / secs.max(1e-9)
    ));
    Ok(())
}

/// Refuses, before any work, a request a video cannot take: its files (the input readable,
/// the output writable and not the input), an output that is no video, picture-only flags.
fn check_request(c: &ConvertRequest) -> Result<(), Error> {
    let (input, output) = (c.input.as_str(), c.output.as_str());
    let mut files = mirrorball::guard::Files::new();
    files
        .input_arg("the input", input)
        .output("the output", output);
    files.check()?;
    if !is_video(output) {
        return Err(Error::request(format!(
            "{output}: a video's output is a video file ({})",
            EXTENSIONS.join(", ")
        )));
    }
    if c.exposure != 0.0 || c.mips || c.compression.is_some() || c.precision.is_some() {
        return Err(Error::request(
            "--exposure, --mips, --compression and --precision are for pictures: a video's \
             frames are converted in their own codes",
        ));
    }
    Ok(())
}

/// `req` with what the input's 360° metadata says where the request does not say it
/// (`--from`, `--in-layout`, `--in-stereo`): MP4/MOV's Spherical Video boxes, Matroska's
/// `Projection` (as the demuxer gives `vstream`'s side data, for an `extent` picture).
fn said_by_file(
    req: &mut ConvertRequest,
    vstream: &format::stream::Stream,
    extent: (u32, u32),
    hooks: &dyn Hooks,
) {
    if req.input_plan.from.is_some() && req.in_stereo.is_some() {
        return;
    }
    let input = req.input.clone();
    let said = if takes_metadata(&input) {
        spherical::read(Path::new(&input)).ok().and_then(|tracks| {
            match tracks.first().map(|t| t.reading()) {
                Some(Ok(Some(r))) => {
                    Some((r.mapping, r.stereo, format!("Spherical Video {}", r.from)))
                }
                _ => None,
            }
        })
    } else {
        match matroska::read(vstream, extent) {
            Some(Ok((mapping, stereo))) => Some((mapping, stereo, "its Projection element".into())),
            Some(Err(e)) => {
                hooks.note(&format!("{input}: {}; give --from", e.message));
                None
            }
            None => None,
        }
    };
    if let Some((mapping, stereo, by)) = said {
        if req.input_plan.from.is_none() {
            let p = mapping.projection();
            req.input_plan.from = ProjSpec::parse(&p.to_string()).ok();
            req.input_plan.layout = req.input_plan.layout.or(mapping.layout());
        }
        req.in_stereo = req.in_stereo.or(Some(stereo));
        hooks.note(&format!(
            "{input}: {by} says {}, {stereo}",
            mapping.projection()
        ));
    }
}

/// How the output states its projection: an MP4/MOV tagged once muxed (the mapping), a
/// Matroska/WebM file as it is muxed ([`Muxed`]); neither where the container cannot state
/// `dst` in `layout` (said through `hooks`). `out` is the whole picture, `stereo` its
/// arrangement.
fn stating(
    output: &str,
    (dst, layout): (&mirrorball_core::Projection, Layout),
    (out, stereo): ((u32, u32), mirrorball_core::Stereo),
    hooks: &dyn Hooks,
) -> (Option<Mapping>, Option<Muxed>) {
    let states = takes_metadata(output) || is_matroska(output);
    let mapping = states
        .then(|| Mapping::of(dst, (dst.layer_count() > 1).then_some(layout)))
        .flatten()
        .filter(|m| !is_matroska(output) || matroska::states(m));
    if states && mapping.is_none() {
        hooks.note(&format!(
            "{output}: {} cannot state {dst}: written without it",
            if is_matroska(output) {
                "Matroska's Projection element, as FFmpeg writes it,"
            } else {
                "Spherical Video metadata"
            }
        ));
    }
    let (w, h) = out;
    let eye = match stereo {
        mirrorball_core::Stereo::Mono => (w, h),
        mirrorball_core::Stereo::SideBySide => (w / 2, h),
        mirrorball_core::Stereo::TopBottom => (w, h / 2),
    };
    let muxed = mapping
        .filter(|_| is_matroska(output))
        .map(|m| (m, stereo, eye));
    (mapping.filter(|_| takes_metadata(output)), muxed)
}

/// Lands the muxed `scratch` file at `out_path`, complete, through `tagged`'s Spherical
/// Video metadata (V2, and V1 for lat-long) where there is one.
fn land(
    scratch: &Path,
    out_path: &Path,
    tagged: Option<Mapping>,
    stereo: mirrorball_core::Stereo,
) -> Result<(), Error> {
    let io = |e| mirrorball_io::Error::io(out_path, e);
    match tagged {
        Some(mapping) => {
            let change = Change::Set {
                mapping,
                stereo,
                v1: matches!(mapping, Mapping::Equirect { .. }),
            };
            let tagging = spherical::tag::plan(scratch, &change)?;
            mirrorball_io::atomic_write(out_path, |w| tagging.write_to(w).map_err(io))?;
        }
        None => mirrorball_io::atomic_write(out_path, |w| {
            let mut f = std::fs::File::open(scratch).map_err(io)?;
            std::io::copy(&mut f, w).map(|_| ()).map_err(io)
        })?,
    }
    Ok(())
}

/// The encoder a container gets unless `--codec` says.
fn default_codec(output: &str) -> &'static str {
    if container(output) == "webm" {
        "libvpx-vp9"
    } else {
        "libx264"
    }
}

type Source = (format::context::Input, ffmpeg::decoder::Video);

/// What a Matroska output states as it is muxed: the mapping, the stereo arrangement and
/// one eye's size ([`matroska::state`]).
type Muxed = (Mapping, mirrorball_core::Stereo, (u32, u32));

/// Decodes, converts, encodes and muxes into `scratch` on three threads; returns the
/// frames written.
fn transcode(
    r: &VideoRequest,
    (source, scratch): (Option<Source>, &Path),
    (conv, muxed): (&Converter, Option<Muxed>),
    (vindex, in_tb, rate, pix): (usize, Rational, Rational, format::Pixel),
    counter: Arc<AtomicU64>,
) -> Result<u64, Error> {
    let (mut ictx, decoder) = source.ok_or_else(|| Error::system("the input was read already"))?;
    let (input, output) = (r.convert.input.as_str(), r.convert.output.as_str());
    let mut octx = format::output_as(&scratch, container(output))
        .map_err(|e| Error::system(format!("{output}: cannot be written: {e}")))?;
    let name = r.codec.as_deref().unwrap_or(default_codec(output));
    let (codec, enc) = open_encoder(r, name, conv, (&decoder, pix, in_tb, rate), &octx)?;
    let fmt = conv.format();
    let mut ost = octx
        .add_stream(codec)
        .map_err(|e| Error::system(format!("{output}: {e}")))?;
    ost.set_parameters(&enc);
    ost.set_time_base(in_tb);
    if let Some((mapping, stereo, eye)) = muxed {
        // SAFETY: the stream is the output context's, its header not yet written.
        unsafe { matroska::state(ost.as_mut_ptr(), &mapping, stereo, eye)? };
    }
    let vost = ost.index();
    let map = copied_streams(&ictx, &mut octx, vindex, output)?;
    octx.set_metadata(ictx.metadata().to_owned());
    octx.write_header().map_err(|e| {
        Error::request(format!(
            "{output}: the {} container cannot hold these streams ({name} video and the \
             input's others, copied): {e}",
            container(output)
        ))
    })?;
    let out_tbs: Vec<Rational> = octx.streams().map(|s| s.time_base()).collect();
    let (tx1, rx1) = sync_channel::<Item>(IN_FLIGHT);
    let (tx2, rx2) = sync_channel::<Item>(IN_FLIGHT);
    let writer = Writer {
        octx,
        enc,
        vost,
        in_tb,
        out_tbs,
        pix,
        frames: 0,
        last: None,
        step: (f64::from(rate.invert()) / f64::from(in_tb))
            .round()
            .max(1.0) as i64,
        durations: std::collections::HashMap::new(),
        output: output.to_string(),
        frame: None,
    };
    let (decoded, converted) = (Pool::default(), Pool::default());
    std::thread::scope(|s| {
        let pools = (decoded.clone(), converted.clone());
        let converting = s.spawn(move || convert_stage(conv, rx1, tx2, pools));
        let done = converted.clone();
        let writing = s.spawn(move || writer.run(rx2, &counter, &done));
        let read = read_stage(
            &mut ictx,
            decoder,
            (input, vindex, fmt),
            &map,
            tx1,
            &decoded,
        );
        let panicked = |_| Error::system("a video thread stopped unexpectedly");
        let converted = converting.join().map_err(panicked)?;
        let written = writing.join().map_err(panicked)?;
        read?;
        converted?;
        written
    })
}

/// The encoder `name` opened for `conv`'s frames (the decoder's pixel format `pix`, colour
/// space and range, the input's time base and rate; `--crf`, `--preset`), refused by name
/// where it cannot take them.
fn open_encoder(
    r: &VideoRequest,
    name: &str,
    conv: &Converter,
    (decoder, pix, in_tb, rate): (&ffmpeg::decoder::Video, format::Pixel, Rational, Rational),
    octx: &format::context::Output,
) -> Result<(ffmpeg::Codec, encoder::Video), Error> {
    let codec = encoder::find_by_name(name).ok_or_else(|| {
        Error::request(format!(
            "--codec: this FFmpeg has no encoder named '{name}' (`ffmpeg -encoders` lists them)"
        ))
    })?;
    let fmt = conv.format();
    if let Some(formats) = codec.video().ok().and_then(|v| v.formats()) {
        let formats: Vec<format::Pixel> = formats.collect();
        if !formats.contains(&pix) {
            return Err(Error::request(format!(
                "--codec {name} cannot encode {} frames, which mirrorball keeps as they came \
                 (its formats: {})",
                fmt.name,
                formats
                    .iter()
                    .filter_map(|f| f.descriptor().map(|d| d.name()))
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        }
    }
    let (w, h) = conv.out_extent;
    let mut enc = codec::context::Context::new_with_codec(codec)
        .encoder()
        .video()
        .map_err(|e| Error::system(format!("--codec {name}: {e}")))?;
    enc.set_width(w);
    enc.set_height(h);
    enc.set_format(pix);
    enc.set_time_base(in_tb);
    enc.set_frame_rate(Some(rate));
    enc.set_colorspace(decoder.color_space());
    enc.set_color_range(decoder.color_range());
    if octx.format().flags().contains(format::Flags::GLOBAL_HEADER) {
        enc.set_flags(codec::Flags::GLOBAL_HEADER);
    }
    let mut opts = Dictionary::new();
    if let Some(crf) = r.crf {
        opts.set("crf", &crf.to_string());
        if name.contains("vpx") {
            // libvpx takes a CRF only as the quality of an unbounded rate.
            opts.set("b", "0");
        }
    }
    if let Some(preset) = &r.preset {
        opts.set("preset", preset);
    }
    let enc = enc.open_as_with(codec, opts).map_err(|e| {
        Error::request(format!(
            "--codec {name} cannot encode {w}x{h} {} with these settings: {e}",
            fmt.name
        ))
    })?;
    Ok((codec, enc))
}

/// Adds to `octx` a stream for each of `ictx`'s audio and subtitle streams, copied as they
/// are (not the video stream `vindex`): the output stream of each input stream, if any.
fn copied_streams(
    ictx: &format::context::Input,
    octx: &mut format::context::Output,
    vindex: usize,
    output: &str,
) -> Result<Vec<Option<usize>>, Error> {
    let mut map: Vec<Option<usize>> = vec![None; ictx.nb_streams() as usize];
    for ist in ictx.streams() {
        let medium = ist.parameters().medium();
        if ist.index() == vindex || !matches!(medium, media::Type::Audio | media::Type::Subtitle) {
            continue;
        }
        let mut ost = octx
            .add_stream(encoder::find(codec::Id::None))
            .map_err(|e| Error::system(format!("{output}: {e}")))?;
        ost.set_parameters(ist.parameters());
        // SAFETY: the stream's parameters are its own, allocated by FFmpeg; the tag is
        // cleared so the muxer picks its own for the codec (as `ffmpeg -c copy` does).
        unsafe {
            (*ost.parameters().as_mut_ptr()).codec_tag = 0;
        }
        map[ist.index()] = Some(ost.index());
    }
    Ok(map)
}

/// Demuxes and decodes: every video frame's planes, and the copied streams' packets, in
/// the file's order.
fn read_stage(
    ictx: &mut format::context::Input,
    mut decoder: ffmpeg::decoder::Video,
    (input, vindex, fmt): (&str, usize, PlaneFormat),
    map: &[Option<usize>],
    tx: SyncSender<Item>,
    pool: &Pool,
) -> Result<(), Error> {
    let mut frame = frame::Video::empty();
    let mut n = 0u64;
    let first = (decoder.width(), decoder.height(), decoder.format());
    let mut drain = |decoder: &mut ffmpeg::decoder::Video, n: &mut u64| -> Result<bool, Error> {
        loop {
            match decoder.receive_frame(&mut frame) {
                Ok(()) => {}
                Err(ffmpeg::Error::Eof) => return Ok(true),
                Err(ffmpeg::Error::Other { errno }) if errno == ffmpeg::error::EAGAIN => {
                    return Ok(true)
                }
                Err(e) => {
                    return Err(ff_input(
                        input,
                        &format!("frame {} cannot be decoded", *n + 1),
                        e,
                    ))
                }
            }
            *n += 1;
            let now = (frame.width(), frame.height(), frame.format());
            if now != first {
                return Err(Error::input(format!(
                    "{input}: frame {n} is {}x{} {:?} where the first was {}x{} {:?}",
                    now.0, now.1, now.2, first.0, first.1, first.2
                )));
            }
            let mut planes = pool.take();
            copy_planes(&frame, fmt, &mut planes);
            // SAFETY: the frame is valid; `pkt_duration` is a plain field of FFmpeg 5's
            // AVFrame (the decoder's duration of the frame, in the stream's time base).
            #[allow(deprecated)]
            let duration = unsafe { (*frame.as_ptr()).pkt_duration };
            let item = Item::Frame {
                pts: frame.timestamp(),
                duration,
                planes,
            };
            if tx.send(item).is_err() {
                return Ok(false);
            }
        }
    };
    for (stream, packet) in ictx.packets() {
        let i = stream.index();
        if i == vindex {
            decoder
                .send_packet(&packet)
                .map_err(|e| ff_input(input, &format!("frame {} cannot be decoded", n + 1), e))?;
            if !drain(&mut decoder, &mut n)? {
                return Ok(());
            }
        } else if let Some(Some(o)) = map.get(i) {
            let item = Item::Copied {
                packet,
                stream: *o,
                time_base: stream.time_base(),
            };
            if tx.send(item).is_err() {
                return Ok(());
            }
        }
    }
    decoder
        .send_eof()
        .map_err(|e| ff_input(input, "the video's end cannot be decoded", e))?;
    drain(&mut decoder, &mut n)?;
    if n == 0 {
        return Err(Error::input(format!(
            "{input}: no video frame could be decoded"
        )));
    }
    Ok(())
}

/// The frame's three planes, rows packed, into `planes` (its memory reused).
fn copy_planes(frame: &frame::Video, fmt: PlaneFormat, planes: &mut Planes) {
    let extent = (frame.width(), frame.height());
    for k in 0..3 {
        let (pw, ph) = fmt.plane_extent(k, extent).unwrap_or(extent);
        let row = pw as usize * fmt.bytes();
        let stride = frame.stride(k);
        let data = frame.data(k);
        let out = &mut planes.data[k];
        out.clear();
        for y in 0..ph as usize {
            out.extend_from_slice(&data[y * stride..y * stride + row]);
        }
        planes.extent[k] = (pw, ph);
    }
}

/// Converts each frame; passes copied packets on.
fn convert_stage(
    conv: &Converter,
    rx: Receiver<Item>,
    tx: SyncSender<Item>,
    (decoded, converted): (Pool, Pool),
) -> Result<(), Error> {
    for item in rx {
        let item = match item {
            Item::Frame {
                pts,
                duration,
                planes,
            } => {
                let mut out = converted.take();
                conv.convert_into(&planes, &mut out)?;
                decoded.give(planes);
                Item::Frame {
                    pts,
                    duration,
                    planes: out,
                }
            }
            copied => copied,
        };
        if tx.send(item).is_err() {
            return Ok(());
        }
    }
    Ok(())
}

/// The encoder and the muxer.
struct Writer {
    octx: format::context::Output,
    enc: encoder::Video,
    vost: usize,
    in_tb: Rational,
    out_tbs: Vec<Rational>,
    pix: format::Pixel,
    frames: u64,
    last: Option<i64>,
    /// One frame's duration in the input's time base, for frames that give none.
    step: i64,
    /// Each frame's duration by its timestamp, given to its packet.
    durations: std::collections::HashMap<i64, i64>,
    output: String,
    /// The last frame sent to the encoder, filled again by the next.
    frame: Option<frame::Video>,
}

impl Writer {
    fn failed(&self, what: &str, e: ffmpeg::Error) -> Error {
        Error::system(format!("{}: {what}: {e}", self.output))
    }

    fn run(mut self, rx: Receiver<Item>, counter: &AtomicU64, done: &Pool) -> Result<u64, Error> {
        for item in rx {
            match item {
                Item::Frame {
                    pts,
                    duration,
                    planes,
                } => {
                    let (w, h) = planes.extent[0];
                    // The last frame's buffers where the encoder holds no reference to them
                    // (`av_frame_make_writable` copies them only where it does), so that
                    // frames after the first touch no fresh pages.
                    let mut f = match self.frame.take() {
                        Some(mut f) if (f.width(), f.height()) == (w, h) => {
                            // SAFETY: `f` is a valid frame with buffers of its own format
                            // and size, allocated by FFmpeg (`frame::Video::new`).
                            let made =
                                unsafe { ffmpeg::ffi::av_frame_make_writable(f.as_mut_ptr()) };
                            if made < 0 {
                                frame::Video::new(self.pix, w, h)
                            } else {
                                f
                            }
                        }
                        _ => frame::Video::new(self.pix, w, h),
                    };
                    for k in 0..3 {
                        let (_, ph) = planes.extent[k];
                        let row = planes.data[k].len() / ph.max(1) as usize;
                        let stride = f.stride(k);
                        let dst = f.data_mut(k);
                        for y in 0..ph as usize {
                            dst[y * stride..y * stride + row]
                                .copy_from_slice(&planes.data[k][y * row..(y + 1) * row]);
                        }
                    }
                    let pts = pts.or(self.last.map(|t| t + self.step)).unwrap_or(0);
                    self.last = Some(pts);
                    f.set_pts(Some(pts));
                    self.durations
                        .insert(pts, if duration > 0 { duration } else { self.step });
                    self.enc
                        .send_frame(&f)
                        .map_err(|e| self.failed("a frame cannot be encoded", e))?;
                    self.packets()?;
                    self.frames += 1;
                    counter.fetch_add(1, Ordering::Relaxed);
                    done.give(planes);
                    self.frame = Some(f);
                }
                Item::Copied {
                    mut packet,
                    stream,
                    time_base,
                } => {
                    packet.rescale_ts(time_base, self.out_tbs[stream]);
                    packet.set_position(-1);
                    packet.set_stream(stream);
                    packet
                        .write_interleaved(&mut self.octx)
                        .map_err(|e| self.failed("a copied packet cannot be written", e))?;
                }
            }
        }
        self.enc
            .send_eof()
            .map_err(|e| self.failed("the encoder cannot finish", e))?;
        self.packets()?;
        self.octx
            .write_trailer()
            .map_err(|e| self.failed("cannot be finished", e))?;
        Ok(self.frames)
    }

    fn packets(&mut self) -> Result<(), Error> {
        let mut p = Packet::empty();
        while self.enc.receive_packet(&mut p).is_ok() {
            let d = p.pts().and_then(|t| self.durations.remove(&t));
            if p.duration() == 0 {
                if let Some(d) = d {
                    p.set_duration(d);
                }
            }
            p.set_stream(self.vost);
            p.rescale_ts(self.in_tb, self.out_tbs[self.vost]);
            p.write_interleaved(&mut self.octx)
                .map_err(|e| self.failed("a video packet cannot be written", e))?;
        }
        Ok(())
    }
}
