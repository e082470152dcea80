//! Round trips through mirrorball's own files: every projection written into every container
//! that holds it is read back with no `--from`, by what the file records; and files tagged
//! as OpenEXR's tools tag environment maps are read in OpenEXR's conventions.

use crate::util::{asset, ok, run, stderr, stdout};
use mirrorball_core::glam::{DVec2, DVec3};
use mirrorball_core::projection::ProjectionSpec;
use mirrorball_core::{Image, LatLong, WorldProjection};
use std::f64::consts::PI;
use std::path::Path;

#[path = "../../../io/tests/io/imf_envmap.rs"]
mod imf_envmap;

/// Every projection, the disk maps with parameters other than their defaults, and the
/// `--size` to write it at.
const SPECS: [(&str, &str); 10] = [
    ("latlong", "64"),
    ("cube", "16"),
    ("sphere:look=+x", "48"),
    ("paraboloid:look=0,1,0", "32"),
    ("continuous-cube", "16"),
    ("mercator:max-lat=70", "64"),
    ("angular:look=-y", "48"),
    ("fisheye:fov=190:lens=equisolid:look=0,1,0", "48"),
    ("octahedral", "48"),
    ("equal-area-octahedral", "48"),
];

/// The log-PSNR `compare` prints, and whether it had to convert the test map.
fn compare(reference: &Path, test: &Path, extra: &[&str]) -> (f64, bool) {
    let mut args = vec![
        "compare",
        reference.to_str().unwrap(),
        test.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = run(&args);
    assert!(o.status.success(), "compare {args:?}: {}", stderr(&o));
    let s = stdout(&o);
    let db = s.split_whitespace().nth(1).unwrap().parse().unwrap();
    (db, s.contains("converted"))
}

/// A 128x64 lat-long PNG of a bundled map in `dir`: an LDR source, so that 8-bit PNG holds
/// what the other containers hold (up to its quantisation).
fn ldr_source(dir: &Path) -> std::path::PathBuf {
    let src = dir.join("src.png");
    ok(&[
        "convert",
        asset("city.exr").to_str().unwrap(),
        src.to_str().unwrap(),
        "--to",
        "latlong",
        "--size",
        "128",
        "-q",
    ]);
    src
}

#[test]
fn every_projection_reads_back_from_every_container_without_from() {
    let dir = tempfile::tempdir().unwrap();
    let src = ldr_source(dir.path());
    for (spec, size) in SPECS {
        let want = ProjectionSpec::parse(spec).unwrap().build(None).unwrap();
        let name = want.name();
        let mut containers = vec!["exr", "hdr", "png", "jpg"];
        if name == "cube" {
            containers.extend(["ktx2", "dds"]);
        }
        // The first output, in float, is what the others are compared with.
        let first = dir.path().join(format!("{name}-first.exr"));
        ok(&[
            "convert",
            src.to_str().unwrap(),
            first.to_str().unwrap(),
            "--to",
            spec,
            "--size",
            size,
            "--precision",
            "float",
            "-q",
        ]);
        for ext in containers {
            let out = dir.path().join(format!("{name}.{ext}"));
            ok(&[
                "convert",
                src.to_str().unwrap(),
                out.to_str().unwrap(),
                "--to",
                spec,
                "--size",
                size,
                "-q",
            ]);
            let o = run(&["info", out.to_str().unwrap(), "--json"]);
            assert!(o.status.success(), "{}", stderr(&o));
            let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
            assert_eq!(v["spec"], want.to_string(), "{name}.{ext}: {v}");
            let decided = v["decided"].as_str().unwrap();
            if ext == "dds" {
                // DDS has no place for the record; its cube flags make it a cube.
                assert!(decided.contains("six faces"), "{decided}");
            } else {
                assert!(
                    decided.contains("recorded in the file"),
                    "{name}.{ext}: {decided}"
                );
            }
            // Read back with no --from: the same projection and size as the first output
            // (nothing converted), equal up to the container's precision. Measured: JPEG
            // (quality 92) 37.0-37.9 dB, 8-bit PNG 60.5-60.9 dB, RGBE 66.8-68.2 dB, half
            // EXR/KTX2/DDS 86.3-87.9 dB.
            let (db, converted) = compare(&first, &out, &[]);
            assert!(!converted, "{name}.{ext} was not read as {want}");
            let floor = match ext {
                "jpg" => 34.0,
                "png" => 57.0,
                "hdr" => 63.0,
                _ => 80.0,
            };
            assert!(db > floor, "{name}.{ext}: {db:.2} dB");
        }
    }
}

#[test]
fn reading_a_recorded_map_as_another_projection_is_what_the_record_prevents() {
    // The control: the same file read as its shape suggests (1:1, a sphere map) scores far
    // lower than read by its record, so the round trip above can fail.
    let dir = tempfile::tempdir().unwrap();
    let src = ldr_source(dir.path());
    let (fisheye, png) = (dir.path().join("f.exr"), dir.path().join("f.png"));
    for out in [&fisheye, &png] {
        ok(&[
            "convert",
            src.to_str().unwrap(),
            out.to_str().unwrap(),
            "--to",
            "fisheye:fov=190:lens=equisolid:look=0,1,0",
            "--size",
            "64",
            "-q",
        ]);
    }
    let (right, _) = compare(&fisheye, &png, &[]);
    let (wrong, converted) = compare(&fisheye, &png, &["--test-from", "sphere"]);
    assert!(converted);
    // Measured: 60.9 dB by record, 6.9 dB as a sphere map.
    assert!(
        right > 55.0 && wrong < 20.0,
        "by record {right:.2} dB, as a sphere map {wrong:.2} dB"
    );
}

// ---------------------------------------------------------------------------------------
// OpenEXR's own conventions (`envmap` tag), through the command line. The pixel directions
// are a port of OpenEXR's src/lib/OpenEXR/ImfEnvmap.cpp (`LatLongMap::direction`,
// `CubeMap::direction` and `CubeMap::pixelPosition`), stored as (d + 1)/2.

/// `CubeMap::direction(face, …)` and `CubeMap::pixelPosition(face, …)` of the pixel at
/// `positionInFace` `(i, j)` of faces of edge `s`.
fn imf_cube_pixel(face: usize, s: u32, i: f64, j: f64) -> (DVec3, DVec2) {
    let pif = DVec2::new(i, j);
    (
        imf_envmap::imf_cube_direction(face, s, pif),
        imf_envmap::imf_cube_pixel_position(face, s, pif),
    )
}

fn coded(d: DVec3) -> [f32; 3] {
    let d = d.normalize();
    [
        (d.x as f32 + 1.0) / 2.0,
        (d.y as f32 + 1.0) / 2.0,
        (d.z as f32 + 1.0) / 2.0,
    ]
}

/// Converts `input` (with `extra` arguments) to a float lat-long `w`×`w/2` and returns, over
/// its texels, the worst and the median angle (in texels of height π/(w/2)) between the
/// direction each holds and mirrorball's direction for it, and what the command said.
fn latlong_direction_errors(
    dir: &Path,
    input: &Path,
    w: u32,
    extra: &[&str],
) -> (f64, f64, String) {
    let out = dir.join("decoded.exr");
    let size = w.to_string();
    let mut args = vec![
        "convert",
        input.to_str().unwrap(),
        out.to_str().unwrap(),
        "--to",
        "latlong",
        "--size",
        &size,
        "--precision",
        "float",
    ];
    args.extend_from_slice(extra);
    let said = ok(&args);
    let img = mirrorball_io::read(&out, &Default::default())
        .unwrap()
        .layers[0]
        .clone();
    let h = w / 2;
    let texel = PI / h as f64;
    let mut errors = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let t = img.get(x, y);
            let got = DVec3::new(
                2.0 * t[0] as f64 - 1.0,
                2.0 * t[1] as f64 - 1.0,
                2.0 * t[2] as f64 - 1.0,
            );
            let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
            let want = LatLong.uv_to_dir(0, uv).unwrap();
            errors.push(got.normalize().dot(want).clamp(-1.0, 1.0).acos() / texel);
        }
    }
    errors.sort_by(f64::total_cmp);
    (errors[errors.len() - 1], errors[errors.len() / 2], said)
}

