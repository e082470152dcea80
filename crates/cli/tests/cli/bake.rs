//! `mirrorball bake`: every engine written here end to end on a small map, `--for list`,
//! each bad request (exit 2, its message, nothing written) and a failed write (nothing
//! left).

use crate::util::{files, ok, run, stderr, stdout};
use mirrorball_bake::{BakeOptions, Engine, ENGINES};
use std::path::{Path, PathBuf};

/// A direction-coded lat-long EXR (`½ + ½·d`), optionally with one negative texel.
fn input(dir: &Path, name: &str, negative: bool) -> PathBuf {
    let mut env = mirrorball_bake::direction_coded(64);
    if negative {
        env.layers_mut()[0].data_mut()[0] = -0.5;
    }
    let path = dir.join(name);
    mirrorball_io::write_image(
        &path,
        &env.layers()[0],
        &mirrorball_io::WriteOptions {
            precision: Some(mirrorball_io::Precision::Float),
            ..Default::default()
        },
    )
    .unwrap();
    path
}

/// The engines whose writers are in this build.
fn written() -> Vec<Engine> {
    ENGINES
        .into_iter()
        .filter(|e| !e.describe().encodings.is_empty())
        .collect()
}

#[test]
fn every_engine_bakes_end_to_end() {
    let dir = tempfile::tempdir().unwrap();
    let src = input(dir.path(), "sky.exr", false);
    let engines = written();
    assert_eq!(engines.len(), ENGINES.len(), "every engine is written");
    for engine in engines {
        let out = dir.path().join(engine.to_string());
        let said = ok(&[
            "bake",
            src.to_str().unwrap(),
            "--for",
            &engine.to_string(),
            out.to_str().unwrap(),
            "--size",
            "16",
        ]);
        assert!(said.contains(&format!("for {engine}")), "{said}");
        let opts = BakeOptions {
            size: 16,
            source: src.display().to_string(),
            ..Default::default()
        };
        let mut want = engine.file_names(&opts);
        want.push("README.md".into());
        want.sort();
        let made: Vec<String> = files(&out)
            .into_iter()
            .filter(|f| !f.ends_with('/'))
            .collect();
        assert_eq!(made, want, "{engine}");
        let readme = std::fs::read_to_string(out.join("README.md")).unwrap();
        assert!(readme.contains("## Loading it"), "{engine}: {readme}");
        // Cube files are cubes with their chain (mirrorball's reader: level 0).
        for f in &want {
            if f.ends_with(".ktx2") || f.ends_with(".dds") {
                let back =
                    mirrorball_io::read(&out.join(f), &mirrorball_io::Limits::default()).unwrap();
                assert_eq!(back.layers.len(), 6, "{engine}: {f}");
            }
        }
    }
    // KTX2 is supercompressed by default where the engine reads it; --no-zstd turns it off.
    let plain = dir.path().join("plain");
    ok(&[
        "bake",
        src.to_str().unwrap(),
        "--for",
        "ktx2",
        plain.to_str().unwrap(),
        "--size",
        "16",
        "--no-zstd",
        "-q",
    ]);
    let scheme =
        |p: &Path| u32::from_le_bytes(std::fs::read(p).unwrap()[44..48].try_into().unwrap());
    assert_eq!(
        scheme(&dir.path().join("ktx2/specular.ktx2")),
        2,
        "Zstandard"
    );
    assert_eq!(scheme(&plain.join("specular.ktx2")), 0, "none");
}

#[test]
fn list_prints_what_each_engine_writes() {
    let o = run(&["bake", "--for", "list"]);
    assert!(o.status.success());
    let text = stdout(&o);
    for e in ENGINES {
        assert!(text.contains(&format!("{e}\n")), "{e}");
        let d = e.describe();
        if !d.encodings.is_empty() {
            for part in [d.files, d.containers, d.convention, d.rule, d.diffuse] {
                assert!(text.contains(part), "{e}: {part}");
            }
            assert!(text.contains(&e.orientation().to_string()), "{e}");
        }
    }
}

/// Runs a request that must be refused: exit 2, `message` in stderr, `dir` unchanged.
fn refused(dir: &Path, args: &[&str], message: &str) {
    let before = files(dir);
    let o = run(args);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
    assert!(stderr(&o).contains(message), "{args:?}: {}", stderr(&o));
    assert_eq!(files(dir), before, "{args:?} left files");
}

