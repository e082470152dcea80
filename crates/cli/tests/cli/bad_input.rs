//! Bad input: a clear message naming the file and the problem, a non-zero exit, no panic, no
//! output file left behind.
use crate::util::{asset, files, run, stderr};
use mirrorball_core::Image;

fn fails(args: &[&str], expect: &[&str]) -> String {
    let o = run(args);
    let e = stderr(&o);
    assert!(!o.status.success(), "mirrorball {args:?} should fail");
    assert!(!e.contains("panicked"), "panic: {e}");
    for s in expect {
        assert!(
            e.to_lowercase().contains(&s.to_lowercase()),
            "'{s}' not in: {e}"
        );
    }
    e
}

#[test]
fn missing_truncated_and_corrupt_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.exr");
    let o = out.to_str().unwrap();
    fails(
        &["convert", "no/such/file.exr", o, "--to", "cube"],
        &["no/such/file.exr", "no such file"],
    );
    let bytes = std::fs::read(asset("city.exr")).unwrap();
    let cut = dir.path().join("cut.exr");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    fails(
        &["convert", cut.to_str().unwrap(), o, "--to", "cube"],
        &["cut.exr"],
    );
    let junk = dir.path().join("junk.exr");
    std::fs::write(&junk, b"this is not an image at all, just text").unwrap();
    fails(
        &["convert", junk.to_str().unwrap(), o, "--to", "cube"],
        &["junk.exr"],
    );
    let junk_png = dir.path().join("junk.png");
    std::fs::write(&junk_png, [0u8; 100]).unwrap();
    fails(&["info", junk_png.to_str().unwrap()], &["junk.png"]);
    assert!(!out.exists());
}

/// DWAB (lossy, common in downloads) decodes: the shipped city-dwab.exr gives exactly the
/// texels of city.exr, which is the same data re-saved with ZIP.
#[test]
fn dwab_compressed_files_decode() {
    let a = mirrorball_io::read(&asset("city-dwab.exr"), &Default::default()).unwrap();
    let b = mirrorball_io::read(&asset("city.exr"), &Default::default()).unwrap();
    assert_eq!(a.layers, b.layers);
    assert!(a.description.contains("DWAB"), "{}", a.description);
}

#[test]
fn absurd_declared_size_is_refused_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let hdr = dir.path().join("huge.hdr");
    let mut bytes = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 40000 +X 40000\n".to_vec();
    bytes.extend_from_slice(&[1, 2, 3, 4]);
    std::fs::write(&hdr, bytes).unwrap();
    // 1.6 billion texels: refused from the header, long before 19 GB could be allocated.
    fails(&["info", hdr.to_str().unwrap()], &["huge.hdr"]);
}

#[test]
fn pictures_that_fit_no_layout_or_projection() {
    let dir = tempfile::tempdir().unwrap();
    let odd = dir.path().join("odd.exr");
    mirrorball_io::write_image(&odd, &Image::new(100, 60, 3), &Default::default()).unwrap();
    let out = dir.path().join("o.exr");
    fails(
        &[
            "convert",
            odd.to_str().unwrap(),
            out.to_str().unwrap(),
            "--to",
            "cube",
        ],
        &["odd.exr", "100x60", "--from"],
    );
    fails(
        &[
            "convert",
            odd.to_str().unwrap(),
            out.to_str().unwrap(),
            "--to",
            "latlong",
            "--from",
            "cube",
        ],
        &["odd.exr", "fits no layout"],
    );
    fails(
        &[
            "convert",
            odd.to_str().unwrap(),
            out.to_str().unwrap(),
            "--to",
            "cube",
            "--from",
            "latlong",
        ],
        &["odd.exr", "2:1"],
    );
    assert!(!out.exists());
}

#[test]
fn bad_requests_fail_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let src = asset("city.exr");
    let s = src.to_str().unwrap();
    let o = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    fails(
        &["convert", s, &o("a.exr"), "--to", "banana"],
        &["unknown projection", "latlong"],
    );
    fails(
        &["convert", s, &o("a.ktx2"), "--to", "sphere"],
        &["a.ktx2", "cube"],
    );
    fails(
        &["convert", s, &o("a.xyz"), "--to", "cube"],
        &["a.xyz", "extension"],
    );
    fails(
        &[
            "convert",
            s,
            &o("a.png"),
            "--to",
            "cube",
            "--precision",
            "float",
        ],
        &["a.png"],
    );
    fails(
        &["convert", s, &o("a.exr"), "--to", "cube", "--mips"],
        &["--mips"],
    );
    fails(
        &[
            "convert",
            s,
            &o("a.exr"),
            "--to",
            "fisheye:fov=400:lens=stereographic",
        ],
        // Names as the user spells them, not Rust's debug form ("Stereographic").
        &["--to: fisheye, stereographic lens: fov must be in (0°, 359.99964°]; fov=400 was given"],
    );
    fails(
        &["convert", s, &o("a.exr"), "--to", "cube", "--size", "0"],
        &["--size"],
    );
    fails(
        &["convert", s, "/no/such/dir/a.exr", "--to", "cube"],
        &["does not exist"],
    );
    assert!(files(dir.path()).is_empty());
}

