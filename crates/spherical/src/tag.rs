//! Adding, replacing or removing the spherical metadata of an MP4/MOV without re-encoding:
//! the movie box is rewritten; the media data is copied through untouched.
//!
//! Every video track's visual sample entries get `st3d` and `sv3d` (before `clap`, `pasp`
//! and `btrt`, as the RFC places them; old ones removed), and with V1 the track gets the
//! GSpherical `uuid` box. When the movie box changes size, every chunk offset (`stco`,
//! `co64`) and sample auxiliary information offset (`saio`) that points past it moves by
//! the difference; ones before it stay (a movie box at the end moves nothing). A 32-bit
//! table whose offsets would pass 4 GiB becomes a 64-bit one (`stco` → `co64`, `saio`
//! version 0 → 1), which grows the box again: the sizes are worked out until they agree.
//!
//! [`plan`] reads and checks everything and builds the new movie box before anything is
//! written; [`Tagging::write_to`] then streams the file into a writer (the caller's
//! temporary file, renamed over the original only when complete).

use crate::bmff::{be_u32, be_u64, full_box, name, FourCC, Node};
use crate::mapping::Mapping;
use crate::movie::{self, Movie};
use crate::v2::{self, Pose, StereoMode, Sv3d};
use crate::{v1, Error};
use mirrorball_core::Stereo;
use std::fs::File;
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::Path;

/// What to do to a file's spherical metadata.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Change {
    /// Write this metadata (replacing any).
    Set {
        /// The projection.
        mapping: Mapping,
        /// How the picture holds its eyes.
        stereo: Stereo,
        /// Also write V1's XML (equirectangular only).
        v1: bool,
    },
    /// Remove `st3d`, `sv3d` and V1's `uuid`.
    Remove,
}

/// What a [`plan`] changes, for people.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    /// Video tracks changed.
    pub tracks: usize,
    /// The movie box's size before and after.
    pub moov: (u64, u64),
    /// Offset tables moved (`stco`, `co64`, `saio`), and how many became 64-bit.
    pub tables_moved: usize,
    /// Of those, the ones made 64-bit.
    pub promoted: usize,
    /// How far the data after the movie box moves.
    pub shift: i64,
    /// The new movie box is the old one byte for byte: nothing to write.
    pub unchanged: bool,
}

/// A file and its new movie box, ready to be written.
#[derive(Debug)]
pub struct Tagging {
    file: File,
    movie: Movie,
    moov: Vec<u8>,
    /// What changes.
    pub summary: Summary,
}

/// Reads `path`, checks that `change` can be made, and builds the new movie box. Nothing is
/// written.
pub fn plan(path: &Path, change: &Change) -> Result<Tagging, Error> {
    let (file, movie) = Movie::open(path)?;
    let (tagged, tracks) = retag(&movie.moov, change).map_err(|e| e.at(path))?;
    let at = Span {
        start: movie.moov_at.start,
        end: movie.moov_at.end(),
        len: movie.len,
    };
    let (moov, tables_moved, promoted, shift) = relocate(&tagged, &at).map_err(|e| e.at(path))?;
    let moov = moov.to_bytes();
    let summary = Summary {
        tracks,
        moov: (movie.moov_at.size, moov.len() as u64),
        tables_moved,
        promoted,
        shift,
        unchanged: moov == movie.moov_bytes,
    };
    Ok(Tagging {
        file,
        movie,
        moov,
        summary,
    })
}

impl Tagging {
    /// The new movie box.
    pub fn moov(&self) -> &[u8] {
        &self.moov
    }

    /// Bytes of the new file.
    pub fn new_len(&self) -> u64 {
        self.movie.len - self.movie.moov_at.size + self.moov.len() as u64
    }

    /// Writes the new file into `out`: the bytes before the movie box, the new movie box,
    /// the bytes after it, streamed (the media data is never held in memory). Fails if the
    /// file is not the length it was when planned.
    pub fn write_to<W: Write>(&self, out: &mut W) -> std::io::Result<()> {
        let changed = || {
            std::io::Error::other(format!(
                "{} changed while being tagged",
                self.movie.path.display()
            ))
        };
        if self.file.metadata()?.len() != self.movie.len {
            return Err(changed());
        }
        let (start, end) = (self.movie.moov_at.start, self.movie.moov_at.end());
        let mut f = &self.file;
        copy_range(&mut f, out, 0, start)?;
        out.write_all(&self.moov)?;
        copy_range(&mut f, out, end, self.movie.len - end)?;
        if self.file.metadata()?.len() != self.movie.len {
            return Err(changed());
        }
        Ok(())
    }
}

