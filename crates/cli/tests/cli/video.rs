//! Video files through `convert`: without the `video` feature a clear refusal saying how to
//! build it; with it, a conversion whose exit status and files are checked, and Ctrl-C in
//! the middle of one leaving nothing behind. (The conversion's properties, pixels and bad
//! inputs: `crates/video/tests`.)

use crate::util::{files, run, stderr};
#[cfg(feature = "video")]
use std::path::Path;

/// A 30 fps testsrc2 lat-long of `size` and `seconds`, with a sine track.
#[cfg(feature = "video")]
fn make_video(path: &Path, size: &str, seconds: u32) {
    let status = std::process::Command::new("ffmpeg")
        .args(["-y", "-v", "error", "-nostdin", "-f", "lavfi", "-i"])
        .arg(format!("testsrc2=size={size}:rate=30:duration={seconds}"))
        .args(["-f", "lavfi", "-i"])
        .arg(format!("sine=duration={seconds}"))
        .args([
            "-pix_fmt",
            "yuv420p",
            "-c:v",
            "libx264",
            "-preset",
            "ultrafast",
            "-c:a",
            "aac",
        ])
        .arg(path)
        .status()
        .expect("ffmpeg (apt-get install ffmpeg) runs");
    assert!(status.success());
}

#[cfg(not(feature = "video"))]
#[test]
fn without_the_feature_a_video_is_refused_with_how_to_build_it() {
    let dir = tempfile::tempdir().unwrap();
    let (i, o) = (dir.path().join("in.mp4"), dir.path().join("out.mp4"));
    std::fs::write(&i, b"not read").unwrap();
    let out = run(&[
        "convert",
        i.to_str().unwrap(),
        o.to_str().unwrap(),
        "--to",
        "eac",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let e = stderr(&out);
    assert!(
        e.contains("--features video") && e.contains("libavcodec-dev"),
        "{e}"
    );
    assert_eq!(files(dir.path()), ["in.mp4"]);
}

#[cfg(feature = "video")]
#[test]
fn a_video_converts_and_a_bad_one_exits_1_with_nothing_left() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let i = d.join("in.mp4");
    make_video(&i, "256x128", 1);
    let o = d.join("out.mp4");
    let out = run(&[
        "convert",
        i.to_str().unwrap(),
        o.to_str().unwrap(),
        "--to",
        "cube",
        "--size",
        "32",
        "--crf",
        "30",
        "--preset",
        "ultrafast",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("30 frames"), "{}", stderr(&out));
    assert_eq!(files(d), ["in.mp4", "out.mp4"]);
    let cut = d.join("cut.mp4");
    let bytes = std::fs::read(&i).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() / 3]).unwrap();
    let o2 = d.join("o2.mov");
    let out = run(&[
        "convert",
        cut.to_str().unwrap(),
        o2.to_str().unwrap(),
        "--to",
        "eac",
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(stderr(&out).contains("cut.mp4"), "{}", stderr(&out));
    let out = run(&[
        "convert",
        i.to_str().unwrap(),
        o2.to_str().unwrap(),
        "--to",
        "eac",
        "--codec",
        "nosuchcodec",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert_eq!(files(d), ["cut.mp4", "in.mp4", "out.mp4"]);
}

#[cfg(all(feature = "video", unix))]
#[test]
fn ctrl_c_in_a_video_leaves_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    make_video(&d.join("in.mp4"), "1024x512", 20);
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_mirrorball"))
        .current_dir(d)
        .args(["convert", "in.mp4", "out.mp4", "--to", "cube", "-q"])
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    while !files(d).iter().any(|f| f.ends_with(".tmp")) {
        assert!(
            child.try_wait().unwrap().is_none(),
            "ended before its scratch file was seen"
        );
        assert!(started.elapsed().as_secs() < 60, "no scratch file");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    std::thread::sleep(std::time::Duration::from_millis(300));
    std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    assert_eq!(files(d), ["in.mp4"]);
}

/// `--v360` on a video: v360's EAC at a size of its own (YouTube's 3840x2160 scaled by a
/// fifth) comes out that size, marked as a 360° video (a mesh projection, as YouTube marks
/// EAC) that is read back as EAC with no --from; a projection mirrorball cannot make exits
/// 2 with nothing written.
#[cfg(feature = "video")]
#[test]
fn a_video_takes_v360s_options() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let i = d.join("in.mp4");
    make_video(&i, "512x256", 1);
    let o = d.join("eac.mp4");
    let out = run(&[
        "convert",
        i.to_str().unwrap(),
        o.to_str().unwrap(),
        "--v360",
        "e:eac:yaw=30:pitch=-20:rorder=pyr:w=768:h=432",
        "--preset",
        "ultrafast",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let probe = std::process::Command::new("ffprobe")
        .args(["-v", "error", "-select_streams", "v:0", "-show_entries"])
        .args(["stream=width,height", "-of", "csv=p=0"])
        .arg(&o)
        .output()
        .expect("ffprobe runs");
    let text = String::from_utf8_lossy(&probe.stdout);
    assert!(text.starts_with("768,432"), "{text}");
    // Debian's ffprobe 5.1 does not read the mesh; mirrorball does, and takes the file for
    // what it is with no --from.
    let info = crate::util::ok(&["info", o.to_str().unwrap()]);
    assert!(info.contains("projection:  eac"), "{info}");
    let back = d.join("back.mp4");
    let out = run(&[
        "convert",
        o.to_str().unwrap(),
        back.to_str().unwrap(),
        "--to",
        "latlong",
        "--size",
        "128",
        "--preset",
        "ultrafast",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("says eac"), "{}", stderr(&out));
    let out = run(&[
        "convert",
        i.to_str().unwrap(),
        d.join("no.mp4").to_str().unwrap(),
        "--v360",
        "e:barrelsplit",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("barrelsplit"), "{}", stderr(&out));
    assert_eq!(files(d), ["back.mp4", "eac.mp4", "in.mp4"]);
}