#[test]
fn bad_requests_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let src = input(dir.path(), "sky.exr", false);
    let negative = input(dir.path(), "neg.exr", true);
    let (s, n) = (src.to_str().unwrap(), negative.to_str().unwrap());
    let out = dir.path().join("out");
    let o = out.to_str().unwrap();
    let d = dir.path();
    refused(
        d,
        &["bake", s, "--for", "blender", o],
        "--for: unknown 'blender' (bevy, three",
    );
    refused(
        d,
        &["bake", s, "--for", "ktx2", o, "--size", "100"],
        "power of two",
    );
    refused(
        d,
        &["bake", s, "--for", "ktx2", o, "--size", "32768"],
        "power of two",
    );
    refused(
        d,
        &["bake", s, "--for", "filament", o, "--encoding", "bc6h"],
        "filament does not load bc6h",
    );
    refused(
        d,
        &["bake", s, "--for", "unity", o, "--zstd", "5"],
        "Zstandard",
    );
    refused(
        d,
        &["bake", s, "--for", "ktx2", o, "--zstd", "30"],
        "--zstd: 30",
    );
    refused(
        d,
        &["bake", s, "--for", "ktx2", o, "--encoding", "jpeg"],
        "--encoding: unknown 'jpeg'",
    );
    refused(
        d,
        &["bake", s, "--for", "ktx2"],
        "needs the input map and the output folder",
    );
    refused(
        d,
        &["bake", s, "--for", "ktx2", o, "--mapping", "0,0.5,1"],
        "3 roughness values but the chain of 256 has 9 levels",
    );
    // BC6H unsigned of a map with negative values (kept): refused after reading, before
    // prefiltering.
    refused(
        d,
        &["bake", n, "--for", "unreal", o, "--keep-invalid"],
        "negative or NaN, which unsigned BC6H cannot hold",
    );
    // Careless names: the input as OUT-DIR, another file, a folder in a missing folder.
    refused(d, &["bake", s, "--for", "ktx2", s], "OUT-DIR is a file");
    let missing = dir.path().join("no/such/out");
    refused(
        d,
        &["bake", s, "--for", "ktx2", missing.to_str().unwrap()],
        "does not exist",
    );
    // An input inside OUT-DIR under a name the bake writes.
    let inside = dir.path().join("inside");
    std::fs::create_dir(&inside).unwrap();
    std::fs::copy(&src, inside.join("sh.json")).unwrap();
    refused(
        &inside,
        &[
            "bake",
            inside.join("sh.json").to_str().unwrap(),
            "--from",
            "latlong",
            "--for",
            "ktx2",
            inside.to_str().unwrap(),
        ],
        "would overwrite the input",
    );
    // A folder where a file goes.
    std::fs::create_dir(inside.join("diffuse.ktx2")).unwrap();
    refused(
        &inside,
        &["bake", s, "--for", "ktx2", inside.to_str().unwrap()],
        "a folder is where",
    );
}

#[cfg(unix)]
#[test]
fn a_failed_write_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let src = input(dir.path(), "sky.exr", false);
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    // The last file written through a link into a folder that does not exist: the cubes
    // before it are written beside their names, then the set is dropped.
    std::os::unix::fs::symlink(dir.path().join("gone/sh.json"), out.join("sh.json")).unwrap();
    let o = run(&[
        "bake",
        src.to_str().unwrap(),
        "--for",
        "ktx2",
        out.to_str().unwrap(),
        "--size",
        "16",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("sh.json"), "{}", stderr(&o));
    assert_eq!(files(&out), ["sh.json"], "only the link it found");
}

/// `convert --for`: a cube turned exactly as the engine's module says (texels moved, the
/// same bits as turning the plain conversion), any other projection by the same map as a
/// rotation (the same as the --flip it is, for three.js).
#[test]
fn convert_for_an_engine_turns_the_map_its_way() {
    use mirrorball_core::{EnvMap, ProjectionKind};
    let dir = tempfile::tempdir().unwrap();
    let src = input(dir.path(), "sky.exr", false);
    let s = src.to_str().unwrap();
    let cube = ProjectionKind::Cube.default_projection();
    let read = |p: &Path| {
        let l = mirrorball_io::read(p, &mirrorball_io::Limits::default()).unwrap();
        EnvMap::new(cube, l.layers).unwrap()
    };
    let plain = dir.path().join("plain.ktx2");
    ok(&[
        "convert",
        s,
        plain.to_str().unwrap(),
        "--to",
        "cube",
        "--size",
        "16",
        "--precision",
        "float",
        "-q",
    ]);
    for engine in [Engine::Unreal, Engine::Unity, Engine::Three] {
        let turned = dir.path().join(format!("{engine}.ktx2"));
        ok(&[
            "convert",
            s,
            turned.to_str().unwrap(),
            "--to",
            "cube",
            "--size",
            "16",
            "--precision",
            "float",
            "--for",
            &engine.to_string(),
            "-q",
        ]);
        let want = read(&plain).transformed(&engine.orientation()).unwrap();
        assert_eq!(read(&turned), want, "{engine}");
        assert_ne!(read(&turned), read(&plain), "{engine}");
    }
    let (a, b) = (dir.path().join("a.exr"), dir.path().join("b.exr"));
    ok(&[
        "convert",
        s,
        a.to_str().unwrap(),
        "--to",
        "latlong",
        "--size",
        "64",
        "--for",
        "three",
        "-q",
    ]);
    ok(&[
        "convert",
        s,
        b.to_str().unwrap(),
        "--to",
        "latlong",
        "--size",
        "64",
        "--flip",
        "x",
        "-q",
    ]);
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let o = run(&[
        "convert",
        s,
        a.to_str().unwrap(),
        "--to",
        "latlong",
        "--for",
        "maya",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("--for: unknown 'maya'"),
        "{}",
        stderr(&o)
    );
}