/// Copies `n` bytes from `at` of `from` into `out`; a file that ends sooner is an error.
fn copy_range(from: &mut &File, out: &mut impl Write, at: u64, n: u64) -> std::io::Result<()> {
    from.seek(SeekFrom::Start(at))?;
    let copied = std::io::copy(&mut from.take(n), out)?;
    if copied != n {
        return Err(std::io::ErrorKind::UnexpectedEof.into());
    }
    Ok(())
}

/// Sample entry boxes the RFC puts after `st3d` and `sv3d`.
const AFTER_SPHERICAL: [&FourCC; 3] = [b"clap", b"pasp", b"btrt"];

/// The movie box with `change` made to every video track; the number of tracks changed.
fn retag(moov: &Node, change: &Change) -> Result<(Node, usize), Error> {
    let mut moov = moov.clone();
    let mut tracks = 0;
    let traks = moov.children_mut().expect("moov is a container");
    for trak in traks.iter_mut() {
        if !movie::is_video(trak) {
            continue;
        }
        tracks += 1;
        let extra = retag_entries(trak, change)?;
        let children = trak.children_mut().expect("trak is a container");
        children.retain(|c| !(&c.kind == b"uuid" && c.payload().is_some_and(v1::is_v1)));
        children.extend(extra);
    }
    Ok((moov, tracks))
}

/// Puts `st3d` and `sv3d` in each of the track's visual sample entries (after removing old
/// ones); returns the boxes the track itself gets (V1's `uuid`).
fn retag_entries(trak: &mut Node, change: &Change) -> Result<Vec<Node>, Error> {
    let mut extra = Vec::new();
    let entries = movie::stsd_mut(trak)
        .and_then(Node::children_mut)
        .ok_or_else(|| Error::malformed("a video track has no sample descriptions"))?;
    for entry in entries.iter_mut() {
        let size = movie::entry_size(entry);
        let Some(children) = entry.children_mut() else {
            continue;
        };
        children.retain(|c| &c.kind != b"st3d" && &c.kind != b"sv3d");
        let Change::Set {
            mapping,
            stereo,
            v1,
        } = *change
        else {
            continue;
        };
        let (w, h) = size.ok_or_else(|| Error::malformed("a video sample entry is cut short"))?;
        let (ew, eh) = stereo
            .eye_extent(w, h)
            .map_err(|e| Error::unfit(format!("the video is {w}×{h}: {e}")))?;
        // Every rule projection_data gives is the request's: the size cannot hold it.
        let data = mapping.projection_data(ew, eh).map_err(|rule| {
            let what = match stereo {
                Stereo::Mono => format!("the video is {w}×{h}"),
                s => format!("each eye of this {s} pair ({w}×{h}) is {ew}×{eh}"),
            };
            Error::unfit(format!("{what}, but {}", rule.problem()))
        })?;
        let at = children
            .iter()
            .position(|c| AFTER_SPHERICAL.contains(&&c.kind))
            .unwrap_or(children.len());
        let sv3d = v2::sv3d(&Sv3d {
            source: v2::SOURCE.into(),
            pose: Pose::default(),
            data,
        });
        children.splice(at..at, [v2::st3d(StereoMode::of(stereo)), sv3d]);
        if v1 && extra.is_empty() {
            let xml = v1::xml(&mapping, StereoMode::of(stereo), ew, eh)?;
            extra.push(v1::node(&xml));
        }
    }
    Ok(extra)
}

/// Where the movie box was in its file, and the file's length.
struct Span {
    start: u64,
    end: u64,
    len: u64,
}

/// `moov` (once at `at` in its file) with every offset past its end moved by the change
/// in its size: the new box, the tables moved, those made 64-bit, and the shift.
fn relocate(moov: &Node, at: &Span) -> Result<(Node, usize, usize, i64), Error> {
    let old = (at.end - at.start) as i64;
    let mut shift = moov.size() as i64 - old;
    for _ in 0..8 {
        let mut moved = moov.clone();
        let (tables, promoted) = shift_tables(&mut moved, at, shift)?;
        let now = moved.size() as i64 - old;
        if now == shift {
            return Ok((moved, tables, promoted, shift));
        }
        shift = now;
    }
    Err(Error::malformed(
        "the chunk offsets do not settle (more than 8 rounds of 64-bit promotion)",
    ))
}

/// Moves the offsets of every `stco`, `co64` and `saio` in `moov`'s tracks.
fn shift_tables(moov: &mut Node, at: &Span, shift: i64) -> Result<(usize, usize), Error> {
    let (mut tables, mut promoted) = (0, 0);
    let traks = moov.children_mut().expect("moov is a container");
    for trak in traks.iter_mut().filter(|t| &t.kind == b"trak") {
        let Some(stbl) = stbl_mut(trak) else { continue };
        for table in stbl.iter_mut() {
            let moved = match &table.kind {
                b"stco" | b"co64" => shift_chunk_offsets(table, at, shift)?,
                b"saio" => shift_aux_offsets(table, at, shift)?,
                _ => continue,
            };
            tables += usize::from(moved.0);
            promoted += usize::from(moved.1);
        }
    }
    Ok((tables, promoted))
}

