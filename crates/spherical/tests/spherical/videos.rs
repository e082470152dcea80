//! Tagged files as FFmpeg reads them: ffprobe reports the spherical mapping and stereo
//! mode written, the frames (video and audio) decode to the same MD5s as the original's,
//! and FFmpeg's own MOV muxer, copying the stream, writes the same boxes.

use crate::{have_ffmpeg, tag_into, tool, video};
use mirrorball_core::{Choice, Stereo};
use mirrorball_spherical::movie::{self, Movie};
use mirrorball_spherical::{read, Change, Kind, Mapping, Reading};
use std::path::Path;

/// ffprobe's side data of the first video stream: (projection, stereo type), as
/// `-show_streams -of json` prints them ("Spherical Mapping" / "Stereo 3D").
fn probe(path: &Path) -> (Option<String>, Option<String>) {
    let out = tool(
        "ffprobe",
        &[
            "-v",
            "error",
            "-select_streams",
            "v:0",
            "-show_streams",
            "-of",
            "json",
            path.to_str().unwrap(),
        ],
    );
    let v: serde_json::Value = serde_json::from_slice(&out).unwrap();
    let side = v["streams"][0]["side_data_list"].as_array().cloned();
    let find = |t: &str, k: &str| {
        side.iter()
            .flatten()
            .find(|s| s["side_data_type"] == t)
            .and_then(|s| s[k].as_str().map(str::to_string))
    };
    (
        find("Spherical Mapping", "projection"),
        find("Stereo 3D", "type"),
    )
}

/// The decoded frames' MD5s, every stream (`-f framemd5`), less the header comments.
fn frame_md5s(path: &Path) -> String {
    let out = tool(
        "ffmpeg",
        &[
            "-v",
            "error",
            "-i",
            path.to_str().unwrap(),
            "-map",
            "0",
            "-f",
            "framemd5",
            "-",
        ],
    );
    let text = String::from_utf8(out).unwrap();
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .collect::<Vec<_>>()
        .join("\n")
}

/// What ffprobe calls each stereo arrangement (libavutil's `av_stereo3d_type_name`).
fn ffprobe_stereo(s: Stereo) -> &'static str {
    match s {
        Stereo::Mono => "2D",
        Stereo::TopBottom => "top and bottom",
        Stereo::SideBySide => "side by side",
    }
}

/// What ffprobe calls the projection written for `kind` (`av_spherical_projection_name`;
/// FFmpeg 5.1 knows no mesh, so an EAC file shows none).
fn ffprobe_projection(kind: Kind) -> Option<&'static str> {
    match kind {
        Kind::Equirect => Some("equirectangular"),
        Kind::HalfEquirect => Some("tiled equirectangular"),
        Kind::Cube => Some("cubemap"),
        Kind::Eac => None,
    }
}

/// The picture size of one eye of each kind, as the test videos have it.
fn eye(kind: Kind) -> (u32, u32) {
    match kind {
        Kind::Equirect => (64, 32),
        Kind::HalfEquirect => (32, 32),
        Kind::Cube => (96, 64),
        Kind::Eac => (3 * 32 + 4, 2 * 32 + 8),
    }
}

#[test]
fn every_projection_and_stereo_mode_reads_back_in_ffprobe_with_the_same_frames() {
    if !have_ffmpeg() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let stereos = [Stereo::Mono, Stereo::TopBottom, Stereo::SideBySide];
    for (i, kind) in Kind::all().enumerate() {
        // Each projection once in each stereo mode; the movie box first in every other one.
        for (j, stereo) in stereos.into_iter().enumerate() {
            let (w, h) = eye(kind);
            let size = stereo.extent(w, h);
            let flags = if (i + j) % 2 == 0 { "+faststart" } else { "" };
            let name = format!("{kind}-{stereo}.mp4");
            let src = video(dir.path(), &name, size, false, flags);
            let out = dir.path().join(format!("tagged-{name}"));
            let change = Change::Set {
                mapping: kind.mapping(),
                stereo,
                v1: false,
            };
            tag_into(&src, &out, &change);
            let (projection, stereo_type) = probe(&out);
            assert_eq!(projection.as_deref(), ffprobe_projection(kind), "{name}");
            assert_eq!(
                stereo_type.as_deref(),
                Some(ffprobe_stereo(stereo)),
                "{name}"
            );
            assert_eq!(frame_md5s(&out), frame_md5s(&src), "{name}");
            let tracks = read(&out).unwrap();
            let want = Reading {
                mapping: kind.mapping(),
                stereo,
                from: "V2",
            };
            assert_eq!(tracks[0].reading(), Ok(Some(want)), "{name}");
        }
    }
}

