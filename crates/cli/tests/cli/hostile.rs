//! Hostile input through the binary: absurd scene values and tessellations refused with
//! what they would cost, mesh and scene problems named, mutated scene files and mutated
//! image files (the io crate's seed corpus) run under a memory cap, each ending in a clean
//! error or a result, and nothing left in the output folder; and the projection-spec
//! parser fuzzed in process (`spec.rs` compiled into this test binary).

#[path = "../../../io/tests/io/mutate.rs"]
mod mutate;

use crate::util::{asset, files, run, stderr};
use mutate::{apply_script, mutations};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// The most virtual memory (KiB) the binary may map in the mutated-file runs: far below
/// what the absurd sizes would ask for, far above what these tiny files need (each thread
/// reserves its stack and a malloc arena).
const VMEM_KIB: u64 = 4 << 20;

/// Runs `mirrorball` with `args` under `ulimit -v` [`VMEM_KIB`]: an allocation beyond it
/// fails and aborts the process, which the callers treat as a failure.
fn run_capped(args: &[&str]) -> (Output, Duration) {
    let start = Instant::now();
    let o = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {VMEM_KIB} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_mirrorball"))
        .args(args)
        .output()
        .expect("the binary runs");
    (o, start.elapsed())
}

/// A clean outcome: success, or exit status 1 or 2 with one `mirrorball: error:` line that
/// names `name`; never a signal (an abort on allocation), never a panic.
fn assert_clean(o: &Output, took: Duration, name: &str, what: &str) {
    let e = stderr(o);
    // The `exr` crate's B44 decoder relies on wrapping unsigned arithmetic (as OpenEXR's C
    // code does): with overflow checks on, as in test builds, a corrupt B44 block panics
    // there, which the reader catches and reports as an error. Release builds wrap.
    let known = cfg!(debug_assertions) && e.contains("compression/b44/mod.rs");
    assert!(known || !e.contains("panicked"), "{what}: panic: {e}");
    assert!(!e.contains("memory allocation"), "{what}: {e}");
    assert!(took < Duration::from_secs(20), "{what}: took {took:?}");
    match o.status.code() {
        Some(0) => {}
        Some(1 | 2) => assert!(
            e.contains("mirrorball: error:") && e.contains(name),
            "{what}: the message should name {name}: {e}"
        ),
        _ => panic!("{what}: killed ({:?}): {e}", o.status),
    }
}

fn corpus(sub: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/corpus")
        .join(sub);
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|d| {
            d.map(|e| e.unwrap().path())
                .filter(|p| p.is_file())
                .collect()
        })
        .unwrap_or_default();
    if let Ok(d) = std::fs::read_dir(dir.join("crashes")) {
        v.extend(d.map(|e| e.unwrap().path()));
    }
    v.sort();
    v
}

#[test]
fn absurd_image_sizes_are_refused_with_what_they_need() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    let o = out.to_str().unwrap();
    for (width, height) in [("65536", "65536"), ("4294967295", "16")] {
        let scene = dir.path().join("big.json");
        std::fs::write(
            &scene,
            format!(
                r#"{{"camera": {{"eye": [0, 0, 3], "target": [0, 0, 0], "width": {width},
                    "height": {height}}}, "material": {{"kind": "cheap-chrome"}},
                    "background": false}}"#
            ),
        )
        .unwrap();
        let (r, took) = run_capped(&["render", scene.to_str().unwrap(), "-o", o]);
        let e = stderr(&r);
        assert_eq!(r.status.code(), Some(1), "{e}");
        assert!(
            e.contains("big.json") && e.contains(&format!("camera.width {width}")),
            "{e}"
        );
        assert!(took < Duration::from_secs(5));
    }
    // Within the bounds of each side, but too much memory in all: said how much.
    for args in [
        vec!["--size", "16384x16384", "--aovs", "--max-memory", "8G"],
        vec![
            "--size",
            "4096x4096",
            "--turntable",
            "100",
            "--max-memory",
            "8G",
        ],
    ] {
        let mut all = vec![
            "render",
            "--material",
            "cheap-chrome",
            "--no-background",
            "-o",
            o,
        ];
        all.extend(args.iter().copied());
        let (r, _) = run_capped(&all);
        let e = stderr(&r);
        assert_eq!(r.status.code(), Some(2), "{all:?}: {e}");
        assert!(
            e.contains("the render's images")
                && e.contains("GB of memory, more than the 8.6 GB of --max-memory"),
            "{e}"
        );
    }
    assert!(files(dir.path()).iter().all(|f| f == "big.json"));
}

