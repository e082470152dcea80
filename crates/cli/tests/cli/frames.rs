//! Frames, streams and batches: sequences through one planned `Remap` agree with converting
//! each frame alone; raw frames through pipes, with Debian's ffmpeg on both sides, agree
//! with the same frames as PNG files; manifests and shards run every job once, skip what
//! is done and resume; bad requests are refused before anything is written.

use crate::util::{asset, files, outputs, run, stderr, stdout};
use mirrorball_io::{read, Limits};
use std::path::Path;
use std::process::{Command, Stdio};

const FFMPEG: &str = "/usr/bin/ffmpeg";

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_mirrorball")
}

fn ok(args: &[&str]) -> (String, String) {
    let o = run(args);
    assert!(o.status.success(), "mirrorball {args:?}: {}", stderr(&o));
    (stdout(&o), stderr(&o))
}

fn texels(p: &Path) -> Vec<f32> {
    let l = read(p, &Limits::default()).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    l.layers.iter().flat_map(|i| i.data().to_vec()).collect()
}

/// `n` lat-long frames of `w`×`w/2`, the city turned 40° more each frame, as
/// `dir/f_0000.exr` ….
fn frames(dir: &Path, n: usize, w: u32) {
    for k in 0..n {
        let out = dir.join(format!("f_{k:04}.exr"));
        ok(&[
            "convert",
            asset("city.exr").to_str().unwrap(),
            out.to_str().unwrap(),
            "--to",
            "latlong",
            "--size",
            &w.to_string(),
            "--yaw",
            &(40 * k).to_string(),
            "--precision",
            "float",
            "-q",
        ]);
    }
}

fn json_lines(text: &str) -> Vec<serde_json::Value> {
    text.lines()
        .filter(|l| l.starts_with('{'))
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{l}: {e}")))
        .collect()
}

#[test]
fn a_sequence_is_each_frame_converted_alone() {
    let d = tempfile::tempdir().unwrap();
    let (i, o) = (d.path().join("in"), d.path().join("out"));
    std::fs::create_dir_all(&i).unwrap();
    std::fs::create_dir_all(&o).unwrap();
    frames(&i, 3, 128);
    let pat_in = i.join("f_%04d.exr");
    let pat_out = o.join("c_%03d.exr");
    let (log, _) = ok(&[
        "convert",
        pat_in.to_str().unwrap(),
        pat_out.to_str().unwrap(),
        "--to",
        "cube",
        "--size",
        "32",
        "--precision",
        "float",
        "--json",
    ]);
    let lines = json_lines(&log);
    assert_eq!(lines.len(), 3, "{log}");
    assert!(lines.iter().all(|l| l["status"] == "done"));
    assert_eq!(outputs(&o), ["c_000.exr", "c_001.exr", "c_002.exr"]);
    for k in 0..3 {
        let single = d.path().join(format!("single_{k}.exr"));
        ok(&[
            "convert",
            i.join(format!("f_{k:04}.exr")).to_str().unwrap(),
            single.to_str().unwrap(),
            "--to",
            "cube",
            "--size",
            "32",
            "--precision",
            "float",
            "-q",
        ]);
        let (a, b) = (texels(&o.join(format!("c_{k:03}.exr"))), texels(&single));
        assert_eq!(a.len(), b.len());
        // Remap is resample's filter with fractions kept to 1/65536 of a texel.
        let worst = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - y).abs() / (1e-3 + y.abs()))
            .fold(0f32, f32::max);
        assert!(worst < 1e-3, "frame {k}: {worst}");
    }
    // The frames differ (the test would not see frames mixed up otherwise).
    assert_ne!(texels(&o.join("c_000.exr")), texels(&o.join("c_001.exr")));
    // Done frames are skipped; a missing one is made again.
    std::fs::remove_file(o.join("c_001.exr")).unwrap();
    let args = [
        "convert",
        pat_in.to_str().unwrap(),
        pat_out.to_str().unwrap(),
        "--to",
        "cube",
        "--size",
        "32",
        "--precision",
        "float",
        "--json",
    ];
    let status: Vec<String> = json_lines(&ok(&args).0)
        .iter()
        .map(|l| format!("{}:{}", l["frame"], l["status"].as_str().unwrap()))
        .collect();
    assert_eq!(status, ["0:skipped", "2:skipped", "1:done"]);
}

