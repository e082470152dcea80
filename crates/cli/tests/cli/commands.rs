//! The commands as a user runs them.
use crate::util::{asset, files, ok, run, stderr, stdout};
use mirrorball_core::glam::DVec3;
use mirrorball_core::metrics::log_psnr;
use mirrorball_core::{resample, EnvMap, ProjectionKind, ResampleOptions};

fn read_env(path: &std::path::Path, kind: ProjectionKind) -> EnvMap {
    let l = mirrorball_io::read(path, &Default::default()).unwrap();
    EnvMap::new(kind.default_projection(), l.layers).unwrap()
}

#[test]
fn convert_to_every_projection_and_back() {
    let dir = tempfile::tempdir().unwrap();
    let src = asset("city.exr");
    for kind in ProjectionKind::ALL {
        let out = dir.path().join(format!("{}.exr", kind.name()));
        let log = ok(&[
            "convert",
            src.to_str().unwrap(),
            out.to_str().unwrap(),
            "--to",
            kind.name(),
            "--size",
            "128",
        ]);
        assert!(log.contains("wrote"), "{log}");
        let back = dir.path().join(format!("{}-back.exr", kind.name()));
        // Read it back without saying what it is where the shape tells; say it otherwise.
        let mut args = vec![
            "convert",
            out.to_str().unwrap(),
            back.to_str().unwrap(),
            "--to",
            "latlong",
            "--size",
            "256",
        ];
        let from = match kind {
            ProjectionKind::LatLong | ProjectionKind::Cube => None,
            k => Some(k.name()),
        };
        if let Some(f) = from {
            args.extend(["--from", f]);
        }
        ok(&args);
        assert!(back.exists());
    }
    // Nothing but the outputs: no temporary files left behind.
    assert!(
        files(dir.path()).iter().all(|f| f.ends_with(".exr")),
        "{:?}",
        files(dir.path())
    );
}

#[test]
fn ktx2_and_dds_cubes_convert_back() {
    let dir = tempfile::tempdir().unwrap();
    let src = asset("venice.exr");
    let reference = read_env(&src, ProjectionKind::LatLong);
    for ext in ["ktx2", "dds"] {
        let cube = dir.path().join(format!("cube.{ext}"));
        ok(&[
            "convert",
            src.to_str().unwrap(),
            cube.to_str().unwrap(),
            "--to",
            "cube",
            "--size",
            "128",
            "--mips",
            "--precision",
            "float",
        ]);
        let info = ok(&["info", cube.to_str().unwrap()]);
        assert!(info.contains("cube") && info.contains("128x128"), "{info}");
        let back = dir.path().join(format!("back-{ext}.exr"));
        ok(&[
            "convert",
            cube.to_str().unwrap(),
            back.to_str().unwrap(),
            "--to",
            "latlong",
            "--size",
            "512",
            "--precision",
            "float",
        ]);
        let b = read_env(&back, ProjectionKind::LatLong);
        let mut r = reference.clone();
        r.sanitize();
        let psnr = log_psnr(&r, &b).unwrap();
        assert!(psnr > 35.0, "{ext}: {psnr}");
    }
}

#[test]
fn separate_faces_out_and_in() {
    let dir = tempfile::tempdir().unwrap();
    let pattern = dir.path().join("face_{face}.exr");
    ok(&[
        "convert",
        asset("studio.exr").to_str().unwrap(),
        pattern.to_str().unwrap(),
        "--to",
        "cube",
        "--size",
        "32",
    ]);
    for f in ["px", "nx", "py", "ny", "pz", "nz"] {
        assert!(dir.path().join(format!("face_{f}.exr")).exists());
    }
    // Each face is written while the next is converted: every file holds its own face, to
    // the bit, as the library makes it, with no temporary file left over.
    let exact = dir.path().join("exact_{face}.exr");
    let exact = exact.to_str().unwrap();
    ok(&[
        "convert",
        asset("studio.exr").to_str().unwrap(),
        exact,
        "--to",
        "cube",
        "--size",
        "24",
        "--precision",
        "float",
    ]);
    let mut src = read_env(&asset("studio.exr"), ProjectionKind::LatLong);
    src.sanitize();
    let cube = ProjectionKind::Cube.default_projection();
    let want = resample(&src, cube, 24, &ResampleOptions::default());
    for (f, layer) in ["px", "nx", "py", "ny", "pz", "nz"]
        .iter()
        .zip(want.layers())
    {
        let got = mirrorball_io::read(
            std::path::Path::new(&exact.replace("{face}", f)),
            &Default::default(),
        )
        .unwrap();
        assert_eq!(got.layers[0].data(), layer.data(), "face {f}");
    }
    assert!(
        files(dir.path()).iter().all(|n| !n.contains(".tmp")),
        "{:?}",
        files(dir.path())
    );
    let cross = dir.path().join("cross.exr");
    ok(&[
        "convert",
        pattern.to_str().unwrap(),
        cross.to_str().unwrap(),
        "--to",
        "cube",
        "--layout",
        "vcross",
    ]);
    let l = mirrorball_io::read(&cross, &Default::default()).unwrap();
    assert_eq!((l.layers[0].width(), l.layers[0].height()), (96, 128));
}