#[test]
fn openexr_tagged_maps_are_read_in_openexr_conventions() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (64u32, 32u32);
    let mut ll = Image::new(w, h, 3);
    for y in 0..h {
        for x in 0..w {
            ll.set(
                x,
                y,
                &coded(imf_envmap::imf_latlong_direction(w, h, x as f64, y as f64)),
            );
        }
    }
    let path = dir.path().join("latlong.exr");
    imf_envmap::write_tagged(
        &path,
        &ll,
        exr::meta::attribute::EnvironmentMap::LatitudeLongitude,
    );
    // Measured: worst 0.006 texel, median 0.003.
    let (worst, median, said) = latlong_direction_errors(dir.path(), &path, w, &[]);
    assert!(said.contains("envmap=latlong"), "{said}");
    assert!(
        worst < 0.05,
        "lat-long: worst {worst:.3}, median {median:.3} texel"
    );
    // Read as mirrorball's lat-long (--from), the same picture is half a turn off.
    let (_, median, said) = latlong_direction_errors(dir.path(), &path, w, &["--from", "latlong"]);
    assert!(said.contains("not followed"), "{said}");
    assert!(
        median > 10.0,
        "as mirrorball's lat-long: median {median:.3} texel"
    );

    let s = 16u32;
    let mut strip = Image::new(s, 6 * s, 3);
    for face in 0..6 {
        for j in 0..s {
            for i in 0..s {
                let (d, p) = imf_cube_pixel(face, s, i as f64, j as f64);
                strip.set(p.x as u32, p.y as u32, &coded(d));
            }
        }
    }
    let path = dir.path().join("cube.exr");
    imf_envmap::write_tagged(&path, &strip, exr::meta::attribute::EnvironmentMap::Cube);
    // Measured: worst 0.14 texel (the resampler's antialiasing across the cube's edges),
    // median 0.018.
    let (worst, median, said) = latlong_direction_errors(dir.path(), &path, w, &[]);
    assert!(said.contains("envmap=cube"), "{said}");
    assert!(
        worst < 0.25 && median < 0.05,
        "cube: worst {worst:.3}, median {median:.3} texel"
    );
    // Read as OpenGL's vertical strip, it is far off.
    // (`--in-layout`: the input's; `--layout vstrip` is the output's, and a lat-long of one
    // layer is no strip: refused.)
    let asis = ["--from", "cube", "--in-layout", "vstrip"];
    let (_, median, _) = latlong_direction_errors(dir.path(), &path, w, &asis);
    assert!(median > 3.0, "as OpenGL's strip: median {median:.3} texel");
}