#[test]
fn chunk_offsets_move_only_when_the_movie_box_comes_first_audio_included() {
    if !have_ffmpeg() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let change = Change::Set {
        mapping: Mapping::FULL,
        stereo: Stereo::Mono,
        v1: true,
    };
    for (flags, moves) in [("", false), ("+faststart", true)] {
        for ext in ["mp4", "mov"] {
            let name = format!("av{flags}.{ext}");
            let src = video(dir.path(), &name, (64, 32), true, flags);
            let out = dir.path().join(format!("tagged-{name}"));
            let s = tag_into(&src, &out, &change);
            // Both tracks' tables move (or neither), by the movie box's growth.
            assert_eq!(s.tables_moved, if moves { 2 } else { 0 }, "{name}");
            assert_eq!(s.shift as u64, s.moov.1 - s.moov.0, "{name}");
            assert_eq!(
                frame_md5s(&out),
                frame_md5s(&src),
                "{name}: video and audio"
            );
            assert_eq!(probe(&out).0.as_deref(), Some("equirectangular"));
            let t = &read(&out).unwrap()[0];
            assert!(matches!(t.v1, Some(Ok(_))), "{name}: V1 written");
            // Removing it all again gives the original movie box's contents back.
            let back = dir.path().join(format!("removed-{name}"));
            let r = tag_into(&out, &back, &Change::Remove);
            assert_eq!(r.moov.1, s.moov.0, "{name}");
            assert_eq!(std::fs::read(&back).unwrap(), std::fs::read(&src).unwrap());
            assert_eq!(probe(&back), (None, None));
        }
    }
}

/// The boxes of the first video sample entry, in order: `(type, bytes)`.
fn entry_boxes(path: &Path) -> Vec<([u8; 4], Vec<u8>)> {
    let (_, m) = Movie::open(path).unwrap();
    let mut node = movie::video_tracks(&m.moov).next().unwrap();
    for k in [b"mdia", b"minf", b"stbl", b"stsd"] {
        node = node.child(k).unwrap();
    }
    let entry = &node.children()[0];
    entry
        .children()
        .iter()
        .map(|c| (c.kind, c.to_bytes()))
        .collect()
}

#[test]
fn ffmpeg_copying_the_stream_writes_the_same_boxes() {
    if !have_ffmpeg() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    // FFmpeg's MOV muxer writes st3d and sv3d from the side data its demuxer read: the
    // same boxes in the same place, but for the tool's name in `svhd`.
    for kind in [Kind::Equirect, Kind::HalfEquirect, Kind::Cube] {
        let src = video(dir.path(), &format!("{kind}.mp4"), eye(kind), false, "");
        let ours = dir.path().join(format!("ours-{kind}.mp4"));
        let change = Change::Set {
            mapping: kind.mapping(),
            stereo: Stereo::Mono,
            v1: false,
        };
        tag_into(&src, &ours, &change);
        let theirs = dir.path().join(format!("theirs-{kind}.mp4"));
        let args = [
            "-v",
            "error",
            "-y",
            "-i",
            ours.to_str().unwrap(),
            "-c",
            "copy",
        ];
        let mut args = args.to_vec();
        args.extend(["-strict", "unofficial", theirs.to_str().unwrap()]);
        tool("ffmpeg", &args);
        let strip = |boxes: Vec<([u8; 4], Vec<u8>)>| -> Vec<([u8; 4], Vec<u8>)> {
            boxes
                .into_iter()
                .map(|(k, b)| {
                    if &k != b"sv3d" {
                        return (k, b);
                    }
                    // sv3d: header, then svhd (left out), then proj.
                    let svhd = u32::from_be_bytes(b[8..12].try_into().unwrap()) as usize;
                    (k, b[8 + svhd..].to_vec())
                })
                .collect()
        };
        let (a, b) = (strip(entry_boxes(&ours)), strip(entry_boxes(&theirs)));
        let kinds = |v: &[([u8; 4], Vec<u8>)]| v.iter().map(|(k, _)| *k).collect::<Vec<_>>();
        assert!(kinds(&a).contains(b"sv3d"), "{kind}: {:?}", kinds(&a));
        assert_eq!(a, b, "{kind}");
    }
}