#[test]
fn globs_and_shards_cover_every_frame_once() {
    let d = tempfile::tempdir().unwrap();
    let (i, o) = (d.path().join("in"), d.path().join("out"));
    std::fs::create_dir_all(&i).unwrap();
    std::fs::create_dir_all(&o).unwrap();
    frames(&i, 5, 32);
    std::fs::write(i.join("notes.txt"), "not a frame").unwrap();
    let mut seen = Vec::new();
    for s in ["0/3", "1/3", "2/3"] {
        let (log, _) = ok(&[
            "convert",
            i.join("f_*.exr").to_str().unwrap(),
            o.join("%d.exr").to_str().unwrap(),
            "--to",
            "cube",
            "--size",
            "8",
            "--shard",
            s,
            "--json",
        ]);
        seen.extend(
            json_lines(&log)
                .iter()
                .map(|l| l["frame"].as_u64().unwrap()),
        );
    }
    assert_eq!(seen, [0, 1, 2, 3, 4]);
    assert_eq!(outputs(&o), ["0.exr", "1.exr", "2.exr", "3.exr", "4.exr"]);
}

#[test]
fn an_interrupted_sequence_leaves_whole_frames_and_resumes() {
    let d = tempfile::tempdir().unwrap();
    let (i, o) = (d.path().join("in"), d.path().join("out"));
    std::fs::create_dir_all(&i).unwrap();
    std::fs::create_dir_all(&o).unwrap();
    frames(&i, 1, 512);
    for k in 1..40 {
        std::fs::copy(i.join("f_0000.exr"), i.join(format!("f_{k:04}.exr"))).unwrap();
    }
    let args = |extra: &[&str]| {
        let mut v: Vec<String> = [
            "convert",
            i.join("f_%04d.exr").to_str().unwrap(),
            o.join("%04d.exr").to_str().unwrap(),
            "--to",
            "cube",
            "--size",
            "256",
            "--compression",
            "none",
            "--precision",
            "float",
            "-q",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        v.extend(extra.iter().map(|s| s.to_string()));
        v
    };
    let mut child = Command::new(bin()).args(args(&[])).spawn().unwrap();
    let t0 = std::time::Instant::now();
    while outputs(&o).iter().filter(|f| !f.starts_with('.')).count() < 2 {
        assert!(t0.elapsed().as_secs() < 120, "no frame written");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let _ = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "exits as interrupted");
    let left = outputs(&o);
    assert!(
        left.iter().all(|f| !f.starts_with('.')),
        "temporary files left: {left:?}"
    );
    assert!(
        left.len() < 40,
        "the interrupt came too late to test: {left:?}"
    );
    let whole = texels(&o.join("0000.exr"));
    for f in &left {
        assert_eq!(texels(&o.join(f)), whole, "{f} is whole");
    }
    let o2 = run(&args(&["--json"])
        .iter()
        .map(String::as_str)
        .collect::<Vec<_>>());
    assert!(o2.status.success(), "{}", stderr(&o2));
    let lines = json_lines(&stdout(&o2));
    let skipped = lines.iter().filter(|l| l["status"] == "skipped").count();
    assert_eq!(skipped, left.len());
    assert_eq!(lines.len(), 40);
    assert_eq!(outputs(&o).len(), 40);
}

/// Runs `producer | mirrorball args | consumer` and returns mirrorball's output.
fn pipe_through(producer: &[&str], args: &[&str], consumer: &[&str]) -> std::process::Output {
    let mut p = Command::new(FFMPEG)
        .args(producer)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap_or_else(|e| panic!("{FFMPEG} (apt-get install ffmpeg): {e}"));
    let mut m = Command::new(bin())
        .args(args)
        .stdin(p.stdout.take().unwrap())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let c = Command::new(FFMPEG)
        .args(consumer)
        .stdin(m.stdout.take().unwrap())
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stderr));
    assert!(p.wait().unwrap().success());
    m.wait_with_output().unwrap()
}