fn stbl_mut(trak: &mut Node) -> Option<&mut Vec<Node>> {
    let mut node = trak;
    for k in [b"mdia", b"minf", b"stbl"] {
        node = node.children_mut()?.iter_mut().find(|c| &c.kind == k)?;
    }
    node.children_mut()
}

/// Where offset `o` goes: past the movie box it moves by `shift`; inside it, or past the
/// end of the file, is an error.
fn moved(o: u64, at: &Span, shift: i64) -> Result<u64, Error> {
    if o >= at.len {
        Err(Error::malformed(format!(
            "an offset ({o}) points past the end of the file ({} bytes): the file is truncated",
            at.len
        )))
    } else if o >= at.end {
        o.checked_add_signed(shift)
            .ok_or_else(|| Error::malformed("an offset overflows"))
    } else if o >= at.start {
        Err(Error::malformed(format!(
            "an offset ({o}) points inside the movie box ({}..{}); the file is corrupt",
            at.start, at.end
        )))
    } else {
        Ok(o)
    }
}

/// Offsets of `count` entries of `width` bytes from `at` of `p`.
fn read_offsets(p: &[u8], at: usize, count: usize, width: usize) -> Vec<u64> {
    (0..count)
        .map(|i| {
            let j = at + i * width;
            if width == 8 {
                be_u64(p, j).expect("checked")
            } else {
                u64::from(be_u32(p, j).expect("checked"))
            }
        })
        .collect()
}

fn write_offsets(out: &mut Vec<u8>, offsets: &[u64], width: usize) {
    for &o in offsets {
        if width == 8 {
            out.extend_from_slice(&o.to_be_bytes());
        } else {
            out.extend_from_slice(&(o as u32).to_be_bytes());
        }
    }
}

/// `old` offsets of `width` bytes, each [`moved`]: `None` when none moved, else the new
/// offsets and whether they need 64 bits (they had them, or one passed 4 GiB).
fn shifted(
    old: &[u64],
    width: usize,
    at: &Span,
    shift: i64,
) -> Result<Option<(Vec<u64>, bool)>, Error> {
    let new = old
        .iter()
        .map(|&o| moved(o, at, shift))
        .collect::<Result<Vec<_>, _>>()?;
    if new == old {
        return Ok(None);
    }
    let wide = width == 8 || new.iter().any(|&o| o > u64::from(u32::MAX));
    Ok(Some((new, wide)))
}

/// `stco`/`co64`: whether any offset moved, and whether it became `co64`.
fn shift_chunk_offsets(t: &mut Node, at: &Span, shift: i64) -> Result<(bool, bool), Error> {
    let p = t.payload().expect("a leaf");
    let (count, width) = movie::table(&t.kind, p)?;
    let Some((new, wide)) = shifted(&read_offsets(p, 8, count, width), width, at, shift)? else {
        return Ok((false, false));
    };
    let mut body = (count as u32).to_be_bytes().to_vec();
    write_offsets(&mut body, &new, if wide { 8 } else { 4 });
    let kind = if wide { *b"co64" } else { *b"stco" };
    let promoted = kind != t.kind;
    *t = Node::leaf(&kind, full_box(p[0], 0, &body));
    Ok((true, promoted))
}

