//! An MP4 or MOV file's top-level boxes and its movie box (`moov`) in memory, and what its
//! video tracks say about their projection. The media data (`mdat`) is never read.

use crate::bmff::{be_u32, name, parse_header, Body, FourCC, Header, Node};
use crate::mapping::Mapping;
use crate::v1::{self, V1};
use crate::v2::{self, StereoMode, Sv3d};
use crate::Error;
use mirrorball_core::Stereo;
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

/// Largest movie box read (the sample tables of a long film are tens of megabytes).
pub const MAX_MOOV: u64 = 1 << 30;

/// Box types that may start an ISO base media or QuickTime file.
const FIRST_BOXES: [&FourCC; 10] = [
    b"ftyp", b"moov", b"mdat", b"free", b"skip", b"wide", b"pnot", b"uuid", b"styp", b"junk",
];

/// Bytes of a visual sample entry's fields before its boxes (ISO/IEC 14496-12 §12.1.3: the
/// sample entry's 8, then 70; QuickTime's video sample description has the same 78).
pub const VISUAL_FIELDS: usize = 78;

/// A movie file opened: its length, its top-level boxes and its movie box.
#[derive(Debug)]
pub struct Movie {
    /// The file.
    pub path: PathBuf,
    /// Its length when read.
    pub len: u64,
    /// The top-level boxes.
    pub top: Vec<Header>,
    /// Where the movie box is.
    pub moov_at: Header,
    /// The movie box as read.
    pub moov_bytes: Vec<u8>,
    /// The movie box: the containers down to each track's sample descriptions opened,
    /// each video track's visual sample entries opened too.
    pub moov: Node,
}

impl Movie {
    /// Reads the top-level boxes of `path` and its movie box, refusing anything that is not
    /// a complete, unfragmented MP4/MOV with a video track, before any output is made.
    pub fn open(path: &Path) -> Result<(File, Movie), Error> {
        let mut file = File::open(path).map_err(|e| Error::io(path, e))?;
        let len = file.metadata().map_err(|e| Error::io(path, e))?.len();
        let top = top_level(&mut file, path, len)?;
        check_top(&top).map_err(|e| e.at(path))?;
        let moov_at = *top
            .iter()
            .find(|h| &h.kind == b"moov")
            .expect("checked: one moov");
        if moov_at.size > MAX_MOOV {
            return Err(Error::input(
                path,
                format!(
                    "its movie box ('moov') is {} bytes; at most {MAX_MOOV} are read",
                    moov_at.size
                ),
            ));
        }
        let mut bytes = vec![0u8; moov_at.size as usize];
        file.seek(SeekFrom::Start(moov_at.start))
            .and_then(|_| file.read_exact(&mut bytes))
            .map_err(|e| Error::io(path, e))?;
        let mut moov = Node::parse(
            &bytes,
            &Header {
                start: 0,
                ..moov_at
            },
            0,
        )
        .map_err(|e| e.within("in its movie box").at(path))?;
        open_video_entries(&mut moov).map_err(|e| e.at(path))?;
        if video_tracks(&moov).next().is_none() {
            return Err(Error::input(path, "has no video track"));
        }
        let movie = Movie {
            path: path.to_path_buf(),
            len,
            top,
            moov_at,
            moov_bytes: bytes,
            moov,
        };
        Ok((file, movie))
    }
}

/// The top-level boxes of `file` (`path`, `len` bytes), each header checked against the
/// length.
fn top_level(file: &mut File, path: &Path, len: u64) -> Result<Vec<Header>, Error> {
    let mut out: Vec<Header> = Vec::new();
    let mut at = 0u64;
    while at < len {
        let mut head = [0u8; 16];
        let n = (len - at).min(16) as usize;
        file.seek(SeekFrom::Start(at))
            .and_then(|_| file.read_exact(&mut head[..n]))
            .map_err(|e| Error::io(path, e))?;
        if out.is_empty() && !looks_like_a_box(&head[..n]) {
            return Err(Error::input(path, not_a_movie(&head[..n])));
        }
        let h = parse_header(&head[..n], at, len - at).map_err(|e| e.at(path))?;
        at = h.end();
        out.push(h);
    }
    if out.is_empty() {
        return Err(Error::input(path, "is empty, not an MP4 or MOV file"));
    }
    Ok(out)
}