#[test]
fn ffmpeg_to_mirrorball_to_ffmpeg_is_the_frames_converted_as_pngs() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let src = "testsrc2=size=256x128:rate=5";
    for (fmt, bytes) in [("rgb48le", 2usize), ("rgb24", 1)] {
        let raw = dir.join(format!("out_{fmt}.raw"));
        let m = pipe_through(
            &[
                "-hide_banner",
                "-f",
                "lavfi",
                "-i",
                src,
                "-frames:v",
                "3",
                "-pix_fmt",
                fmt,
                "-f",
                "rawvideo",
                "-",
            ],
            &[
                "convert",
                "-",
                "-",
                "--in-size",
                "256x128",
                "--pix-fmt",
                fmt,
                "--to",
                "cube",
                "--size",
                "32",
                "--layout",
                "hstrip",
            ],
            &[
                "-hide_banner",
                "-y",
                "-f",
                "rawvideo",
                "-pix_fmt",
                fmt,
                "-s",
                "192x32",
                "-i",
                "-",
                "-f",
                "rawvideo",
                "-pix_fmt",
                fmt,
                raw.to_str().unwrap(),
            ],
        );
        assert!(m.status.success(), "{}", stderr(&m));
        assert!(stderr(&m).contains("writing 192x32"), "{}", stderr(&m));
        let got = std::fs::read(&raw).unwrap();
        let frame = 192 * 32 * 3 * bytes;
        assert_eq!(got.len(), 3 * frame, "three whole frames");
        // The same frames as PNG files, each converted alone.
        let pngs = dir.join(format!("png_{fmt}"));
        std::fs::create_dir_all(&pngs).unwrap();
        let st = Command::new(FFMPEG)
            .args([
                "-hide_banner",
                "-loglevel",
                "error",
                "-f",
                "lavfi",
                "-i",
                src,
                "-frames:v",
                "3",
                "-pix_fmt",
                if bytes == 2 { "rgb48be" } else { "rgb24" },
            ])
            .arg(pngs.join("%d.png"))
            .status()
            .unwrap();
        assert!(st.success());
        for k in 0..3 {
            let one = pngs.join(format!("cube_{k}.png"));
            to_strip(&pngs.join(format!("{}.png", k + 1)), &one, bytes);
            let img = image_codes(&one, bytes);
            let codes = raw_codes(&got[k * frame..(k + 1) * frame], bytes);
            // The frames are made by one planned `Remap`, the PNGs each by `resample`: they
            // agree to ~1e-5, a code or so at 16 bits.
            let tol = if bytes == 2 { 3 } else { 1 };
            let worst = worst_difference(&codes, &img);
            assert!(worst <= tol, "{fmt} frame {k}: off by {worst} codes");
            let spread = codes.iter().max().unwrap() - codes.iter().min().unwrap();
            assert!(spread > 100, "the frame has content");
        }
    }
}

/// A raw frame holds the codes the PNG of it holds: the same frames written as PNG files
/// and to a pipe (both made by one planned `Remap`, both encoded by io's sRGB rule) agree
/// to the code, at 8 and 16 bits, into a strip and an EAC frame.
#[test]
fn a_pipe_frame_holds_the_codes_of_its_png() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    frames(dir, 2, 256);
    let input = dir.join("f_%04d.exr");
    for (fmt, bytes, precision) in [("rgb24", 1usize, "8"), ("rgb48le", 2, "16")] {
        for (to, layout) in [("cube", "hstrip"), ("eac", "eac")] {
            let out = dir.join(format!("{fmt}_{to}"));
            std::fs::create_dir_all(&out).unwrap();
            let pattern = out.join("p_%04d.png");
            ok(&[
                "convert",
                input.to_str().unwrap(),
                pattern.to_str().unwrap(),
                "--to",
                to,
                "--size",
                "48",
                "--layout",
                layout,
                "--precision",
                precision,
                "-q",
            ]);
            let piped = Command::new(bin())
                .args([
                    "convert",
                    input.to_str().unwrap(),
                    "-",
                    "--to",
                    to,
                    "--size",
                    "48",
                    "--layout",
                    layout,
                    "--pix-fmt",
                    fmt,
                    "-q",
                ])
                .output()
                .unwrap();
            assert!(piped.status.success(), "{}", stderr(&piped));
            let frame = piped.stdout.len() / 2;
            for k in 0..2 {
                let png = image_codes(&out.join(format!("p_{k:04}.png")), bytes);
                let raw = raw_codes(&piped.stdout[k * frame..(k + 1) * frame], bytes);
                assert_eq!(raw.len(), png.len(), "{fmt} {to} frame {k}");
                let differ = raw.iter().zip(&png).filter(|(a, b)| a != b).count();
                assert_eq!(differ, 0, "{fmt} {to} frame {k}: {differ} codes differ");
                let spread = raw.iter().max().unwrap() - raw.iter().min().unwrap();
                assert!(spread > 100, "the frame has content");
            }
        }
    }
}

