//! mirrorball-spherical integration tests: files made by Debian's ffmpeg, tagged, and read
//! back by ffprobe and ffmpeg (`videos.rs`); hostile and unusual files, 64-bit sizes and a
//! sparse file past 4 GiB (`hostile.rs`).
mod hostile;
mod videos;

use mirrorball_spherical::{plan, Change};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Whether Debian's ffmpeg and ffprobe are on the PATH; says so loudly when not.
pub fn have_ffmpeg() -> bool {
    let found = ["ffmpeg", "ffprobe"]
        .iter()
        .all(|t| Command::new(t).arg("-version").output().is_ok());
    if !found {
        eprintln!(
            "\n!!!!!!!! SKIPPED: no ffmpeg/ffprobe on the PATH, so tagged files were NOT checked \
             against FFmpeg (apt-get install ffmpeg) !!!!!!!!\n"
        );
    }
    found
}

/// Runs a tool, asserting success; its standard output.
pub fn tool(name: &str, args: &[&str]) -> Vec<u8> {
    let o = Command::new(name)
        .args(args)
        .output()
        .expect("the tool runs");
    assert!(
        o.status.success(),
        "{name} {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o.stdout
}

/// A short test video `name` in `dir`: `w`×`h` H.264 (and AAC audio with `audio`), with
/// `flags` passed to the muxer (`+faststart` puts the movie box first).
pub fn video(dir: &Path, name: &str, (w, h): (u32, u32), audio: bool, flags: &str) -> PathBuf {
    let out = dir.join(name);
    let size = format!("testsrc=size={w}x{h}:rate=10:duration=0.3");
    let mut args = vec!["-v", "error", "-y", "-f", "lavfi", "-i", &size];
    if audio {
        args.extend([
            "-f",
            "lavfi",
            "-i",
            "sine=duration=0.3",
            "-c:a",
            "aac",
            "-shortest",
        ]);
    }
    args.extend(["-c:v", "libx264", "-pix_fmt", "yuv420p"]);
    if !flags.is_empty() {
        args.extend(["-movflags", flags]);
    }
    let out_s = out.to_str().unwrap().to_string();
    args.push(&out_s);
    tool("ffmpeg", &args);
    out
}

/// `input` tagged with `change` into `output` through the library.
pub fn tag_into(input: &Path, output: &Path, change: &Change) -> mirrorball_spherical::Summary {
    let t = plan(input, change).unwrap_or_else(|e| panic!("{e}"));
    let mut f = std::fs::File::create(output).unwrap();
    t.write_to(&mut f).unwrap();
    assert_eq!(std::fs::metadata(output).unwrap().len(), t.new_len());
    t.summary.clone()
}
