//! Files made here box by box (no ffmpeg needed): what is not an MP4, cut short or lying
//! about its sizes is refused with the file named; boxes of size 0 and 64-bit sizes are
//! read; a file past 4 GiB (sparse) gets its chunk offsets moved and made 64-bit.

use mirrorball_core::{Fault, Stereo};
use mirrorball_spherical::bmff::{full_box, headers_in, Node};
use mirrorball_spherical::movie::Movie;
use mirrorball_spherical::{plan, read, Change, Mapping};
use std::io::Write;
use std::path::Path;

/// A track of handler `handler` (`vide` or `soun`) whose chunk offsets are `offsets`, in a
/// `stco`, or a `co64` when `wide`.
fn trak(handler: &[u8; 4], offsets: &[u64], wide: bool) -> Node {
    let mut hdlr = vec![0u8; 8];
    hdlr.extend_from_slice(handler);
    hdlr.extend_from_slice(&[0; 13]);
    let hdlr = Node::leaf(b"hdlr", full_box(0, 0, &hdlr[4..]));
    let mut fields = vec![0u8; 78];
    fields[24..26].copy_from_slice(&64u16.to_be_bytes());
    fields[26..28].copy_from_slice(&32u16.to_be_bytes());
    let avcc = Node::leaf(b"avcC", vec![1, 2, 3]);
    let pasp = Node::leaf(b"pasp", vec![0, 0, 0, 1, 0, 0, 0, 1]);
    let entry = if handler == b"vide" {
        Node::tree(b"avc1", fields, vec![avcc, pasp])
    } else {
        Node::leaf(b"mp4a", vec![0; 28])
    };
    let stsd = Node::tree(b"stsd", full_box(0, 0, &1u32.to_be_bytes()), vec![entry]);
    let mut table = (offsets.len() as u32).to_be_bytes().to_vec();
    for &o in offsets {
        if wide {
            table.extend_from_slice(&o.to_be_bytes());
        } else {
            table.extend_from_slice(&(o as u32).to_be_bytes());
        }
    }
    let kind = if wide { b"co64" } else { b"stco" };
    let stco = Node::leaf(kind, full_box(0, 0, &table));
    let stbl = Node::tree(b"stbl", vec![], vec![stsd, stco]);
    let minf = Node::tree(b"minf", vec![], vec![stbl]);
    let mdia = Node::tree(b"mdia", vec![], vec![hdlr, minf]);
    Node::tree(b"trak", vec![], vec![mdia])
}

fn ftyp() -> Vec<u8> {
    Node::leaf(b"ftyp", b"isom\0\0\x02\0isomiso2".to_vec()).to_bytes()
}

/// A small complete file: `ftyp`, then `moov` and `mdat` in either order; the chunk
/// offsets point at the media data's first bytes.
fn small(moov_first: bool) -> Vec<u8> {
    let media = Node::leaf(b"mdat", (0..200u8).collect()).to_bytes();
    let f = ftyp();
    let moov_of = |at: u64| {
        let traks = vec![
            trak(b"vide", &[at], false),
            trak(b"soun", &[at + 100], false),
        ];
        Node::tree(b"moov", vec![], traks).to_bytes()
    };
    // The movie box's size does not depend on the offsets' values.
    let before = if moov_first { moov_of(0).len() } else { 0 };
    let moov = moov_of((f.len() + before + 8) as u64);
    let mut out = f;
    if moov_first {
        out.extend_from_slice(&moov);
        out.extend_from_slice(&media);
    } else {
        out.extend_from_slice(&media);
        out.extend_from_slice(&moov);
    }
    out
}

fn equirect() -> Change {
    Change::Set {
        mapping: Mapping::FULL,
        stereo: Stereo::Mono,
        v1: false,
    }
}

/// The chunk offsets each track points at, as bytes of the file: what must not change.
fn chunks(bytes: &[u8], path: &Path) -> Vec<Vec<u8>> {
    std::fs::write(path, bytes).unwrap();
    let (_, m) = Movie::open(path).unwrap();
    let mut out = Vec::new();
    for t in m.moov.children() {
        let mut n = t;
        for k in [b"mdia", b"minf", b"stbl"] {
            n = n.child(k).unwrap();
        }
        let table = n.child(b"stco").or(n.child(b"co64")).unwrap();
        let p = table.payload().unwrap();
        let wide = &table.kind == b"co64";
        let o = if wide {
            u64::from_be_bytes(p[8..16].try_into().unwrap())
        } else {
            u64::from(u32::from_be_bytes(p[8..12].try_into().unwrap()))
        } as usize;
        out.push(bytes[o..o + 20].to_vec());
    }
    out
}

#[test]
fn the_data_each_track_points_at_is_the_same_after_tagging() {
    let dir = tempfile::tempdir().unwrap();
    for moov_first in [false, true] {
        let src = dir.path().join("src.mp4");
        let bytes = small(moov_first);
        let before = chunks(&bytes, &src);
        let out = dir.path().join("out.mp4");
        let s = crate::tag_into(&src, &out, &equirect());
        assert_eq!(s.tables_moved, if moov_first { 2 } else { 0 });
        let after = chunks(&std::fs::read(&out).unwrap(), &dir.path().join("x.mp4"));
        assert_eq!(after, before, "moov first: {moov_first}");
    }
}