/// The first raw frame is converted from its decoded maps (it decides what the frames are),
/// the later ones straight from their codes (`Remap::rows_coded`): one frame sent three
/// times comes out as three identical frames, at 8 and 16 bits, rotated and exposed, into
/// a cube strip, an equal-area octahedral map and an equi-angular cube.
#[test]
fn a_frame_read_as_codes_is_the_frame_read_as_maps() {
    let d = tempfile::tempdir().unwrap();
    // The cube strip is encoded as its rows are made; EAC's turned cells from its layers.
    for (fmt, to) in [
        ("rgb24", "cube"),
        ("rgb48le", "cube"),
        ("rgb24", "equal-area-octahedral"),
        ("rgb48le", "eac"),
    ] {
        let raw = d.path().join(format!("in_{fmt}.raw"));
        let st = Command::new(FFMPEG)
            .args(["-v", "error", "-y", "-f", "lavfi", "-i"])
            .arg("testsrc2=size=256x128:rate=5,loop=loop=2:size=1")
            .args(["-frames:v", "3", "-pix_fmt", fmt, "-f", "rawvideo"])
            .arg(&raw)
            .status()
            .unwrap_or_else(|e| panic!("{FFMPEG} (apt-get install ffmpeg): {e}"));
        assert!(st.success());
        let m = Command::new(bin())
            .args([
                "convert",
                "-",
                "-",
                "--in-size",
                "256x128",
                "--pix-fmt",
                fmt,
                "--to",
                to,
            ])
            .args(["--size", "24", "--yaw", "30", "--exposure", "-1"])
            .stdin(std::fs::File::open(&raw).unwrap())
            .output()
            .unwrap();
        assert!(m.status.success(), "{}", stderr(&m));
        let got = &m.stdout;
        assert_eq!(got.len() % 3, 0);
        let frame = got.len() / 3;
        assert!(frame > 0);
        for k in 1..3 {
            let same = got[k * frame..(k + 1) * frame] == got[..frame];
            assert!(
                same,
                "{fmt} to {to}: frame {k} (codes) differs from frame 0 (maps)"
            );
        }
        let distinct: std::collections::HashSet<&u8> = got[..frame].iter().collect();
        assert!(distinct.len() > 50, "{fmt} to {to}: the frame has content");
    }
}

/// A stereo pair through pipes: ffmpeg's side-by-side frames (two different test sources,
/// so a swapped eye shows) converted to a top-bottom pair of cube strips are, eye by eye,
/// each eye cut out by ffmpeg and converted alone as a PNG.
#[test]
fn a_stereo_pair_through_pipes_is_each_eye_converted_alone() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let graph = "testsrc2=size=256x128:rate=5[l];testsrc=size=256x128:rate=5[r];[l][r]hstack";
    let raw = dir.join("pair.raw");
    let m = pipe_through(
        &[
            "-hide_banner",
            "-filter_complex",
            graph,
            "-frames:v",
            "2",
            "-pix_fmt",
            "rgb48le",
            "-f",
            "rawvideo",
            "-",
        ],
        &[
            "convert",
            "-",
            "-",
            "--in-size",
            "512x128",
            "--pix-fmt",
            "rgb48le",
            "--in-stereo",
            "sbs",
            "--from",
            "latlong",
            "--to",
            "cube",
            "--size",
            "32",
            "--layout",
            "hstrip",
            "--stereo",
            "tb",
        ],
        &[
            "-hide_banner",
            "-y",
            "-f",
            "rawvideo",
            "-pix_fmt",
            "rgb48le",
            "-s",
            "192x64",
            "-i",
            "-",
            "-f",
            "rawvideo",
            "-pix_fmt",
            "rgb48le",
            raw.to_str().unwrap(),
        ],
    );
    assert!(m.status.success(), "{}", stderr(&m));
    assert!(stderr(&m).contains("writing 192x64"), "{}", stderr(&m));
    let got = std::fs::read(&raw).unwrap();
    let frame = 192 * 64 * 3 * 2;
    assert_eq!(got.len(), 2 * frame, "two whole frames");
    for (eye, crop) in [(0, "crop=256:128:0:0"), (1, "crop=256:128:256:0")] {
        let pngs = dir.join(format!("eye{eye}"));
        std::fs::create_dir_all(&pngs).unwrap();
        let st = Command::new(FFMPEG)
            .args(["-hide_banner", "-loglevel", "error", "-filter_complex"])
            .arg(format!("{graph},{crop}"))
            .args(["-frames:v", "2", "-pix_fmt", "rgb48be"])
            .arg(pngs.join("%d.png"))
            .status()
            .unwrap();
        assert!(st.success());
        for k in 0..2 {
            let one = pngs.join(format!("cube_{k}.png"));
            to_strip(&pngs.join(format!("{}.png", k + 1)), &one, 2);
            let img = image_codes(&one, 2);
            // This eye's half of the frame: the top for the left eye.
            let half = &got[k * frame + eye * frame / 2..k * frame + (eye + 1) * frame / 2];
            let worst = worst_difference(&raw_codes(half, 2), &img);
            assert!(worst <= 3, "eye {eye} of frame {k}: off by {worst} codes");
        }
    }
    // The two eyes differ, so a swap would have shown.
    assert_ne!(&got[..frame / 2], &got[frame / 2..frame]);
}

