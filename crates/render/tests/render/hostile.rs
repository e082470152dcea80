//! Hostile mesh files and tessellations: the seed corpus (`tests/corpus/{obj,gltf}/`)
//! mutated (see the io tests' `mutate.rs`) and loaded, each ending in an error naming the
//! file or a valid mesh, quickly; vertices that are not finite, or too far apart to frame,
//! named as such; and built-in triangle counts known before anything is built.

#[path = "../../../io/tests/io/mutate.rs"]
mod mutate;

use mirrorball_render::mesh::MAX_TRIANGLES;
use mirrorball_render::Builtin;
use mirrorball_render::{load_mesh, load_mesh_bytes};
use mutate::{apply_script, mutations};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Panics inside a parser that the loader caught and reported.
static CAUGHT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

fn corpus(format: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/corpus")
        .join(format);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    let crashes = dir.join("crashes");
    if let Ok(d) = std::fs::read_dir(crashes) {
        files.extend(d.map(|e| e.unwrap().path()));
    }
    files.sort();
    files
}

/// Loads `path`: an error that starts with the file's name, or a mesh that validates and
/// has triangles; and its bytes, as an upload is read: the same mesh, or an error where
/// the file's is (or where the file names another, which bytes alone cannot hold). Returns
/// how long the file took.
fn check_load(path: &Path) -> Duration {
    let start = Instant::now();
    let result = load_mesh(path);
    let took = start.elapsed();
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    let from_bytes = load_mesh_bytes(&name, &std::fs::read(path).unwrap());
    match (&result, &from_bytes) {
        (Ok(a), Ok(b)) => assert_eq!(a, b, "{name}: the bytes' mesh is the file's"),
        (Err(_), Err(e)) => assert!(e.to_string().starts_with(&name), "{e}"),
        (Ok(_), Err(e)) => assert!(e.to_string().contains("another file"), "{name}: {e}"),
        (Err(e), Ok(_)) => panic!("{name}: read from its bytes, though the file gives {e}"),
    }
    match result {
        Err(e) => {
            assert_eq!(e.fault(), mirrorball_core::Fault::Input, "{e}");
            let e = e.to_string();
            assert!(
                e.starts_with(&path.display().to_string()) && e.len() > path.as_os_str().len() + 2,
                "{e}"
            );
            // A panic caught: only the one known in gltf-json (see `load_mesh`).
            if e.contains("failed on malformed data") {
                CAUGHT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            }
        }
        Ok(m) => {
            m.validate().unwrap();
            assert!(!m.triangles.is_empty());
            assert!(m.positions.iter().all(|p| p.is_finite()));
        }
    }
    took
}

fn replay(format: &str) {
    let dir = tempfile::tempdir().unwrap();
    let (mut files, mut slowest) = (0, Duration::ZERO);
    for (k, seed) in corpus(format).iter().enumerate() {
        if !seed.parent().unwrap().ends_with("crashes") {
            load_mesh(seed).unwrap_or_else(|e| panic!("seed {e}"));
        }
        let bytes = std::fs::read(seed).unwrap();
        let name = seed.file_name().unwrap().to_string_lossy().into_owned();
        for (i, m) in mutations(&bytes, k as u64).into_iter().enumerate() {
            let path = dir.path().join(format!("m{i}-{name}"));
            std::fs::write(&path, &m).unwrap();
            slowest = slowest.max(check_load(&path));
            files += 1;
            std::fs::remove_file(&path).unwrap();
        }
    }
    eprintln!(
        "{format}: {files} files, slowest {slowest:?}, parser panics caught so far: {}",
        CAUGHT.load(std::sync::atomic::Ordering::Relaxed)
    );
    assert!(slowest < Duration::from_secs(5));
}

#[test]
fn hostile_obj() {
    replay("obj");
}

#[test]
fn hostile_gltf() {
    replay("gltf");
}

fn fuzz(format: &str) {
    let seeds: Vec<(PathBuf, Vec<u8>)> = corpus(format)
        .into_iter()
        .map(|p| {
            let b = std::fs::read(&p).unwrap();
            (p, b)
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    bolero::check!()
        .with_iterations(200)
        .for_each(|input: &[u8]| {
            let Some((&pick, script)) = input.split_first() else {
                return;
            };
            let (seed_path, seed) = &seeds[pick as usize % seeds.len()];
            let ext = seed_path.extension().unwrap().to_str().unwrap();
            let path = dir.path().join(format!("fuzz.{ext}"));
            std::fs::write(&path, apply_script(seed, script)).unwrap();
            check_load(&path);
        });
}

#[test]
fn fuzz_obj() {
    fuzz("obj");
}

#[test]
fn fuzz_gltf() {
    fuzz("gltf");
}

#[test]
fn vertices_that_are_not_finite_or_too_far_apart_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let nan = dir.path().join("nan.obj");
    std::fs::write(&nan, "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let e = load_mesh(&nan).unwrap_err();
    assert_eq!(e.fault(), mirrorball_core::Fault::Input);
    let e = e.to_string();
    assert!(
        e.starts_with(&nan.display().to_string())
            && e.contains("vertex 1")
            && e.contains("not finite"),
        "{e}"
    );
    let huge = dir.path().join("huge.obj");
    std::fs::write(&huge, "v -3e38 0 0\nv 3e38 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let e = load_mesh(&huge).unwrap_err();
    assert_eq!(e.fault(), mirrorball_core::Fault::Input);
    let e = e.to_string();
    assert!(
        e.starts_with(&huge.display().to_string()) && e.contains("span") && e.contains("inf"),
        "{e}"
    );
    let far = dir.path().join("far.obj");
    std::fs::write(&far, "v 0 0 0\nv 1e20 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let e = load_mesh(&far).unwrap_err();
    assert_eq!(e.fault(), mirrorball_core::Fault::Input);
    let e = e.to_string();
    assert!(e.contains("1e20") && e.contains("vertex 1"), "{e}");
    // Large but within what can be framed: loads.
    let big = dir.path().join("big.obj");
    std::fs::write(&big, "v 0 0 0\nv 1e9 0 0\nv 0 1e9 0\nf 1 2 3\n").unwrap();
    load_mesh(&big).unwrap();
}

#[test]
fn builtin_triangle_counts_are_known_before_building() {
    for b in Builtin::ALL {
        for level in (1..=12).chain([31, 64, 100]) {
            let built = b.mesh(level).triangles.len() as u64;
            let counted = b.triangle_count(level);
            if b == Builtin::Teapot {
                // Collapsed patch edges drop a few triangles.
                assert!(
                    built <= counted && built * 100 >= counted * 85,
                    "{b:?} {level}: {built} vs {counted}"
                );
            } else {
                assert_eq!(built, counted, "{b:?} {level}");
            }
        }
        let max = b.max_tessellation(MAX_TRIANGLES);
        assert!(b.triangle_count(max) <= MAX_TRIANGLES);
        assert!(b.triangle_count(max + 1) > MAX_TRIANGLES, "{b:?}");
    }
    // The sphere and torus fit at the largest tessellation the CLI takes; the teapot does
    // not, by far.
    assert!(Builtin::Sphere.triangle_count(4096) <= MAX_TRIANGLES);
    assert!(Builtin::Torus.triangle_count(4096) <= MAX_TRIANGLES);
    assert_eq!(Builtin::Teapot.triangle_count(4096), 1 << 30);
    assert_eq!(Builtin::Teapot.max_tessellation(MAX_TRIANGLES), 512);
}
