//! Video files converted through the library as `mirrorball convert in.mp4 out.mp4` does,
//! checked with Debian's `ffmpeg` and `ffprobe`: frames, rate, duration and audio kept, the
//! spherical metadata written and read, the pixels of `v360`, and bad inputs refused with
//! nothing left behind.

use mirrorball::convert::ConvertRequest;
use mirrorball::{Error, Fault, Hooks, ProjSpec};
use mirrorball_video::{run, VideoRequest};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::AtomicU64;
use std::sync::{Arc, Mutex};

/// Hooks that keep the notes.
#[derive(Default)]
struct Notes(Mutex<Vec<String>>);

impl Hooks for Notes {
    fn note(&self, line: &str) {
        self.0.lock().unwrap().push(line.to_string());
    }
    fn progress(&self, _: &str, _: u64, work: &mut (dyn FnMut(Arc<AtomicU64>) + Send)) {
        work(Arc::new(AtomicU64::new(0)))
    }
}

fn ffmpeg(args: &[&str]) {
    let out = Command::new("ffmpeg")
        .args(["-y", "-v", "error", "-nostdin"])
        .args(args)
        .output()
        .expect("ffmpeg runs");
    assert!(
        out.status.success(),
        "ffmpeg {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn probe(path: &Path, args: &[&str]) -> serde_json::Value {
    let out = Command::new("ffprobe")
        .args(["-v", "error", "-of", "json"])
        .args(args)
        .arg(path)
        .output()
        .expect("ffprobe runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// A 1 s, 30 fps 256×128 testsrc2 with a 440 Hz AAC track.
fn source(dir: &Path, name: &str, pix_fmt: &str) -> PathBuf {
    source_of(
        dir,
        name,
        pix_fmt,
        "testsrc2=size=256x128:rate=30:duration=1",
    )
}

/// [`source`] of the lavfi video `video`.
fn source_of(dir: &Path, name: &str, pix_fmt: &str, video: &str) -> PathBuf {
    let path = dir.join(name);
    ffmpeg(&[
        "-f",
        "lavfi",
        "-i",
        video,
        "-f",
        "lavfi",
        "-i",
        "sine=frequency=440:duration=1",
        "-c:v",
        "libx264",
        "-crf",
        "10",
        "-pix_fmt",
        pix_fmt,
        "-c:a",
        "aac",
        "-shortest",
        path.to_str().unwrap(),
    ]);
    path
}

fn request(input: &Path, output: &Path, to: &str) -> VideoRequest {
    VideoRequest {
        convert: ConvertRequest {
            input: input.to_string_lossy().into_owned(),
            output: output.to_string_lossy().into_owned(),
            to: Some(ProjSpec::parse(to).unwrap()),
            ..ConvertRequest::default()
        },
        ..VideoRequest::default()
    }
}

fn convert(r: &VideoRequest) -> Result<Vec<String>, Error> {
    let notes = Notes::default();
    run(r, &notes)?;
    Ok(notes.0.into_inner().unwrap())
}

/// The video stream's frames counted, rate and duration, and the pixel format.
fn video_facts(path: &Path) -> (u64, String, f64, String) {
    let v = probe(
        path,
        &[
            "-count_frames",
            "-select_streams",
            "v:0",
            "-show_entries",
            "stream=nb_read_frames,avg_frame_rate,duration,pix_fmt",
        ],
    );
    let s = &v["streams"][0];
    (
        s["nb_read_frames"].as_str().unwrap().parse().unwrap(),
        s["avg_frame_rate"].as_str().unwrap().to_string(),
        s["duration"].as_str().unwrap().parse().unwrap(),
        s["pix_fmt"].as_str().unwrap().to_string(),
    )
}

/// The decoded audio's MD5, as ffmpeg's md5 muxer gives it.
fn audio_md5(path: &Path) -> String {
    let out = Command::new("ffmpeg")
        .args(["-v", "error", "-nostdin", "-i"])
        .arg(path)
        .args(["-map", "0:a", "-f", "md5", "-"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap().trim().to_string()
}

fn names_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The stream's side data of `kind`, if ffprobe reports it.
fn side_data(path: &Path, kind: &str) -> Option<serde_json::Value> {
    let v = probe(path, &["-select_streams", "v:0", "-show_streams"]);
    v["streams"][0]["side_data_list"]
        .as_array()?
        .iter()
        .find(|d| d["side_data_type"] == kind)
        .cloned()
}

#[test]
fn eac_and_cube_keep_frames_rate_duration_and_audio() {
    let dir = tempfile::tempdir().unwrap();
    let input = source(dir.path(), "in.mp4", "yuv420p");
    let (frames, rate, duration, _) = video_facts(&input);
    assert_eq!((frames, rate.as_str()), (30, "30/1"));
    let md5 = audio_md5(&input);
    for (to, mapping) in [("eac", None), ("cube", Some("cubemap"))] {
        let out = dir.path().join(format!("{to}.mp4"));
        convert(&request(&input, &out, to)).unwrap();
        let (f, r, d, pix) = video_facts(&out);
        assert_eq!(
            (f, r.as_str(), pix.as_str()),
            (frames, "30/1", "yuv420p"),
            "{to}"
        );
        assert!(
            (d - duration).abs() < 1.0 / 30.0 + 1e-6,
            "{to}: {d} s, input {duration} s"
        );
        assert_eq!(audio_md5(&out), md5, "{to}: the audio is copied untouched");
        let sph = side_data(&out, "Spherical Mapping");
        if let Some(m) = mapping {
            let sph = sph.expect("ffprobe reports the spherical mapping");
            assert_eq!(sph["projection"], m, "{sph}");
        }
        // What mirrorball wrote, as mirrorball-spherical reads it back.
        let tracks = mirrorball::spherical::read(&out).unwrap();
        let reading = tracks[0].reading().unwrap().expect("metadata written");
        assert_eq!(reading.from, "V2");
        assert_eq!(reading.mapping.projection().kind().to_string(), to);
    }
    // Only the outputs are left.
    assert_eq!(names_in(dir.path()), ["cube.mp4", "eac.mp4", "in.mp4"]);
}

#[test]
fn the_stereo_mode_is_written_and_read_back() {
    let dir = tempfile::tempdir().unwrap();
    let input = source(dir.path(), "in.mp4", "yuv420p");
    let out = dir.path().join("tb.mov");
    let mut r = request(&input, &out, "latlong");
    r.convert.stereo = Some(mirrorball_core::Stereo::TopBottom);
    r.convert.size = Some(64);
    convert(&r).unwrap();
    let sph = side_data(&out, "Spherical Mapping").expect("spherical mapping");
    assert_eq!(sph["projection"], "equirectangular");
    let st = side_data(&out, "Stereo 3D").expect("stereo 3d");
    assert_eq!(st["type"], "top and bottom", "{st}");
    // Converted again with no --from or --in-stereo: the file says both.
    let again = dir.path().join("again.mp4");
    let mut r = request(&out, &again, "cube");
    r.convert.size = Some(32);
    let notes = convert(&r).unwrap();
    assert!(
        notes.iter().any(|n| n.contains("Spherical Video V2 says")),
        "{notes:?}"
    );
    // One eye read (the picture 64x64 → a 96x64 cube of 32² faces, not a tb pair's).
    let v = probe(
        &again,
        &[
            "-select_streams",
            "v:0",
            "-show_entries",
            "stream=width,height",
        ],
    );
    assert_eq!(
        (
            v["streams"][0]["width"].as_u64(),
            v["streams"][0]["height"].as_u64()
        ),
        (Some(96), Some(64))
    );
}

/// Matroska and WebM state the projection and stereo mode as their `Projection` and
/// `StereoMode` elements (FFmpeg's muxer, from the stream's side data): ffprobe reads them
/// back, a second conversion with no --from takes them from the file, and EAC (a mesh,
/// which FFmpeg's muxer cannot write) is written without one, saying so.
#[test]
fn matroska_and_webm_state_the_projection_and_stereo_mode() {
    let dir = tempfile::tempdir().unwrap();
    let input = source(dir.path(), "in.mp4", "yuv420p");
    // WebM holds no AAC: its case reads the same video without the audio.
    let silent = dir.path().join("silent.mp4");
    ffmpeg(&[
        "-i",
        input.to_str().unwrap(),
        "-an",
        "-c",
        "copy",
        silent.to_str().unwrap(),
    ]);
    let cases = [
        ("cube.mkv", "cube", mirrorball_core::Stereo::Mono, "cubemap"),
        (
            "ll.mkv",
            "latlong",
            mirrorball_core::Stereo::TopBottom,
            "equirectangular",
        ),
        (
            "ll.webm",
            "latlong",
            mirrorball_core::Stereo::SideBySide,
            "equirectangular",
        ),
        (
            "vr180.mkv",
            "half-equirect",
            mirrorball_core::Stereo::Mono,
            "tiled equirectangular",
        ),
    ];
    for (name, to, stereo, projection) in cases {
        let out = dir.path().join(name);
        let from = if name.ends_with(".webm") {
            &silent
        } else {
            &input
        };
        let mut r = request(from, &out, to);
        r.convert.stereo = Some(stereo);
        r.convert.size = Some(64);
        let notes = convert(&r).unwrap();
        assert!(
            notes.iter().any(|n| n.contains("Matroska Projection")),
            "{name}: {notes:?}"
        );
        let sph = side_data(&out, "Spherical Mapping").expect("ffprobe reads the projection");
        assert_eq!(sph["projection"], projection, "{name}: {sph}");
        let st = side_data(&out, "Stereo 3D");
        match stereo {
            mirrorball_core::Stereo::Mono => assert!(st.is_none(), "{name}: {st:?}"),
            mirrorball_core::Stereo::TopBottom => {
                assert_eq!(st.unwrap()["type"], "top and bottom", "{name}")
            }
            mirrorball_core::Stereo::SideBySide => {
                assert_eq!(st.unwrap()["type"], "side by side", "{name}")
            }
        }
        // Read back by mirrorball with no --from: one eye, as the file says.
        let again = dir.path().join(format!("again-{name}.mp4"));
        let mut r = request(&out, &again, "cube");
        r.convert.size = Some(16);
        let notes = convert(&r).unwrap();
        assert!(
            notes
                .iter()
                .any(|n| n.contains("its Projection element says")),
            "{name}: {notes:?}"
        );
        let v = probe(
            &again,
            &[
                "-select_streams",
                "v:0",
                "-show_entries",
                "stream=width,height",
            ],
        );
        // One eye read: 16² faces in c3x2, not a stereo pair's picture.
        assert_eq!(
            (
                v["streams"][0]["width"].as_u64(),
                v["streams"][0]["height"].as_u64()
            ),
            (Some(48), Some(32)),
            "{name}"
        );
    }
    let eac = dir.path().join("eac.mkv");
    let notes = convert(&request(&input, &eac, "eac")).unwrap();
    assert!(
        notes.iter().any(|n| n.contains("written without it")),
        "{notes:?}"
    );
    assert!(side_data(&eac, "Spherical Mapping").is_none());
}

/// Raw yuv420p frames of `path` decoded by ffmpeg, through `filter` if any.
fn raw_frames(path: &Path, filter: Option<&str>) -> Vec<u8> {
    raw_frames_as(path, filter, "yuv420p")
}

/// The frames of `path` (through `filter`, if any) as raw `pix_fmt`.
fn raw_frames_as(path: &Path, filter: Option<&str>, pix_fmt: &str) -> Vec<u8> {
    let mut cmd = Command::new("ffmpeg");
    cmd.args(["-v", "error", "-nostdin", "-i"]).arg(path);
    if let Some(f) = filter {
        cmd.args(["-vf", f]);
    }
    let out = cmd
        .args([
            "-fps_mode",
            "passthrough",
            "-f",
            "rawvideo",
            "-pix_fmt",
            pix_fmt,
            "-",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

/// [`psnr`] of little-endian 16-bit codes (10-bit video's samples).
fn psnr_words(a: &[u8], b: &[u8], max: f64) -> f64 {
    let w = |f: &[u8]| -> Vec<f64> {
        f.chunks_exact(2)
            .map(|c| u16::from_le_bytes([c[0], c[1]]) as f64)
            .collect()
    };
    let (x, y) = (w(a), w(b));
    assert_eq!(x.len(), y.len());
    let mse = x.iter().zip(&y).map(|(p, q)| (p - q).powi(2)).sum::<f64>() / x.len() as f64;
    10.0 * (max * max / mse.max(1e-12)).log10()
}

fn psnr(a: &[u8], b: &[u8], max: f64) -> f64 {
    assert_eq!(a.len(), b.len());
    let mse = a
        .iter()
        .zip(b)
        .map(|(&x, &y)| (x as f64 - y as f64).powi(2))
        .sum::<f64>()
        / a.len() as f64;
    10.0 * (max * max / mse.max(1e-12)).log10()
}

#[test]
fn the_pixels_are_v360s_in_yuv420p() {
    let dir = tempfile::tempdir().unwrap();
    // testsrc2's one-texel edges softened: where v360's bilinear reads and mirrorball's
    // antialiased filter differ most (the zone-plate tests measure that difference).
    let input = source_of(
        dir.path(),
        "in.mp4",
        "yuv420p",
        "testsrc2=size=512x256:rate=30:duration=1,gblur=sigma=1.5",
    );
    for (to, size, v360) in [
        ("cube", 128, "e:c3x2"),
        ("eac", 128, "e:eac"),
        ("latlong", 256, "e:e"),
    ] {
        let out = dir.path().join(format!("{to}.mkv"));
        let mut r = request(&input, &out, to);
        r.convert.size = Some(size);
        r.crf = Some(0); // lossless: the conversion's own pixels
        convert(&r).unwrap();
        let v = probe(
            &out,
            &[
                "-select_streams",
                "v:0",
                "-show_entries",
                "stream=width,height",
            ],
        );
        let (w, h) = (
            v["streams"][0]["width"].as_u64().unwrap() as usize,
            v["streams"][0]["height"].as_u64().unwrap() as usize,
        );
        // EAC's two-texel border does not halve: v360 gives each half-size colour plane a
        // two-texel border of its own, so its 4:2:0 colour planes are not its 4:4:4 ones
        // halved (35 and 27 dB between them, its own luma identical); mirrorball's follow
        // the 4:4:4 picture's geometry halved (each colour texel where its 2×2 block is,
        // made at its own size), so EAC is held to v360's 4:4:4 picture.
        let v360 = match to {
            "eac" => format!("format=yuv444p,v360={v360}:w={w}:h={h},format=yuv420p"),
            _ => format!("v360={v360}:w={w}:h={h}"),
        };
        let ours = raw_frames(&out, None);
        let theirs = raw_frames(&input, Some(&v360));
        assert_eq!(
            ours.len(),
            30 * (w * h * 3 / 2),
            "{to}: 30 frames of {w}x{h}"
        );
        assert_eq!(ours.len(), theirs.len());
        let db = psnr(&ours, &theirs, 255.0);
        let plane = |f: &[u8], k: usize| -> Vec<u8> {
            let (n, c) = (w * h, w * h / 4);
            f.chunks_exact(n + 2 * c)
                .flat_map(|fr| match k {
                    0 => fr[..n].to_vec(),
                    _ => fr[n + (k - 1) * c..n + k * c].to_vec(),
                })
                .collect()
        };
        let each: Vec<f64> = (0..3)
            .map(|k| psnr(&plane(&ours, k), &plane(&theirs, k), 255.0))
            .collect();
        eprintln!("{to}: {db:.1} dB against {v360} (Y, U, V: {each:.1?})");
        assert!(each[0] > 44.0, "{to}: Y {:.1} dB against {v360}", each[0]);
        assert!(
            db > 38.0,
            "{to}: {db:.1} dB against {v360} (Y, U, V: {each:.1?})"
        );
    }
}

/// `--v360 S` on a video against `ffmpeg -vf v360=S`, in yuv420p and yuv420p10le: each
/// plane's PSNR (a wrong turn, order or face arrangement is far below it), lossless
/// encodes on both sides. EAC is held to v360's 4:4:4 picture (see
/// `the_pixels_are_v360s_in_yuv420p`).
#[test]
fn v360_options_give_v360s_pixels_in_yuv420p_and_yuv420p10le() {
    let dir = tempfile::tempdir().unwrap();
    for (pix_fmt, max, bytes) in [("yuv420p", 255.0, 1), ("yuv420p10le", 1023.0, 2)] {
        let input = source_of(
            dir.path(),
            &format!("in-{pix_fmt}.mkv"),
            pix_fmt,
            "testsrc2=size=512x256:rate=30:duration=1,gblur=sigma=1.5",
        );
        for options in [
            "e:c3x2:out_forder=fbudlr:out_frot=123012:yaw=-45:pitch=10:w=384:h=256",
            "e:eac:yaw=30:pitch=20:roll=-50:rorder=rpy:w=388:h=264",
            "e:flat:h_fov=90:v_fov=58.71551708:w=320:h=180:pitch=30:roll=15:rorder=ryp",
            // v360's eac at a size of its own (YouTube's 3840x2160 scaled by a fifth).
            "e:eac:yaw=-60:w=768:h=432",
        ] {
            let out = dir.path().join(format!("out-{pix_fmt}.mkv"));
            let v360 = mirrorball::v360::parse(options).unwrap();
            let mut r = request(&input, &out, "latlong");
            r.convert.to = None;
            r.convert = r.convert.with_v360(&v360).unwrap();
            r.crf = Some(0);
            convert(&r).unwrap();
            let filter = match options.starts_with("e:eac") {
                true => format!("format=yuv444p10le,v360={options},format={pix_fmt}"),
                false => format!("v360={options}"),
            };
            let ours = raw_frames_as(&out, None, pix_fmt);
            let theirs = raw_frames_as(&input, Some(&filter), pix_fmt);
            assert_eq!(ours.len(), theirs.len(), "{pix_fmt} {options}");
            // PSNR over the codes themselves: bytes, or 10-bit codes in 16-bit words.
            let db = if bytes == 1 {
                psnr(&ours, &theirs, max)
            } else {
                psnr_words(&ours, &theirs, max)
            };
            eprintln!("{pix_fmt}: --v360 {options}: {db:.1} dB against v360");
            assert!(
                db > 38.0,
                "{pix_fmt}: --v360 {options}: {db:.1} dB against v360"
            );
        }
    }
}

#[test]
fn ten_bit_stays_ten_bit() {
    let dir = tempfile::tempdir().unwrap();
    let input = source(dir.path(), "in10.mp4", "yuv420p10le");
    let out = dir.path().join("cube10.mp4");
    let mut r = request(&input, &out, "cube");
    r.convert.size = Some(64);
    convert(&r).unwrap();
    let (frames, _, _, pix) = video_facts(&out);
    assert_eq!((frames, pix.as_str()), (30, "yuv420p10le"));
}

/// `r` fails with `fault`, its message naming the input, and leaves the folder as it was.
fn refused(r: &VideoRequest, fault: Fault, words: &str) {
    let dir = Path::new(&r.convert.output).parent().unwrap().to_path_buf();
    let before = names_in(&dir);
    let e = convert(r).expect_err("refused");
    assert_eq!(e.fault, fault, "{e}");
    let message = e.to_string();
    assert!(message.contains(&r.convert.input), "{message}");
    assert!(message.contains(words), "{message}");
    assert_eq!(names_in(&dir), before, "no output or scratch file left");
}

#[test]
fn bad_inputs_are_refused_and_leave_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let input = source(d, "in.mp4", "yuv420p");
    let bytes = std::fs::read(&input).unwrap();
    let cut = d.join("cut.mp4");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    refused(
        &request(&cut, &d.join("o1.mp4"), "cube"),
        Fault::Input,
        "cannot be read",
    );
    let audio = d.join("audio.mp4");
    ffmpeg(&[
        "-f",
        "lavfi",
        "-i",
        "sine=duration=1",
        "-c:a",
        "aac",
        audio.to_str().unwrap(),
    ]);
    refused(
        &request(&audio, &d.join("o2.mp4"), "cube"),
        Fault::Input,
        "no video stream",
    );
    let odd = d.join("odd.mkv");
    ffmpeg(&[
        "-f",
        "lavfi",
        "-i",
        "testsrc2=size=256x128:rate=30:duration=0.2",
        "-vf",
        "scale=255:127",
        "-c:v",
        "ffv1",
        "-pix_fmt",
        "yuv420p",
        odd.to_str().unwrap(),
    ]);
    let mut r = request(&odd, &d.join("o3.mp4"), "cube");
    r.convert.input_plan.from = Some(ProjSpec::parse("latlong").unwrap());
    refused(&r, Fault::Input, "odd size");
}