#[test]
fn tessellations_beyond_the_triangle_budget_are_refused_before_building() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    let o = out.to_str().unwrap();
    let flag = |object: &str, level: &str| {
        run_capped(&[
            "render",
            "--object",
            object,
            "--tessellation",
            level,
            "--material",
            "cheap-chrome",
            "--no-background",
            "-o",
            o,
        ])
    };
    let (r, took) = flag("teapot", "4096");
    let e = stderr(&r);
    assert_eq!(r.status.code(), Some(2), "{e}");
    assert!(
        e.contains("--tessellation")
            && e.contains("1073741824 triangles")
            && e.contains("16777216")
            && e.contains("tessellation 512"),
        "{e}"
    );
    assert!(took < Duration::from_secs(5));
    let (r, _) = flag("cube", "4096");
    assert!(stderr(&r).contains("201326592 triangles"), "{}", stderr(&r));
    // The same from a scene file, named.
    let scene = dir.path().join("pots.toml");
    std::fs::write(
        &scene,
        "background = false\n[material]\nkind = \"cheap-chrome\"\n[[meshes]]\nmesh = \"teapot\"\ntessellation = 4096\n",
    )
    .unwrap();
    let (r, _) = run_capped(&["render", scene.to_str().unwrap(), "-o", o]);
    let e = stderr(&r);
    assert!(
        e.contains("pots.toml") && e.contains("meshes[0]") && e.contains("1073741824"),
        "{e}"
    );
    // Within the budget one by one, not together.
    let scene = dir.path().join("spheres.json");
    std::fs::write(
        &scene,
        r#"{"background": false, "material": {"kind": "cheap-chrome"},
            "meshes": [{"mesh": "sphere", "tessellation": 4096},
                       {"mesh": "sphere", "tessellation": 4096}]}"#,
    )
    .unwrap();
    let (r, _) = run_capped(&["render", scene.to_str().unwrap(), "-o", o]);
    let e = stderr(&r);
    assert!(
        e.contains("spheres.json") && e.contains("33538048 triangles in all"),
        "{e}"
    );
    // A tessellation within the budget renders (a small picture).
    let (r, _) = flag("teapot", "64");
    assert!(r.status.success(), "{}", stderr(&r));
}

#[test]
fn bad_meshes_and_scenes_name_the_file_and_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    let o = out.to_str().unwrap();
    let obj = dir.path().join("teapot.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n").unwrap();
    let r = run(&[
        "render",
        "--object",
        obj.to_str().unwrap(),
        "--material",
        "cheap-chrome",
        "--no-background",
        "-o",
        o,
    ]);
    let e = stderr(&r);
    assert_eq!(r.status.code(), Some(1), "{e}");
    assert!(
        e.contains("teapot.obj: vertex 2") && e.contains("is not finite"),
        "{e}"
    );
    let huge = dir.path().join("huge.obj");
    std::fs::write(&huge, "v -3e38 0 0\nv 3e38 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let r = run(&[
        "render",
        "--object",
        huge.to_str().unwrap(),
        "--env",
        asset("city.exr").to_str().unwrap(),
        "-o",
        o,
    ]);
    let e = stderr(&r);
    assert!(e.contains("huge.obj: the vertices span"), "{e}");
    // An empty scene: the environment it lacks, and where to give it.
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, "").unwrap();
    let r = run(&["render", scene.to_str().unwrap(), "-o", o]);
    let e = stderr(&r);
    assert_eq!(r.status.code(), Some(2), "{e}");
    assert!(
        e.contains("scene.toml: no environment map") && e.contains("environment.file"),
        "{e}"
    );
    assert!(!out.exists());
}