#[test]
fn orientation_conventions_round_trip() {
    // Each convention option, applied going out and again coming back, is the identity;
    // applied once, it really changes the map.
    let dir = tempfile::tempdir().unwrap();
    let src = asset("city.exr");
    let reference = {
        let mut e = read_env(&src, ProjectionKind::LatLong);
        e.sanitize();
        e
    };
    for flags in [
        vec!["--flip", "z"],
        vec!["--flip", "x"],
        vec!["--flip", "y"],
        vec!["--yaw", "90"],
    ] {
        let cube = dir.path().join("c.exr");
        let back = dir.path().join("b.exr");
        let mut a = vec![
            "convert",
            src.to_str().unwrap(),
            cube.to_str().unwrap(),
            "--to",
            "cube",
            "--size",
            "256",
            "--precision",
            "float",
        ];
        a.extend(flags.iter());
        ok(&a);
        // Undo: mirrors are their own inverse; a yaw is undone by the opposite yaw.
        let undo: Vec<&str> = if flags[0] == "--yaw" {
            vec!["--yaw", "-90"]
        } else {
            flags.clone()
        };
        let mut b = vec![
            "convert",
            cube.to_str().unwrap(),
            back.to_str().unwrap(),
            "--to",
            "latlong",
            "--size",
            "512",
            "--precision",
            "float",
        ];
        b.extend(undo.iter());
        ok(&b);
        let psnr = log_psnr(&reference, &read_env(&back, ProjectionKind::LatLong)).unwrap();
        assert!(psnr > 38.0, "{flags:?}: {psnr}");
        // Only one way: clearly different.
        let once = dir.path().join("once.exr");
        let mut c = vec![
            "convert",
            cube.to_str().unwrap(),
            once.to_str().unwrap(),
            "--to",
            "latlong",
            "--size",
            "512",
            "--precision",
            "float",
        ];
        c.extend(["--yaw", "0"]);
        ok(&c);
        let psnr_once = log_psnr(&reference, &read_env(&once, ProjectionKind::LatLong)).unwrap();
        assert!(
            psnr_once < 30.0,
            "{flags:?} should change the map: {psnr_once}"
        );
    }
}

