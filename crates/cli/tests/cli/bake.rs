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
        want.extend(["README.md".into(), mirrorball_io::RECORD.into()]);
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
        "--size 32768: outside 1..=16384",
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
    // The last file written through a link into a folder that does not exist (the bake
    // told to replace it): the cubes before it are written beside their names, then the
    // set is dropped.
    std::os::unix::fs::symlink(dir.path().join("gone/sh.json"), out.join("sh.json")).unwrap();
    let o = run(&[
        "bake",
        src.to_str().unwrap(),
        "--for",
        "ktx2",
        out.to_str().unwrap(),
        "--size",
        "16",
        "--overwrite",
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

/// `bake` of `src` for `engine` into `out` at size 16, with `extra` flags.
fn bake_into(src: &Path, engine: Engine, out: &Path, extra: &[&str]) -> std::process::Output {
    let engine = engine.to_string();
    let mut args = vec![
        "bake",
        src.to_str().unwrap(),
        "--for",
        &engine,
        out.to_str().unwrap(),
        "--size",
        "16",
    ];
    args.extend(extra);
    run(&args)
}

/// What a bake for `engine` leaves in its folder: its files, the README, the record, and
/// a folder entry for each of its folders (as `files` lists them).
fn bake_listing(engine: Engine) -> Vec<String> {
    let mut want: Vec<String> = engine
        .file_names(&BakeOptions {
            size: 16,
            ..Default::default()
        })
        .into_iter()
        .chain(["README.md".into(), mirrorball_io::RECORD.into()])
        .collect();
    let folders: Vec<String> = want
        .iter()
        .filter_map(|f| f.split_once('/').map(|(d, _)| format!("{d}/")))
        .collect();
    want.extend(folders);
    want.sort();
    want.dedup();
    want
}

#[test]
fn every_engine_refuses_files_no_bake_wrote_unless_told() {
    let dir = tempfile::tempdir().unwrap();
    let src = input(dir.path(), "sky.exr", false);
    for engine in ENGINES {
        let out = dir.path().join(format!("{engine}"));
        std::fs::create_dir(&out).unwrap();
        std::fs::write(out.join("README.md"), "my notes").unwrap();
        std::fs::write(out.join("notes.txt"), "mine").unwrap();
        // The user's README, then a file of the engine's own name the user made: each
        // refused by name before any work, nothing written, exit 2.
        let own = engine.file_names(&BakeOptions::default())[0].clone();
        for (made, named) in [(None, "README.md"), (Some(&own), own.as_str())] {
            if let Some(f) = made {
                let p = out.join(f);
                std::fs::create_dir_all(p.parent().unwrap()).unwrap();
                std::fs::write(&p, "mine too").unwrap();
            }
            let before = files(&out);
            let o = bake_into(&src, engine, &out, &[]);
            let e = stderr(&o);
            assert_eq!(o.status.code(), Some(2), "{engine}: {e}");
            assert!(
                e.contains(&out.join(named).display().to_string()) && e.contains("--overwrite"),
                "{engine}: {e}"
            );
            assert!(
                !e.contains("prefilter"),
                "{engine}: refused before any work: {e}"
            );
            assert_eq!(files(&out), before, "{engine}");
        }
        // Told to: they are replaced, the other file is left alone; a bake again is its own.
        let o = bake_into(&src, engine, &out, &["--overwrite", "-q"]);
        assert!(o.status.success(), "{engine}: {}", stderr(&o));
        assert_ne!(std::fs::read(out.join("README.md")).unwrap(), b"my notes");
        assert_ne!(std::fs::read(out.join(&own)).unwrap(), b"mine too");
        assert_eq!(std::fs::read(out.join("notes.txt")).unwrap(), b"mine");
        let o = bake_into(&src, engine, &out, &["-q"]);
        assert!(o.status.success(), "{engine} again: {}", stderr(&o));
        let mut want = bake_listing(engine);
        want.push("notes.txt".into());
        want.sort();
        assert_eq!(files(&out), want, "{engine}");
    }
}

#[test]
fn a_bake_for_another_engine_removes_the_earlier_bakes_files_and_no_other() {
    let dir = tempfile::tempdir().unwrap();
    let src = input(dir.path(), "sky.exr", false);
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    // Every engine after the one before it, round to the first again.
    let mut before: Option<Engine> = None;
    for engine in ENGINES.into_iter().chain([ENGINES[0]]) {
        let o = bake_into(&src, engine, &out, &[]);
        let said = stderr(&o);
        assert!(o.status.success(), "{engine} after {before:?}: {said}");
        let mut want = bake_listing(engine);
        want.push("notes.txt".into());
        want.sort();
        assert_eq!(files(&out), want, "{engine} after {before:?}");
        let record = std::fs::read_to_string(out.join(mirrorball_io::RECORD)).unwrap();
        let mut listed: Vec<&str> = record
            .lines()
            .filter_map(|l| l.strip_prefix("bake\t"))
            .collect();
        listed.sort();
        let mut own = engine.file_names(&BakeOptions {
            size: 16,
            ..Default::default()
        });
        own.push("README.md".into());
        own.sort();
        assert_eq!(listed, own, "{engine}");
        if let Some(b) = before {
            let opts = BakeOptions {
                size: 16,
                ..Default::default()
            };
            let stale: Vec<String> = b
                .file_names(&opts)
                .into_iter()
                .filter(|f| !engine.file_names(&opts).contains(f))
                .collect();
            for f in &stale {
                assert!(
                    said.contains(&out.join(f).display().to_string()),
                    "{engine} after {b}: {f} not said removed: {said}"
                );
            }
            assert_eq!(said.contains("removed"), !stale.is_empty(), "{said}");
        }
        before = Some(engine);
    }
    assert_eq!(std::fs::read(out.join("notes.txt")).unwrap(), b"mine");
}

/// A direction-coded lat-long EXR `width` wide.
fn wide_input(dir: &Path, width: u32) -> PathBuf {
    let env = mirrorball_bake::direction_coded(width);
    let path = dir.join(format!("sky{width}.exr"));
    mirrorball_io::write_image(&path, &env.layers()[0], &Default::default()).unwrap();
    path
}

/// The face edge of the background an engine's bake wrote in `out`.
fn background_edge(engine: Engine, out: &Path) -> u32 {
    let read = |f: &str| {
        mirrorball_io::read(&out.join(f), &mirrorball_io::Limits::default())
            .unwrap()
            .layers[0]
            .width()
    };
    match engine {
        Engine::Bevy => read("skybox.ktx2"),
        Engine::Three => read("cube/px.hdr"),
        // KTX1's pixelWidth (after the identifier and six u32s).
        Engine::Filament => {
            let b = std::fs::read(out.join("skybox.ktx")).unwrap();
            u32::from_le_bytes(b[36..40].try_into().unwrap())
        }
        _ => unreachable!("{engine} writes no background"),
    }
}

#[test]
fn the_background_has_the_sources_resolution_or_the_size_asked() {
    let dir = tempfile::tempdir().unwrap();
    // 512×256: 131072 texels, as six faces of 148² hold: 128², the nearest power of two.
    let src = wide_input(dir.path(), 512);
    let takers: Vec<Engine> = ENGINES
        .into_iter()
        .filter(|e| e.describe().background.is_some())
        .collect();
    assert_eq!(takers, [Engine::Bevy, Engine::Three, Engine::Filament]);
    for engine in ENGINES {
        let out = dir.path().join(format!("{engine}"));
        let o = bake_into(&src, engine, &out, &[]);
        let said = stderr(&o);
        assert!(o.status.success(), "{engine}: {said}");
        if !takers.contains(&engine) {
            assert!(!said.contains("background"), "{engine}: {said}");
            refused(
                dir.path(),
                &[
                    "bake",
                    src.to_str().unwrap(),
                    "--for",
                    &engine.to_string(),
                    out.to_str().unwrap(),
                    "--background-size",
                    "64",
                ],
                "no background",
            );
            continue;
        }
        assert!(said.contains("16², background 128²"), "{engine}: {said}");
        assert_eq!(background_edge(engine, &out), 128, "{engine}");
        let readme = std::fs::read_to_string(out.join("README.md")).unwrap();
        assert!(readme.contains("128²"), "{engine}: {readme}");
        ok(&[
            "bake",
            src.to_str().unwrap(),
            "--for",
            &engine.to_string(),
            out.to_str().unwrap(),
            "--size",
            "16",
            "--background-size",
            "32",
            "-q",
        ]);
        assert_eq!(background_edge(engine, &out), 32, "{engine}");
    }
    refused(
        dir.path(),
        &[
            "bake",
            src.to_str().unwrap(),
            "--for",
            "bevy",
            dir.path().join("x").to_str().unwrap(),
            "--background-size",
            "100",
        ],
        "background size 100: give a power of two",
    );
}