/// `plan`'s error for `bytes` as a file `name`, which must be the input's fault, name the
/// file and leave it as it was.
fn refused(dir: &Path, name: &str, bytes: &[u8]) -> String {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    let e = plan(&p, &equirect()).expect_err(name);
    assert_eq!(e.fault(), Fault::Input, "{name}: {e}");
    let msg = e.to_string();
    assert!(msg.starts_with(p.to_str().unwrap()), "{msg}");
    assert_eq!(std::fs::read(&p).unwrap(), bytes, "{name} untouched");
    msg
}

#[test]
fn what_is_not_an_mp4_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let png = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR\0\0\0\x01\0\0\0\x01\x08\x02\0\0\0";
    assert!(refused(d, "a.png.mp4", png).contains("a PNG image"));
    assert!(refused(d, "b.mp4", b"\xff\xd8\xff\xe0 jpeg").contains("not an MP4"));
    assert!(refused(d, "c.mp4", b"\x1a\x45\xdf\xa3webm....").contains("Matroska"));
    assert!(refused(d, "d.mp4", b"").contains("empty"));
    assert!(refused(d, "e.mp4", b"hello, world, not a movie").contains("not an MP4"));
    let missing = plan(&d.join("none.mp4"), &equirect()).unwrap_err();
    assert_eq!(missing.fault(), Fault::Input);
    assert!(missing.to_string().contains("no such file"));
}

#[test]
fn structure_problems_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let f = ftyp();
    // No movie box; two; a fragmented file; no video track.
    let mdat = Node::leaf(b"mdat", vec![0; 16]).to_bytes();
    assert!(refused(d, "a.mp4", &[f.clone(), mdat.clone()].concat()).contains("no movie box"));
    let moov = Node::tree(b"moov", vec![], vec![trak(b"vide", &[0], false)]).to_bytes();
    let two = [f.clone(), moov.clone(), moov.clone()].concat();
    assert!(refused(d, "b.mp4", &two).contains("2 movie boxes"));
    let moof = Node::leaf(b"moof", vec![]).to_bytes();
    let frag = [f.clone(), moov.clone(), moof].concat();
    assert!(refused(d, "c.mp4", &frag).contains("fragmented"));
    let audio = Node::tree(b"moov", vec![], vec![trak(b"soun", &[0], false)]).to_bytes();
    assert!(refused(d, "d.mp4", &[f.clone(), audio].concat()).contains("no video track"));
    // A table declaring more entries than it holds.
    let mut lying = small(true);
    let at = find(&lying, b"stco") + 8;
    lying[at..at + 4].copy_from_slice(&1000u32.to_be_bytes());
    let msg = refused(d, "e.mp4", &lying);
    assert!(msg.contains("declares 1000 entries"), "{msg}");
}

/// Where box type `kind` first appears in `bytes` (the offset of its type field).
fn find(bytes: &[u8], kind: &[u8; 4]) -> usize {
    bytes.windows(4).position(|w| w == kind).unwrap()
}

#[test]
fn cut_short_or_oversized_boxes_are_refused_and_nothing_panics() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for moov_first in [false, true] {
        let good = small(moov_first);
        // Cut anywhere: refused (or, cut inside the media data only, still a whole
        // movie box pointing past the end: refused too, as a truncated box).
        for cut in (1..good.len()).step_by(11) {
            let msg = refused(d, "cut.mp4", &good[..cut]);
            assert!(
                ["truncated", "not an MP4", "stray", "no movie box"]
                    .iter()
                    .any(|m| msg.contains(m)),
                "{cut}: {msg}"
            );
        }
        // Every size field inside the movie box set to 0, 1 (a 64-bit size that is not
        // there), 7 and u32::MAX: an error or a file that is still read; never a panic, and
        // a file that is read is written whole.
        let moov_at = find(&good, b"moov") - 4;
        let (hs, _) = headers_in(&good, 0).unwrap();
        let moov = hs.iter().find(|h| &h.kind == b"moov").unwrap();
        for at in (moov_at..moov.end() as usize - 3).step_by(4) {
            for v in [0u32, 1, u32::MAX] {
                let mut bad = good.clone();
                bad[at..at + 4].copy_from_slice(&v.to_be_bytes());
                let p = d.join("bad.mp4");
                std::fs::write(&p, &bad).unwrap();
                match plan(&p, &equirect()) {
                    Ok(t) => {
                        let mut out = Vec::new();
                        t.write_to(&mut out).unwrap();
                        assert_eq!(out.len() as u64, t.new_len());
                    }
                    Err(e) => assert!(e.to_string().starts_with(p.to_str().unwrap())),
                }
            }
        }
    }
}