#[test]
fn info_reports_guess_stats_and_json() {
    let out = ok(&["info", asset("sky.exr").to_str().unwrap()]);
    assert!(out.contains("latlong") && out.contains("guessed"), "{out}");
    assert!(out.contains("512x256"), "{out}");
    let o = run(&["info", asset("city.exr").to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("valid JSON");
    assert_eq!(v["projection"], "latlong");
    assert!((v["solid_angle_sr"].as_f64().unwrap() - 4.0 * std::f64::consts::PI).abs() < 1e-6);
    // The bundled map's negative values, as many as convert reports setting to 0.
    let negative = v["negative_values"].as_u64().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("c.exr");
    let e = ok(&[
        "convert",
        asset("city.exr").to_str().unwrap(),
        out.to_str().unwrap(),
        "--to",
        "cube",
        "--size",
        "8",
    ]);
    assert!(
        negative > 0 && e.contains(&format!("{negative} NaN, infinite or negative values")),
        "{negative}: {e}"
    );
}

#[test]
fn compare_prints_psnr() {
    let dir = tempfile::tempdir().unwrap();
    let cube = dir.path().join("c.exr");
    ok(&[
        "convert",
        asset("city.exr").to_str().unwrap(),
        cube.to_str().unwrap(),
        "--to",
        "cube",
        "--size",
        "128",
    ]);
    let o = run(&[
        "compare",
        asset("city.exr").to_str().unwrap(),
        cube.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = stdout(&o);
    let db: f64 = s.split_whitespace().nth(1).unwrap().parse().unwrap();
    assert!(db > 35.0 && db < 100.0, "{s}");
}

#[test]
fn demo_writes_every_projection() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("demo");
    let log = ok(&["demo", "--out", out.to_str().unwrap(), "--size", "128"]);
    for kind in ProjectionKind::ALL {
        assert!(out.join(format!("{}.png", kind.name())).exists(), "{log}");
        assert!(out.join(format!("{}.exr", kind.name())).exists());
    }
    assert!(out.join("cube.ktx2").exists() && out.join("cube.dds").exists());
    assert!(out.join("index.html").exists());
}

/// A converted map samples like its source in every direction (direction conventions agree
/// end to end through the files).
#[test]
fn converted_cube_samples_like_its_source() {
    let dir = tempfile::tempdir().unwrap();
    let src = read_env(&asset("city.exr"), ProjectionKind::LatLong);
    let cube_path = dir.path().join("c.ktx2");
    ok(&[
        "convert",
        asset("city.exr").to_str().unwrap(),
        cube_path.to_str().unwrap(),
        "--to",
        "cube",
        "--size",
        "256",
        "--precision",
        "float",
    ]);
    let cube = EnvMap::new(
        ProjectionKind::Cube.default_projection(),
        mirrorball_io::read(&cube_path, &Default::default())
            .unwrap()
            .layers,
    )
    .unwrap();
    let smooth_src = resample(&src, *src.projection(), 128, &ResampleOptions::default());
    let smooth_cube = resample(&cube, *src.projection(), 128, &ResampleOptions::default());
    for d in [
        DVec3::X,
        DVec3::NEG_X,
        DVec3::Y,
        DVec3::NEG_Y,
        DVec3::Z,
        DVec3::NEG_Z,
        DVec3::new(0.3, 0.4, -0.8).normalize(),
    ] {
        let (a, b) = (smooth_src.sample(d), smooth_cube.sample(d));
        for c in 0..3 {
            let rel = (a[c] - b[c]).abs() / a[c].abs().max(1e-3);
            assert!(rel < 0.1, "{d}: {a:?} vs {b:?}");
        }
    }
}

#[test]
fn exr_outputs_record_their_projection() {
    // Recorded in mirrorball's attributes; no OpenEXR `envmap` tag, whose lat-long and cube
    // conventions are not mirrorball's.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ll.exr");
    ok(&[
        "convert",
        asset("city.exr").to_str().unwrap(),
        out.to_str().unwrap(),
        "--to",
        "latlong",
        "--size",
        "64",
    ]);
    let l = mirrorball_io::read(&out, &Default::default()).unwrap();
    assert_eq!(l.declared, None);
    let info = l.recorded.unwrap().unwrap();
    assert_eq!(info.projection.kind(), ProjectionKind::LatLong);
    let cube = dir.path().join("c.exr");
    ok(&[
        "convert",
        asset("city.exr").to_str().unwrap(),
        cube.to_str().unwrap(),
        "--to",
        "cube",
        "--size",
        "16",
    ]);
    let l = mirrorball_io::read(&cube, &Default::default()).unwrap();
    assert_eq!(l.declared, None);
    let info = l.recorded.unwrap().unwrap();
    assert_eq!(info.projection.kind(), ProjectionKind::Cube);
    assert_eq!(info.layout, Some(mirrorball_core::Layout::HorizontalCross));
}

/// `compare` scores what both maps cover (a 180° fisheye: half the sphere), says so in its
/// JSON, and draws where they differ in the reference's projection.
#[test]
fn compare_scores_the_common_coverage_with_json_and_a_difference_picture() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let city = asset("city.exr");
    let c = city.to_str().unwrap();
    let fe = d.join("fe.exr");
    let f = fe.to_str().unwrap();
    ok(&[
        "convert",
        c,
        f,
        "--to",
        "fisheye:fov=180",
        "--size",
        "256",
        "-q",
    ]);
    let diff = d.join("diff.png");
    let o = run(&[
        "compare",
        c,
        f,
        "--test-from",
        "fisheye:fov=180",
        "--json",
        "--diff",
        diff.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("valid JSON");
    assert!(
        (v["compared_fraction_of_sphere"].as_f64().unwrap() - 0.5).abs() < 1e-3,
        "{v}"
    );
    // Over the half it covers the fisheye is close; counted over the whole sphere, the
    // uncovered half (black) would drag it far down.
    let psnr = v["log_psnr_db"].as_f64().unwrap();
    assert!(psnr > 35.0, "{v}");
    let picture = mirrorball_io::read(&diff, &Default::default()).unwrap();
    assert_eq!(
        (picture.layers[0].width(), picture.layers[0].height()),
        (512, 256)
    );
    // A map against itself: no difference anywhere, an all-black picture.
    let same = d.join("same.exr");
    let o = run(&["compare", c, c, "--json", "--diff", same.to_str().unwrap()]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("valid JSON");
    assert_eq!(v["log_psnr_db"], "inf");
    assert!((v["compared_fraction_of_sphere"].as_f64().unwrap() - 1.0).abs() < 1e-9);
    let zero = mirrorball_io::read(&same, &Default::default()).unwrap();
    assert!(zero.layers[0].data().iter().all(|&x| x == 0.0));
    // The difference picture may not replace an input.
    let o = run(&["compare", c, f, "--diff", c]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// A fisheye's corners are black by default (as v360 leaves them), the rim's value with
/// `--outside rim`; a sphere map's are the rim's by default; a name that is no choice is
/// refused with the choices, before any file is written.
#[test]
fn outside_the_circle_is_black_or_the_rim() {
    let dir = tempfile::tempdir().unwrap();
    let src = asset("venice.exr");
    let corner = |to: &str, extra: &[&str]| {
        let out = dir.path().join("out.exr");
        let mut args = vec!["convert", src.to_str().unwrap(), out.to_str().unwrap()];
        args.extend(["--to", to, "--size", "64", "--quiet"]);
        args.extend(extra);
        ok(&args);
        let map = mirrorball_io::read(&out, &Default::default()).unwrap();
        let img = &map.layers[0];
        (img.get(0, 0)[..3].to_vec(), img.get(32, 32)[..3].to_vec())
    };
    let (c, centre) = corner("fisheye", &[]);
    assert_eq!(c, [0.0; 3]);
    assert!(centre.iter().any(|v| *v > 0.0));
    let (c, _) = corner("fisheye", &["--outside", "rim"]);
    assert!(c.iter().any(|v| *v > 0.0), "{c:?}");
    let (c, _) = corner("sphere", &[]);
    assert!(c.iter().any(|v| *v > 0.0), "{c:?}");
    let (c, _) = corner("sphere", &["--outside", "black"]);
    assert_eq!(c, [0.0; 3]);
    let out = dir.path().join("bad.exr");
    let o = run(&[
        "convert",
        src.to_str().unwrap(),
        out.to_str().unwrap(),
        "--to",
        "fisheye",
        "--outside",
        "purple",
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("black") && stderr(&o).contains("rim"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
}

/// `--size WxH` (v360's `w` and `h`): a flat view of exactly that size, its vfov from the
/// height (square pixels: the corners' directions agree with the fields of view); a
/// projection whose height the width fixes takes its own height only; the vfov and a height
/// together, a height without --to, and a half-given size are refused before any work.
#[test]
fn size_takes_a_width_and_height() {
    let dir = tempfile::tempdir().unwrap();
    let src = asset("venice.exr");
    let out = dir.path().join("view.exr");
    let convert = |to: &str, size: &str| {
        run(&[
            "convert",
            src.to_str().unwrap(),
            out.to_str().unwrap(),
            "--to",
            to,
            "--size",
            size,
            "--quiet",
        ])
    };
    for (to, size, want) in [
        ("flat", "1280x720", (1280, 720)),
        ("flat:hfov=100", "1280x739", (1280, 739)),
        ("cube", "32x32", (32, 32)),
        ("latlong", "64x32", (64, 32)),
    ] {
        let o = convert(to, size);
        assert!(o.status.success(), "{to} {size}: {}", stderr(&o));
        let map = mirrorball_io::read(&out, &Default::default()).unwrap();
        let img = &map.layers[0];
        let got = if to == "cube" {
            (img.width() / 4, img.height() / 3)
        } else {
            (img.width(), img.height())
        };
        assert_eq!(got, want, "{to} {size}");
        std::fs::remove_file(&out).unwrap();
    }
    // Square pixels: the view's vertical field of view is the one whose tangent is the
    // horizontal one's scaled by the aspect.
    let spec = mirrorball_core::projection::ProjectionSpec::parse("flat")
        .unwrap()
        .with_height(1280, 720)
        .unwrap();
    let view = spec.build(None).unwrap();
    use mirrorball_core::WorldProjection;
    let top = view
        .uv_to_dir(0, mirrorball_core::glam::DVec2::new(0.5, 0.0))
        .unwrap();
    let right = view
        .uv_to_dir(0, mirrorball_core::glam::DVec2::new(1.0, 0.5))
        .unwrap();
    let (tv, th) = (top.y / -top.z, right.x / -right.z);
    assert!((tv / th - 720.0 / 1280.0).abs() < 1e-9, "{tv} {th}");
    for (to, size, says) in [
        ("flat:vfov=60", "1280x720", "not both"),
        ("latlong", "64x40", "64x32"),
        ("cube", "32x16", "32x32"),
        ("flat", "1280x", "whole number"),
        ("flat", "0x720", "positive"),
    ] {
        let o = convert(to, size);
        assert!(!o.status.success(), "{to} {size}");
        assert!(stderr(&o).contains(says), "{to} {size}: {}", stderr(&o));
        assert!(!out.exists());
    }
}