/// Converts the PNG `png` alone to a horizontal strip of 32² cube faces at `out`, in PNG
/// samples of `bytes` bytes: what the pipe tests compare their frames with.
fn to_strip(png: &Path, out: &Path, bytes: usize) {
    ok(&[
        "convert",
        png.to_str().unwrap(),
        out.to_str().unwrap(),
        "--to",
        "cube",
        "--size",
        "32",
        "--layout",
        "hstrip",
        "--precision",
        if bytes == 2 { "16" } else { "8" },
        "-q",
    ]);
}

/// The codes of raw little-endian samples of `bytes` bytes each.
fn raw_codes(raw: &[u8], bytes: usize) -> Vec<i64> {
    if bytes == 2 {
        raw.chunks_exact(2)
            .map(|c| u16::from_le_bytes([c[0], c[1]]) as i64)
            .collect()
    } else {
        raw.iter().map(|&c| c as i64).collect()
    }
}

/// The largest difference between two pictures' codes, of one length.
fn worst_difference(a: &[i64], b: &[i64]) -> i64 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).map(|(a, b)| (a - b).abs()).max().unwrap()
}

/// The codes of an RGB PNG of `bytes` bytes a sample, from the linear values io reads
/// (its decoding table inverted exactly: the codes are far apart in `f32`).
fn image_codes(p: &Path, bytes: usize) -> Vec<i64> {
    let scale = if bytes == 2 { 65535.0 } else { 255.0 };
    let l = read(p, &Limits::default()).unwrap();
    assert_eq!(l.layers[0].channels(), 3);
    l.layers[0]
        .data()
        .iter()
        .map(|&v| (mirrorball_core::color::linear_to_srgb(v as f64) * scale).round() as i64)
        .collect()
}