/// `saio` (ISO/IEC 14496-12 §8.7.9): version 0 offsets are 32-bit, version 1 64-bit;
/// `flags & 1` puts an aux_info_type and its parameter before the count.
fn shift_aux_offsets(t: &mut Node, at: &Span, shift: i64) -> Result<(bool, bool), Error> {
    let p = t.payload().expect("a leaf");
    let short = || Error::malformed(format!("{} is cut short", name(&t.kind)));
    let (version, flags) = (
        *p.first().ok_or_else(short)?,
        be_u32(p, 0).ok_or_else(short)? & 0xFF_FFFF,
    );
    let head = if flags & 1 != 0 { 12 } else { 4 };
    let count = be_u32(p, head).ok_or_else(short)? as usize;
    let width = if version == 0 { 4 } else { 8 };
    if (p.len() - head - 4) / width < count {
        return Err(Error::malformed(format!(
            "'saio' declares {count} offsets but holds {} bytes",
            p.len() - head - 4
        )));
    }
    let old = read_offsets(p, head + 4, count, width);
    let Some((new, wide)) = shifted(&old, width, at, shift)? else {
        return Ok((false, false));
    };
    let mut body = p[4..head + 4].to_vec();
    write_offsets(&mut body, &new, if wide { 8 } else { 4 });
    let promoted = wide && width == 4;
    *t = Node::leaf(b"saio", full_box(u8::from(wide).max(version), flags, &body));
    Ok((true, promoted))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The movie box at `start..end` of a file of 2^40 bytes.
    fn span(start: u64, end: u64) -> Span {
        Span {
            start,
            end,
            len: 1 << 40,
        }
    }

    /// A movie box with one track whose `stbl` holds `table`.
    fn moov_with(table: Node) -> Node {
        let stbl = Node::tree(b"stbl", vec![], vec![table]);
        let minf = Node::tree(b"minf", vec![], vec![stbl]);
        let mdia = Node::tree(b"mdia", vec![], vec![minf]);
        let trak = Node::tree(b"trak", vec![], vec![mdia]);
        Node::tree(b"moov", vec![], vec![trak])
    }

    fn stco(offsets: &[u32]) -> Node {
        let mut b = (offsets.len() as u32).to_be_bytes().to_vec();
        for o in offsets {
            b.extend_from_slice(&o.to_be_bytes());
        }
        Node::leaf(b"stco", full_box(0, 0, &b))
    }

    fn table_of(moov: &Node) -> &Node {
        let stbl = &moov.children()[0].children()[0].children()[0].children()[0];
        &stbl.children()[0]
    }

    #[test]
    fn offsets_past_the_movie_box_move_and_ones_before_stay() {
        // The movie box at 100..300 grown by 40 bytes (its size as built: the table alone).
        let moov = moov_with(stco(&[50, 300, 5000]));
        let size = moov.size();
        let at = span(100, 100 + size - 40);
        let (moved, tables, promoted, shift) = relocate(&moov, &at).unwrap();
        assert_eq!((tables, promoted, shift), (1, 0, 40));
        let p = table_of(&moved).payload().unwrap();
        assert_eq!(read_offsets(p, 8, 3, 4), [50, 340, 5040]);
        // An offset inside the old movie box is a corrupt file.
        let bad = moov_with(stco(&[150]));
        let e = relocate(&bad, &span(100, 100 + bad.size() - 8)).unwrap_err();
        assert!(e.to_string().contains("inside"), "{e}");
        let e = relocate(&moov, &Span { len: 4000, ..at }).unwrap_err();
        assert!(e.to_string().contains("past the end"), "{e}");
    }

    #[test]
    fn an_offset_pushed_past_4_gib_makes_the_table_64_bit() {
        // Chunks just under 2^32, the movie box before them growing by 16 bytes: the table
        // becomes co64, which grows the box by 4 bytes an entry more.
        let near = u32::MAX - 10;
        let moov = moov_with(stco(&[1000, near]));
        let grown = 16;
        let (start, end) = (32, 32 + moov.size() - grown);
        let (moved, tables, promoted, shift) = relocate(&moov, &span(start, end)).unwrap();
        let t = table_of(&moved);
        assert_eq!(&t.kind, b"co64");
        assert_eq!((tables, promoted), (1, 1));
        assert_eq!(
            shift as u64,
            grown + 2 * 4,
            "the promotion's own growth is counted"
        );
        assert_eq!(moved.size() - (end - start), shift as u64);
        let offs = read_offsets(t.payload().unwrap(), 8, 2, 8);
        assert_eq!(offs, [1000 + shift as u64, u64::from(near) + shift as u64]);
        // Shrinking never promotes; a 64-bit table stays 64-bit.
        let (moved, ..) = relocate(&moved, &span(start, start + moved.size() + 8)).unwrap();
        assert_eq!(&table_of(&moved).kind, b"co64");
    }

    #[test]
    fn saio_offsets_move_and_widen() {
        let mut body = 7u32.to_be_bytes().to_vec(); // aux_info_type
        body.extend_from_slice(&0u32.to_be_bytes()); // its parameter
        body.extend_from_slice(&1u32.to_be_bytes()); // one offset
        body.extend_from_slice(&(u32::MAX - 2).to_be_bytes());
        let moov = moov_with(Node::leaf(b"saio", full_box(0, 1, &body)));
        let (moved, _, promoted, shift) = relocate(&moov, &span(0, moov.size() - 8)).unwrap();
        let p = table_of(&moved).payload().unwrap();
        assert_eq!((p[0], promoted, shift), (1, 1, 12));
        assert_eq!(&p[4..12], &body[..8]);
        assert_eq!(read_offsets(p, 16, 1, 8), [u64::from(u32::MAX - 2) + 12]);
    }
}
