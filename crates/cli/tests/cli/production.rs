//! The sizes users bring: 4096×2048 and 8192×4096 HDRIs (made here from the bundled city
//! map, never committed) through `convert` into every kind of output, and read back.
use crate::util::{asset, ok, run, stdout};
use mirrorball_core::{resample, EnvMap, ProjectionKind, ResampleOptions};
use std::path::{Path, PathBuf};

/// `city.exr` grown to a `width`×`width/2` lat-long, written as a half-float ZIP EXR (the
/// common download) in `dir`.
fn big_source(dir: &Path, width: u32) -> PathBuf {
    let loaded = mirrorball_io::read(&asset("city.exr"), &Default::default()).unwrap();
    let mut src = EnvMap::new(ProjectionKind::LatLong.default_projection(), loaded.layers).unwrap();
    src.sanitize();
    let big = resample(&src, *src.projection(), width, &ResampleOptions::default());
    let path = dir.join(format!("city-{width}.exr"));
    mirrorball_io::write_image(&path, &big.layers()[0], &Default::default()).unwrap();
    path
}

/// log-PSNR of `test` against `reference`, from `compare --json`.
fn psnr(reference: &Path, test: &Path, test_from: Option<&str>) -> f64 {
    let mut args = vec![
        "compare",
        reference.to_str().unwrap(),
        test.to_str().unwrap(),
        "--json",
    ];
    if let Some(f) = test_from {
        args.extend(["--test-from", f]);
    }
    let o = run(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    v["log_psnr_db"].as_f64().unwrap_or(f64::INFINITY)
}

#[test]
fn a_4k_hdri_converts_to_every_kind_of_output_and_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let src = big_source(d, 4096);
    let s = src.to_str().unwrap();
    // The default cube of a 4096×2048 source: 1024² faces (a power of two).
    let cross = d.join("cross.exr");
    let e = ok(&["convert", s, cross.to_str().unwrap(), "--to", "cube"]);
    assert!(e.contains("cube 1024x1024 x6"), "{e}");
    assert!(psnr(&src, &cross, None) > 40.0);
    // One file a face, and a KTX2 cube with its chain, at 2048².
    let faces = d.join("f_{face}.exr");
    ok(&[
        "convert",
        s,
        faces.to_str().unwrap(),
        "--to",
        "cube",
        "--size",
        "2048",
        "-q",
    ]);
    let ktx = d.join("c.ktx2");
    ok(&[
        "convert",
        s,
        ktx.to_str().unwrap(),
        "--to",
        "cube",
        "--size",
        "2048",
        "--mips",
        "-q",
    ]);
    let info = ok(&["info", ktx.to_str().unwrap()]);
    assert!(info.contains("2048x2048"), "{info}");
    assert!(psnr(&src, &ktx, None) > 40.0);
    // A disk map and back to a lat-long of the source's size.
    let probe = d.join("probe.exr");
    ok(&[
        "convert",
        s,
        probe.to_str().unwrap(),
        "--to",
        "angular",
        "-q",
    ]);
    let back = d.join("back.exr");
    ok(&[
        "convert",
        probe.to_str().unwrap(),
        back.to_str().unwrap(),
        "--from",
        "angular",
        "--to",
        "latlong",
        "--size",
        "4096",
        "-q",
    ]);
    assert!(psnr(&src, &back, None) > 35.0);
}

#[test]
fn an_8k_hdri_converts_within_memory() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let src = big_source(d, 8192);
    let ktx = d.join("c.ktx2");
    ok(&[
        "convert",
        src.to_str().unwrap(),
        ktx.to_str().unwrap(),
        "--to",
        "cube",
        "--size",
        "2048",
        "--mips",
        "-q",
    ]);
    let loaded = mirrorball_io::read(&ktx, &Default::default()).unwrap();
    assert_eq!(loaded.layers.len(), 6);
    assert_eq!(loaded.layers[0].width(), 2048);
    assert!(psnr(&src, &ktx, None) > 40.0);
}