/// Whether `head` starts with a box of a type that begins MP4 and MOV files.
fn looks_like_a_box(head: &[u8]) -> bool {
    head.len() >= 8 && FIRST_BOXES.iter().any(|k| head[4..8] == k[..])
}

fn not_a_movie(head: &[u8]) -> String {
    let hex: Vec<String> = head.iter().take(8).map(|b| format!("{b:02x}")).collect();
    let what = if head.starts_with(b"\x89PNG") {
        " (a PNG image)"
    } else if head.starts_with(&[0xff, 0xd8]) {
        " (a JPEG image)"
    } else if head.starts_with(&[0x1a, 0x45, 0xdf, 0xa3]) {
        " (Matroska or WebM, which tag does not write)"
    } else {
        ""
    };
    format!(
        "not an MP4 or MOV file: it does not start with an ISO base media box (its first bytes are {}{what})",
        hex.join(" ")
    )
}

/// One movie box, no fragments.
fn check_top(top: &[Header]) -> Result<(), Error> {
    let count = |k: &FourCC| top.iter().filter(|h| &h.kind == k).count();
    match count(b"moov") {
        1 => {}
        0 => return Err(Error::malformed(
            "has no movie box ('moov'): not a complete MP4 or MOV file (an unfinished recording?)",
        )),
        n => {
            return Err(Error::malformed(format!(
                "has {n} movie boxes ('moov'); a file has one"
            )))
        }
    }
    if count(b"moof") > 0 {
        return Err(Error::malformed(
            "is a fragmented MP4 ('moof' boxes), which tag does not rewrite; remux it first \
             (ffmpeg -i IN -c copy OUT.mp4)",
        ));
    }
    Ok(())
}

/// The handler type of a track (`mdia`/`hdlr`: `vide`, `soun`, …).
fn handler(trak: &Node) -> Option<FourCC> {
    let hdlr = trak.child(b"mdia")?.child(b"hdlr")?.payload()?;
    hdlr.get(8..12)?.try_into().ok()
}

/// Whether a box is a video track (a `trak` with handler `vide`).
pub fn is_video(trak: &Node) -> bool {
    &trak.kind == b"trak" && handler(trak) == Some(*b"vide")
}

/// The video tracks.
pub fn video_tracks(moov: &Node) -> impl Iterator<Item = &Node> {
    moov.children().iter().filter(|t| is_video(t))
}

/// A track's sample description box, if it has one.
fn stsd(trak: &Node) -> Option<&Node> {
    trak.child(b"mdia")?
        .child(b"minf")?
        .child(b"stbl")?
        .child(b"stsd")
}

/// A track's sample description box, to change.
pub fn stsd_mut(trak: &mut Node) -> Option<&mut Node> {
    let path: [&FourCC; 4] = [b"mdia", b"minf", b"stbl", b"stsd"];
    let mut node = trak;
    for k in path {
        node = node.children_mut()?.iter_mut().find(|c| &c.kind == k)?;
    }
    Some(node)
}

/// Opens every video track's sample entries: 78 bytes of fields, then boxes.
fn open_video_entries(moov: &mut Node) -> Result<(), Error> {
    let Some(traks) = moov.children_mut() else {
        return Ok(());
    };
    for trak in traks.iter_mut() {
        if !is_video(trak) {
            continue;
        }
        let Some(entries) = stsd_mut(trak).and_then(Node::children_mut) else {
            continue;
        };
        for e in entries.iter_mut() {
            if let Body::Leaf(payload) = &e.body {
                *e = Node::open(&e.kind, payload, VISUAL_FIELDS, 0).map_err(|err| {
                    err.within(format_args!("its video sample entry {}", name(&e.kind)))
                })?;
            }
        }
    }
    Ok(())
}

/// What a video track says about its projection and pictures.
#[derive(Clone, Debug, PartialEq)]
pub struct VideoTrack {
    /// The sample entry's type (the codec: `avc1`, `hvc1`, `vp09`, …).
    pub codec: String,
    /// The picture's width and height, from the sample entry.
    pub size: (u32, u32),
    /// `st3d`, if there.
    pub stereo: Option<StereoMode>,
    /// `sv3d`, if there, or why it cannot be read.
    pub sv3d: Option<Result<Sv3d, Error>>,
    /// The V1 `uuid` box, if there, or why it cannot be read.
    pub v1: Option<Result<V1, Error>>,
}