#[test]
fn mutated_scene_files_end_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let outdir = dir.path().join("out");
    std::fs::create_dir(&outdir).unwrap();
    let out = outdir.join("x.png");
    let mut runs = 0;
    for (k, seed) in corpus("scene").iter().enumerate() {
        let bytes = std::fs::read(seed).unwrap();
        let ext = seed.extension().unwrap().to_str().unwrap();
        // The seed renders.
        let (r, _) = run_capped(&[
            "render",
            seed.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "-q",
        ]);
        assert!(
            r.status.success(),
            "seed {}: {}",
            seed.display(),
            stderr(&r)
        );
        std::fs::remove_file(&out).unwrap();
        // Every third mutation: each is a process.
        for (i, m) in mutations(&bytes, k as u64)
            .into_iter()
            .enumerate()
            .step_by(3)
        {
            let scene = dir.path().join(format!("m{i}.{ext}"));
            std::fs::write(&scene, &m).unwrap();
            let (r, took) = run_capped(&[
                "render",
                scene.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
                "-q",
            ]);
            let name = format!("m{i}.{ext}");
            assert_clean(&r, took, &name, &format!("{name} ({})", seed.display()));
            runs += 1;
            let _ = std::fs::remove_file(&out);
            assert!(
                files(&outdir).is_empty(),
                "{name}: left {:?}",
                files(&outdir)
            );
        }
    }
    eprintln!("{runs} mutated scenes");
}

#[test]
fn mutated_image_files_end_cleanly_in_info_and_convert() {
    let io_corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("../io/tests/corpus");
    let dir = tempfile::tempdir().unwrap();
    let outdir = dir.path().join("out");
    std::fs::create_dir(&outdir).unwrap();
    let mut runs = 0;
    let mut formats: Vec<PathBuf> = std::fs::read_dir(&io_corpus)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    formats.sort();
    for format in formats {
        // Past crashes, as they are.
        let crashes = format.join("crashes");
        if crashes.is_dir() {
            for crash in corpus_in(&crashes) {
                let name = crash.file_name().unwrap().to_string_lossy().into_owned();
                let (r, took) = run_capped(&["info", crash.to_str().unwrap()]);
                assert_clean(&r, took, &name, &name);
                runs += 1;
            }
        }
        for (k, seed) in corpus_in(&format).iter().enumerate() {
            let bytes = std::fs::read(seed).unwrap();
            // The inflated size fields (the mutations after the cuts and flips), every
            // fourth, and a few cuts.
            let all = mutations(&bytes, 1000 + k as u64);
            let cuts = all.len() - 40 - 108 - 8;
            let picked = all
                .iter()
                .enumerate()
                .filter(|(i, _)| (*i < cuts && i % 8 == 0) || (*i >= cuts + 40 && i % 4 == 0));
            for (i, m) in picked {
                let name = format!("m{i}-{}", seed.file_name().unwrap().to_string_lossy());
                let input = dir.path().join(&name);
                std::fs::write(&input, m).unwrap();
                let (r, took) = run_capped(&["info", input.to_str().unwrap()]);
                assert_clean(&r, took, &name, &name);
                if i % 16 == 0 {
                    let out = outdir.join("o.exr");
                    let (r, took) = run_capped(&[
                        "convert",
                        input.to_str().unwrap(),
                        out.to_str().unwrap(),
                        "--to",
                        "latlong",
                        "--size",
                        "16",
                        "-q",
                    ]);
                    assert_clean(&r, took, &name, &name);
                    if r.status.success() {
                        std::fs::remove_file(&out).unwrap();
                    }
                    assert!(
                        files(&outdir).is_empty(),
                        "{name}: left {:?}",
                        files(&outdir)
                    );
                }
                runs += 1;
                std::fs::remove_file(&input).unwrap();
            }
        }
    }
    eprintln!("{runs} mutated image files");
}

fn corpus_in(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    v.sort();
    v
}

// ---------------------------------------------------------------------------------------
// The projection-spec parser, in process.

#[test]
fn fuzz_scene() {
    // Each input is a process: few iterations here, more in a campaign.
    let seeds: Vec<(PathBuf, Vec<u8>)> = corpus("scene")
        .into_iter()
        .map(|p| {
            let b = std::fs::read(&p).unwrap();
            (p, b)
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.png");
    bolero::check!()
        .with_iterations(40)
        .for_each(|input: &[u8]| {
            let Some((&pick, script)) = input.split_first() else {
                return;
            };
            let (seed_path, seed) = &seeds[pick as usize % seeds.len()];
            let ext = seed_path.extension().unwrap().to_str().unwrap();
            let scene = dir.path().join(format!("fuzz.{ext}"));
            std::fs::write(&scene, apply_script(seed, script)).unwrap();
            let (r, took) = run_capped(&[
                "render",
                scene.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
                "-q",
            ]);
            assert_clean(&r, took, &format!("fuzz.{ext}"), "fuzzed scene");
            let _ = std::fs::remove_file(&out);
        });
}