#[test]
fn nan_inf_and_negative_texels_are_reported_and_fixed() {
    let dir = tempfile::tempdir().unwrap();
    let mut img = Image::new(64, 32, 3);
    img.data_mut().fill(0.5);
    img.set(3, 3, &[f32::NAN, 0.5, 0.5]);
    img.set(4, 3, &[f32::INFINITY, 0.5, 0.5]);
    img.set(5, 3, &[-1.0, -2.0, 0.5]); // two values of one texel
    let bad = dir.path().join("bad.exr");
    mirrorball_io::write_image(
        &bad,
        &img,
        &mirrorball_io::WriteOptions {
            precision: Some(mirrorball_io::Precision::Float),
            ..Default::default()
        },
    )
    .unwrap();
    let o = run(&["info", bad.to_str().unwrap()]);
    let out = String::from_utf8_lossy(&o.stdout);
    // Values, not texels, counted alike by info and convert.
    assert!(
        out.contains("1 NaN, 1 infinite, 2 negative colour values (4 in all"),
        "{out}"
    );
    let conv = dir.path().join("fixed.exr");
    let r = run(&[
        "convert",
        bad.to_str().unwrap(),
        conv.to_str().unwrap(),
        "--to",
        "cube",
        "--size",
        "16",
    ]);
    assert!(r.status.success());
    assert!(
        stderr(&r).contains("4 NaN, infinite or negative values set to 0"),
        "{}",
        stderr(&r)
    );
    let o = run(&["info", conv.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("0 NaN, 0 infinite, 0 negative"));
}

/// A face that cannot be put in place (a folder stands where its file would go) fails a
/// conversion to one file a face with a message naming it, and leaves no temporary files
/// (the faces that could be renamed into place are whole files).
#[test]
fn an_unwritable_face_is_named_and_leaves_no_temporary_files() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("face_py.exr")).unwrap();
    let pattern = dir.path().join("face_{face}.exr");
    let e = fails(
        &[
            "convert",
            asset("studio.exr").to_str().unwrap(),
            pattern.to_str().unwrap(),
            "--to",
            "cube",
            "--size",
            "16",
        ],
        &["face_py.exr"],
    );
    assert!(!e.contains("face_px.exr:"), "{e}");
    let left = files(dir.path());
    assert!(left.iter().all(|n| !n.contains(".tmp")), "{left:?}");
}

/// A dual fisheye's bad lens: the key and the problem, exit status 2 (the request), nothing
/// written.
#[test]
fn dual_fisheye_bad_lenses() {
    let dir = tempfile::tempdir().unwrap();
    let s = asset("city.exr");
    let s = s.to_str().unwrap();
    let out = dir.path().join("a.exr");
    let o = out.to_str().unwrap();
    for (spec, says) in [
        (
            "dfisheye:fov=400",
            &["fov=400", "must be in (0°, 360°]"][..],
        ),
        ("dfisheye:back-fov=0", &["back lens", "fov=0"]),
        ("dfisheye:fov=nan", &["'nan' is not a number"]),
        (
            "dfisheye:front=1.5,0.5,-0.5",
            &["front lens", "radius -0.5"],
        ),
        ("dfisheye:front=4,0.5,0.5", &["front lens", "outside"]),
        (
            "dfisheye:fov=220:k=0,-0.3",
            &["k=0,-0.3", "stops increasing"],
        ),
    ] {
        for args in [
            ["convert", s, o, "--to", spec, "--size", "64"],
            ["convert", s, o, "--from", spec, "--to", "latlong"],
        ] {
            let e = fails(&args, says);
            let code = run(&args).status.code();
            assert_eq!(code, Some(2), "{spec}: {e}");
        }
    }
    assert!(files(dir.path()).is_empty());
}

/// Stereo requests that cannot be met: refused by name with exit status 2, nothing written.
#[test]
fn bad_stereo_requests_name_the_file_and_the_size() {
    let dir = tempfile::tempdir().unwrap();
    let odd = dir.path().join("odd.exr");
    mirrorball_io::write_image(&odd, &Image::new(65, 32, 3), &Default::default()).unwrap();
    let odd = odd.to_str().unwrap();
    let tall = dir.path().join("tall.exr");
    mirrorball_io::write_image(&tall, &Image::new(64, 33, 3), &Default::default()).unwrap();
    let tall = tall.to_str().unwrap();
    let out = dir.path().join("out.exr");
    let o = out.to_str().unwrap();
    let ktx = dir.path().join("out.ktx2");
    let faces = dir.path().join("f_{face}.exr");
    for (args, says) in [
        (
            vec![
                "convert",
                odd,
                o,
                "--from",
                "latlong",
                "--in-stereo",
                "sbs",
                "--to",
                "latlong",
            ],
            vec!["odd.exr", "even width", "65x32"],
        ),
        (
            vec![
                "convert",
                tall,
                o,
                "--from",
                "latlong",
                "--in-stereo",
                "tb",
                "--to",
                "latlong",
            ],
            vec!["tall.exr", "even height", "64x33"],
        ),
        (
            vec![
                "convert",
                "-",
                o,
                "--in-size",
                "64x33",
                "--pix-fmt",
                "rgb24",
                "--in-stereo",
                "tb",
                "--to",
                "latlong",
            ],
            vec!["--in-size 64x33", "even height"],
        ),
        (
            vec!["convert", odd, o, "--in-stereo", "3d", "--to", "latlong"],
            vec!["--in-stereo", "unknown '3d'", "2d, sbs, tb"],
        ),
        (
            vec!["convert", odd, o, "--stereo", "left", "--to", "latlong"],
            vec!["--stereo", "unknown 'left'"],
        ),
        (
            vec![
                "convert",
                odd,
                ktx.to_str().unwrap(),
                "--from",
                "latlong",
                "--stereo",
                "sbs",
                "--to",
                "cube",
            ],
            vec!["out.ktx2", "one picture"],
        ),
        (
            vec![
                "convert",
                odd,
                faces.to_str().unwrap(),
                "--from",
                "latlong",
                "--stereo",
                "tb",
                "--to",
                "cube",
            ],
            vec!["f_{face}.exr", "one picture"],
        ),
    ] {
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        fails(&args, &says);
    }
    assert!(!out.exists() && !ktx.exists());
}