/// How mirrorball reads a video: what the metadata says, resolved (V2 before V1).
#[derive(Clone, Debug, PartialEq)]
pub struct Reading {
    /// The mapping.
    pub mapping: Mapping,
    /// How the picture holds its eyes.
    pub stereo: Stereo,
    /// Which metadata said so: "V2" or "V1".
    pub from: &'static str,
}

/// A visual sample entry's width and height (its fields' bytes 24 to 28).
pub fn entry_size(entry: &Node) -> Option<(u32, u32)> {
    let Body::Tree { head, .. } = &entry.body else {
        return None;
    };
    let at = |i: usize| {
        Some(u32::from(u16::from_be_bytes([
            *head.get(i)?,
            *head.get(i + 1)?,
        ])))
    };
    Some((at(24)?, at(26)?))
}

impl VideoTrack {
    fn of(trak: &Node) -> Option<VideoTrack> {
        let entry = stsd(trak)?.children().first()?;
        let stereo = entry
            .child(b"st3d")
            .and_then(Node::payload)
            .and_then(|p| v2::parse_st3d(p).ok());
        let sv3d = entry
            .child(b"sv3d")
            .and_then(Node::payload)
            .map(v2::parse_sv3d);
        let v1 = trak
            .children()
            .iter()
            .filter(|c| &c.kind == b"uuid")
            .filter_map(Node::payload)
            .find(|p| v1::is_v1(p))
            .map(v1::parse);
        Some(VideoTrack {
            codec: String::from_utf8_lossy(&entry.kind).into_owned(),
            size: entry_size(entry)?,
            stereo,
            sv3d,
            v1,
        })
    }

    /// One eye's size in a picture holding `stereo`.
    fn eye(&self, stereo: Stereo) -> (u32, u32) {
        let (w, h) = self.size;
        stereo.eye_extent(w, h).unwrap_or((w, h))
    }

    /// The mapping and stereo arrangement the metadata states, V2 first (the RFC: V2 takes
    /// priority): `Ok(None)` when the track has none, an error saying what it has when
    /// mirrorball cannot read that.
    pub fn reading(&self) -> Result<Option<Reading>, Error> {
        if let Some(sv3d) = &self.sv3d {
            let sv3d = sv3d
                .as_ref()
                .map_err(|e| e.clone().within("its 'sv3d' box is unreadable"))?;
            let mode = self.stereo.unwrap_or(StereoMode::Mono);
            let stereo = mode.stereo().ok_or_else(|| {
                Error::malformed(format!("its stereo mode is {}", mode.describe()))
            })?;
            let (w, h) = self.eye(stereo);
            let mapping = Mapping::from_data(&sv3d.data, w, h)?;
            return Ok(Some(Reading {
                mapping,
                stereo,
                from: "V2",
            }));
        }
        let Some(v1) = &self.v1 else {
            return Ok(None);
        };
        let v1 = v1
            .as_ref()
            .map_err(|e| e.clone().within("its V1 XML is unreadable"))?;
        let stereo = v1.stereo().and_then(StereoMode::stereo).ok_or_else(|| {
            Error::malformed(format!("its V1 stereo mode is {:?}", v1.stereo_mode))
        })?;
        let mapping = v1.mapping().ok_or_else(|| {
            Error::malformed(format!(
                "its V1 XML says Spherical {}, ProjectionType '{}'",
                v1.spherical, v1.projection_type
            ))
        })?;
        Ok(Some(Reading {
            mapping,
            stereo,
            from: "V1",
        }))
    }
}

/// What the video tracks of `path` say, in track order.
pub fn read(path: &Path) -> Result<Vec<VideoTrack>, Error> {
    let (_, movie) = Movie::open(path)?;
    Ok(video_tracks(&movie.moov)
        .filter_map(VideoTrack::of)
        .collect())
}

/// The entries of a chunk offset or similar table: `(count, width)` from the payload of
/// `stco` (4), `co64` (8), checked against the bytes there.
pub fn table(kind: &FourCC, p: &[u8]) -> Result<(usize, usize), Error> {
    let width = if kind == b"co64" { 8 } else { 4 };
    let count = be_u32(p, 4)
        .ok_or_else(|| Error::malformed(format!("{} is cut short", name(kind))))?
        as usize;
    if (p.len() - 8) / width < count {
        return Err(Error::malformed(format!(
            "{} declares {count} entries but holds {} bytes",
            name(kind),
            p.len() - 8
        )));
    }
    Ok((count, width))
}