#[test]
fn an_unreadable_record_is_an_error_naming_the_file_and_from_overrides_it() {
    // A Radiance file by hand: a record this version cannot read, then 4x2 flat RGBE texels.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("odd.hdr");
    let mut bytes =
        b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nmirrorball:projection=banana:fov=3\n\n-Y 2 +X 4\n"
            .to_vec();
    bytes.extend(std::iter::repeat_n([128u8, 128, 128, 129], 8).flatten());
    std::fs::write(&path, bytes).unwrap();
    let o = run(&["info", path.to_str().unwrap()]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("odd.hdr") && e.contains("banana:fov=3") && e.contains("--from"),
        "{e}"
    );
    assert!(!e.contains("panicked"), "{e}");
    let said = ok(&["info", path.to_str().unwrap(), "--from", "latlong"]);
    assert!(said.contains("as asked"), "{said}");
}

/// One file a layer records the projection too: a continuous cube and a dual paraboloid
/// written as `{face}` sets read back as themselves (not as a plain cube) with no `--from`.
#[test]
fn sets_of_one_file_a_layer_read_back_by_their_record() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let src = ldr_source(d);
    for (spec, size) in [
        ("continuous-cube", "16"),
        ("paraboloid:look=0,1,0", "32"),
        ("cube", "16"),
    ] {
        let set = d.join(format!("{}_{{face}}.exr", spec.split(':').next().unwrap()));
        let packed = d.join(format!("{}.exr", spec.split(':').next().unwrap()));
        let (s, f, p) = (
            src.to_str().unwrap(),
            set.to_str().unwrap(),
            packed.to_str().unwrap(),
        );
        ok(&["convert", s, f, "--to", spec, "--size", size, "-q"]);
        ok(&["convert", s, p, "--to", spec, "--size", size, "-q"]);
        let info = ok(&["info", f]);
        assert!(info.contains("recorded in the files"), "{spec}: {info}");
        let (db, converted) = compare(&packed, &set, &[]);
        assert!(
            !converted && db > 80.0,
            "{spec}: {db} dB, converted {converted}"
        );
    }
}

/// A stereo pair mirrorball writes records its arrangement with the eye's layout
/// (`sbs/c3x2`): read back with no flag, `info` reports the left eye and says it is a pair,
/// and a conversion to a pair keeps both eyes where they were.
#[test]
fn a_stereo_pair_reads_back_by_its_record() {
    let d = tempfile::tempdir().unwrap();
    let pair = d.path().join("pair.exr");
    let again = d.path().join("again.exr");
    let (p, a) = (pair.to_str().unwrap(), again.to_str().unwrap());
    let city = asset("city.exr");
    ok(&[
        "convert",
        city.to_str().unwrap(),
        p,
        "--to",
        "cube",
        "--size",
        "16",
        "--layout",
        "c3x2",
        "--stereo",
        "sbs",
        "--yaw",
        "30",
        "-q",
    ]);
    let info = ok(&["info", p]);
    assert!(
        info.contains("sbs stereo pair") && info.contains("16x16 x 6"),
        "{info}"
    );
    ok(&[
        "convert", p, a, "--to", "cube", "--size", "16", "--layout", "c3x2", "--stereo", "sbs",
        "-q",
    ]);
    let (x, y) = (
        mirrorball_io::read(&pair, &Default::default()).unwrap(),
        mirrorball_io::read(&again, &Default::default()).unwrap(),
    );
    assert_eq!((y.layers[0].width(), y.layers[0].height()), (96, 32));
    let worst = x.layers[0]
        .data()
        .iter()
        .zip(y.layers[0].data())
        .map(|(a, b)| (a - b).abs() / (1.0 + a.abs()))
        .fold(0.0f32, f32::max);
    assert!(worst < 2e-3, "cube to the same cube moved texels: {worst}");
}