#[test]
fn bad_frames_requests_are_refused_and_nothing_is_written() {
    let d = tempfile::tempdir().unwrap();
    let (i, o) = (d.path().join("in"), d.path().join("out"));
    std::fs::create_dir_all(&i).unwrap();
    std::fs::create_dir_all(&o).unwrap();
    frames(&i, 2, 32);
    let pin = i.join("f_%04d.exr");
    let pin = pin.to_str().unwrap();
    let pout = o.join("%d.exr");
    let pout = pout.to_str().unwrap();
    let nothing = i.join("g_%04d.exr");
    for (args, code, says) in [
        (vec![nothing.to_str().unwrap(), pout], 2, "matches no file"),
        (vec![pin, pin], 2, "the output pattern is the input pattern"),
        (vec![pin, pout, "--shard", "3/2"], 2, "counted from 0"),
        (vec![pin, pout, "--shard", "0/0"], 2, "at least 1"),
        (
            vec![pin, o.join("one.exr").to_str().unwrap()],
            2,
            "need an output pattern",
        ),
        (vec!["-", pout, "--pix-fmt", "rgb24"], 2, "need --in-size"),
        (
            vec![
                "-",
                pout,
                "--in-size",
                "32x16",
                "--pix-fmt",
                "rgb24",
                "--shard",
                "0/2",
            ],
            2,
            "one stream",
        ),
        (
            vec![pin, "-", "--pix-fmt", "rgb24", "--layout", "separate"],
            2,
            "one picture",
        ),
        (
            vec![pin, pout, "--pix-fmt", "yuv420p"],
            2,
            "--pix-fmt: unknown 'yuv420p'",
        ),
        (
            vec![pin, pout, "--overwrite", "--in-size", "4x4"],
            2,
            "--in-size is the size of raw frames",
        ),
    ] {
        let mut a = vec!["convert"];
        a.extend(&args);
        a.extend(["--to", "cube", "--size", "8"]);
        let out = run(&a);
        assert_eq!(out.status.code(), Some(code), "{a:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(says), "{a:?}: {}", stderr(&out));
        assert!(outputs(&o).is_empty(), "{a:?} wrote {:?}", outputs(&o));
    }
    // A pipe that ends inside a frame: the frames before it are whole, then the error.
    let frame = 32 * 16 * 3;
    let mut m = Command::new(bin())
        .args([
            "convert",
            "-",
            pout,
            "--in-size",
            "32x16",
            "--pix-fmt",
            "rgb24",
            "--to",
            "cube",
            "--size",
            "8",
        ])
        .stdin(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    use std::io::Write;
    m.stdin
        .take()
        .unwrap()
        .write_all(&vec![128u8; frame * 2 + 100])
        .unwrap();
    let out = m.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("ended 100 bytes into frame 2"),
        "{}",
        stderr(&out)
    );
    assert_eq!(outputs(&o), ["0.exr", "1.exr"]);
}

#[test]
fn manifests_run_each_job_once_across_shards_skip_and_report() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let city = asset("city.exr");
    let sky = asset("sky.exr");
    let out = |n: &str| dir.join(n).to_str().unwrap().to_string();
    let jsonl = format!(
        "# jobs\n{}\n{}\n{}\n",
        serde_json::json!({"input": city, "output": out("a.ktx2"), "options": "--size 16"}),
        serde_json::json!({"input": sky, "output": out("b_{face}.exr"), "options": ["--size", "8"]}),
        serde_json::json!({"input": city, "output": out("c.png"), "options": "--to latlong --size 32"}),
    );
    let m = dir.join("jobs.jsonl");
    std::fs::write(&m, jsonl).unwrap();
    let mut lines = Vec::new();
    for s in ["0/2", "1/2"] {
        let (log, _) = ok(&[
            "convert",
            "--manifest",
            m.to_str().unwrap(),
            "--shard",
            s,
            "--to",
            "cube",
            "-q",
        ]);
        lines.extend(json_lines(&log));
    }
    let jobs: Vec<u64> = lines.iter().map(|l| l["job"].as_u64().unwrap()).collect();
    assert_eq!(jobs, [0, 1, 2]);
    assert!(lines.iter().all(|l| l["status"] == "done"), "{lines:?}");
    assert_eq!(lines[2]["line"], 4);
    let made = files(dir);
    for f in ["a.ktx2", "b_px.exr", "b_nz.exr", "c.png"] {
        assert!(made.contains(&f.to_string()), "{f}: {made:?}");
    }
    // The job's --to latlong won over the command line's --to cube.
    assert_eq!(
        read(&dir.join("c.png"), &Limits::default()).unwrap().layers[0].width(),
        32
    );
    // Run again: every job skipped; a CSV of the same jobs, with a failing one added.
    let (log, _) = ok(&[
        "convert",
        "--manifest",
        m.to_str().unwrap(),
        "--to",
        "cube",
        "-q",
    ]);
    assert!(
        json_lines(&log).iter().all(|l| l["status"] == "skipped"),
        "{log}"
    );
    let csv = dir.join("jobs.csv");
    std::fs::write(
        &csv,
        format!(
            "input,output,options\n{},{},--size 16\n{},\"{}\",--size 8\n",
            dir.join("missing.exr").display(),
            out("x.ktx2"),
            city.display(),
            out("y,1.ktx2")
        ),
    )
    .unwrap();
    let o = run(&[
        "convert",
        "--manifest",
        csv.to_str().unwrap(),
        "--to",
        "cube",
        "-q",
    ]);
    assert_eq!(o.status.code(), Some(1));
    let l = json_lines(&stdout(&o));
    assert_eq!(
        (l[0]["status"].as_str(), l[1]["status"].as_str()),
        (Some("failed"), Some("done"))
    );
    assert!(l[0]["error"].as_str().unwrap().contains("missing.exr"));
    assert!(dir.join("y,1.ktx2").exists());
    // Malformed lines are named, before any job runs.
    std::fs::write(
        &m,
        format!(
            "{}\n{{\"input\": 1}}\n",
            serde_json::json!({"input": city, "output": out("z.ktx2")})
        ),
    )
    .unwrap();
    let o = run(&["convert", "--manifest", m.to_str().unwrap(), "--to", "cube"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("jobs.jsonl:2: \"input\" must be a non-empty string"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.join("z.ktx2").exists());
    std::fs::write(
        &m,
        format!(
            "{}\n",
            serde_json::json!({"input": city, "output": out("z.ktx2"), "options": "--size nine"})
        ),
    )
    .unwrap();
    let o = run(&["convert", "--manifest", m.to_str().unwrap(), "--to", "cube"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("jobs.jsonl:1: invalid value 'nine'"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn a_rerun_skips_only_what_the_same_settings_made() {
    let d = tempfile::tempdir().unwrap();
    let (i, o) = (d.path().join("in"), d.path().join("out"));
    std::fs::create_dir_all(&i).unwrap();
    frames(&i, 3, 64);
    let pat_in = i.join("f_%04d.exr");
    let pat_out = o.join("c_%03d.exr");
    let convert = |size: &str| {
        ok(&[
            "convert",
            pat_in.to_str().unwrap(),
            pat_out.to_str().unwrap(),
            "--to",
            "cube",
            "--size",
            size,
            "--json",
        ])
    };
    // Each frame's status, in frame order (skipped frames are logged first).
    let statuses = |log: &str| -> Vec<String> {
        let mut lines: Vec<(u64, String)> = json_lines(log)
            .iter()
            .map(|l| {
                (
                    l["frame"].as_u64().unwrap(),
                    l["status"].as_str().unwrap().to_string(),
                )
            })
            .collect();
        lines.sort();
        lines.into_iter().map(|(_, s)| s).collect()
    };
    let height = |k: u32| {
        read(&o.join(format!("c_{k:03}.exr")), &Limits::default())
            .unwrap()
            .layers[0]
            .height()
    };
    // The output folder is made; the same request again skips every frame.
    let (log, _) = convert("16");
    assert_eq!(statuses(&log), ["done"; 3]);
    let h16 = height(0);
    let (log, err) = convert("16");
    assert_eq!(statuses(&log), ["skipped"; 3]);
    assert!(
        err.contains("3 frames skipped: their outputs exist, made with these settings"),
        "{err}"
    );
    // Other settings: every frame again, and said so.
    let (log, err) = convert("8");
    assert_eq!(statuses(&log), ["done"; 3], "{err}");
    assert!(err.contains("3 frames converted again"), "{err}");
    assert_eq!(height(0), h16 / 2, "made again at the new size");
    // A newer input frame: that frame alone again.
    std::thread::sleep(std::time::Duration::from_millis(20));
    let one = i.join("f_0001.exr");
    let bytes = std::fs::read(&one).unwrap();
    std::fs::write(&one, bytes).unwrap();
    let (log, err) = convert("8");
    assert_eq!(statuses(&log), ["skipped", "done", "skipped"], "{err}");
    assert!(err.contains("1 frame converted again"), "{err}");
    // An output no record speaks for (another tool's, or an older mirrorball's) is kept,
    // and said.
    std::fs::remove_file(o.join(".mirrorball-frames")).unwrap();
    let (log, err) = convert("16");
    assert_eq!(statuses(&log), ["skipped"; 3]);
    assert!(
        err.contains("3 frames skipped: their outputs exist, with no record of the settings"),
        "{err}"
    );
    assert_eq!(height(2), h16 / 2, "kept");
}