#[test]
fn size_zero_and_64_bit_media_boxes_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let good = small(true);
    // The media data last: size 0 ("to the end of the file") means the same.
    let mdat = find(&good, b"mdat") - 4;
    let mut zero = good.clone();
    zero[mdat..mdat + 4].copy_from_slice(&0u32.to_be_bytes());
    let src = dir.path().join("zero.mp4");
    std::fs::write(&src, &zero).unwrap();
    let before = chunks(&zero, &src);
    let out = dir.path().join("zero-out.mp4");
    crate::tag_into(&src, &out, &equirect());
    let tagged = std::fs::read(&out).unwrap();
    assert_eq!(chunks(&tagged, &dir.path().join("x.mp4")), before);
    assert_eq!(
        read(&out).unwrap()[0].reading().unwrap().unwrap().from,
        "V2"
    );
    // A 64-bit size on a small movie box is read too.
    let moov_at = find(&good, b"moov") - 4;
    let moov_len = u32::from_be_bytes(good[moov_at..moov_at + 4].try_into().unwrap());
    let mut wide = good[..moov_at].to_vec();
    wide.extend_from_slice(&1u32.to_be_bytes());
    wide.extend_from_slice(b"moov");
    wide.extend_from_slice(&(u64::from(moov_len) + 8).to_be_bytes());
    wide.extend_from_slice(&good[moov_at + 8..]);
    let src = dir.path().join("wide.mp4");
    std::fs::write(&src, &wide).unwrap();
    let (_, m) = Movie::open(&src).unwrap();
    assert_eq!(
        (m.moov_at.header_len, m.moov_at.size),
        (16, u64::from(moov_len) + 8)
    );
}

/// A writer that counts what it is given and keeps the first `keep` bytes.
struct Head {
    kept: Vec<u8>,
    keep: usize,
    total: u64,
}

impl Write for Head {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let room = self.keep.saturating_sub(self.kept.len()).min(buf.len());
        self.kept.extend_from_slice(&buf[..room]);
        self.total += buf.len() as u64;
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// A sparse file (nothing but its first bytes on disk): the movie box first, then a 64-bit
/// `mdat` past 4 GiB. The video's chunk sits 40 bytes below 2^32, so the tagged movie box
/// pushes it past; the sound's is past 2^32 already (`co64`). Returns the file, its
/// length and the two offsets.
fn past_4_gib(dir: &Path) -> (std::path::PathBuf, u64, [u64; 2]) {
    let below = (1u64 << 32) - 40;
    let past = (1u64 << 32) + 4096;
    let traks = vec![trak(b"vide", &[below], false), trak(b"soun", &[past], true)];
    let mut head = ftyp();
    head.extend_from_slice(&Node::tree(b"moov", vec![], traks).to_bytes());
    let len = past + 8192;
    let mdat_size = len - head.len() as u64;
    head.extend_from_slice(&1u32.to_be_bytes());
    head.extend_from_slice(b"mdat");
    head.extend_from_slice(&mdat_size.to_be_bytes());
    let src = dir.join("big.mp4");
    let mut f = std::fs::File::create(&src).unwrap();
    f.write_all(&head).unwrap();
    f.set_len(len).unwrap();
    (src, len, [below, past])
}

#[test]
fn a_file_past_4_gib_gets_its_offsets_moved_and_made_64_bit() {
    let dir = tempfile::tempdir().unwrap();
    let (src, len, [below, past]) = past_4_gib(dir.path());
    let t = plan(&src, &equirect()).unwrap();
    let s = &t.summary;
    assert_eq!((s.tables_moved, s.promoted), (2, 1));
    assert_eq!(s.shift as u64, s.moov.1 - s.moov.0);
    assert_eq!(t.new_len(), len + s.shift as u64);
    // The new movie box, read back: both tables 64-bit, moved past the growth.
    let p = dir.path().join("head.mp4");
    std::fs::write(&p, [ftyp(), t.moov().to_vec()].concat()).unwrap();
    let (_, m) = Movie::open(&p).unwrap();
    let shift = s.shift as u64;
    assert_eq!(movie_offsets(&m.moov), [below + shift, past + shift]);
}

#[test]
#[ignore = "reads 4 GiB of a sparse file: 2 s with the pages cached, 20 s without"]
fn a_file_past_4_gib_is_written_whole() {
    let dir = tempfile::tempdir().unwrap();
    let (src, len, _) = past_4_gib(dir.path());
    let t = plan(&src, &equirect()).unwrap();
    let mut out = Head {
        kept: Vec::new(),
        keep: 1 << 16,
        total: 0,
    };
    t.write_to(&mut out).unwrap();
    assert_eq!(out.total, len + t.summary.shift as u64);
    let moov_at = ftyp().len();
    assert_eq!(&out.kept[moov_at..moov_at + t.moov().len()], t.moov());
}

/// Each track's first chunk offset, from its `co64`.
fn movie_offsets(moov: &Node) -> Vec<u64> {
    moov.children()
        .iter()
        .map(|t| {
            let mut n = t;
            for k in [b"mdia", b"minf", b"stbl"] {
                n = n.child(k).unwrap();
            }
            let p = n.child(b"co64").expect("64-bit").payload().unwrap();
            u64::from_be_bytes(p[8..16].try_into().unwrap())
        })
        .collect()
}
