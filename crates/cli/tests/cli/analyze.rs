//! `mirrorball analyze`.
use crate::util::{files, ok, run, stderr};

#[test]
fn analyze_writes_a_report() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    let log = ok(&["analyze", "--out", out.to_str().unwrap(), "--size", "64"]);
    assert!(log.contains("wrote"), "{log}");
    let names = files(&out);
    for f in [
        "index.html",
        "report.json",
        "analysis-solid-angle-heatmaps.svg",
        "analysis-zimmons-1d.svg",
        "analysis-anisotropy-heatmaps.svg",
        "analysis-reflection-cone.svg",
        "analysis-indexing-line.svg",
        "analysis-indexing-meshes.svg",
        "analysis-rims.svg",
    ] {
        assert!(names.iter().any(|n| n == f), "{f} missing from {names:?}");
    }
    // Nothing half-written left behind.
    assert!(names.iter().all(|n| !n.ends_with(".tmp")), "{names:?}");
    let json = std::fs::read_to_string(out.join("report.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&json).expect("report.json parses");
    let projections = v["projections"].as_array().unwrap();
    assert_eq!(
        projections.len(),
        mirrorball_core::ProjectionKind::ALL.len()
    );
    assert_eq!(v["sizing"]["mode"], "size");
    assert_eq!(projections[1]["stats"]["width"], 64); // the cube, edge 64
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(html.contains("<svg"));
}

#[test]
fn analyze_one_projection_and_reject_bad_requests() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r");
    ok(&[
        "analyze",
        "--projection",
        "fisheye:fov=220",
        "--texel-budget",
        "4096",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(v["projections"].as_array().unwrap().len(), 1);
    assert_eq!(v["projections"][0]["stats"]["width"], 64);

    let o = run(&[
        "analyze",
        "--projection",
        "banana",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("--projection") && stderr(&o).contains("banana"),
        "{}",
        stderr(&o)
    );
    let o = run(&["analyze", "--size", "0", "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--size"), "{}", stderr(&o));
    let o = run(&[
        "analyze",
        "--size",
        "8",
        "--texel-budget",
        "9",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let file = dir.path().join("plain-file");
    std::fs::write(&file, b"x").unwrap();
    let o = run(&["analyze", "--size", "8", "--out", file.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("not a folder"), "{}", stderr(&o));
}
