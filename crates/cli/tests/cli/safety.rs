//! The user's files are safe: no way of naming an input as an output gets through, an
//! interrupted run leaves nothing half-written (and a later run cleans what a killed one
//! left), symbolic links are written through, numbers must be numbers, and a job that
//! would not fit in memory is refused before it starts.
use crate::util::{asset, files, ok, run, stderr};
use std::path::Path;

/// Runs `args` in `dir`, expecting a refusal (exit 2) whose message holds every `expect`.
fn refused_in(dir: &Path, args: &[&str], expect: &[&str]) {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_mirrorball"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap();
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "mirrorball {args:?}: {e}");
    assert!(!e.contains("panicked"), "{e}");
    for s in expect {
        assert!(e.contains(s), "'{s}' not in: {e}");
    }
}

/// A folder holding `s.exr` (the bundled city map), a hard link and a symbolic link to it,
/// and a sub-folder.
fn setup() -> (tempfile::TempDir, Vec<u8>) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::copy(asset("city.exr"), d.join("s.exr")).unwrap();
    std::fs::create_dir(d.join("sub")).unwrap();
    std::fs::hard_link(d.join("s.exr"), d.join("hard.exr")).unwrap();
    #[cfg(unix)]
    std::os::unix::fs::symlink("s.exr", d.join("soft.exr")).unwrap();
    let bytes = std::fs::read(d.join("s.exr")).unwrap();
    (dir, bytes)
}

/// Every other name of `s.exr` in the folder `setup` makes.
fn other_names(d: &Path) -> Vec<String> {
    let mut v = vec![
        "./s.exr".to_string(),
        d.join("s.exr").display().to_string(),
        "sub/../s.exr".to_string(),
        "hard.exr".to_string(),
    ];
    if cfg!(unix) {
        v.push("soft.exr".to_string());
    }
    v
}

#[test]
fn convert_refuses_every_name_of_its_input() {
    let (dir, bytes) = setup();
    let d = dir.path();
    let before = files(d);
    for out in other_names(d) {
        refused_in(
            d,
            &["convert", "s.exr", &out, "--to", "latlong"],
            &["would overwrite the input"],
        );
    }
    // One file a face, one of which is the input.
    std::fs::copy(d.join("s.exr"), d.join("f_nx.exr")).unwrap();
    let nx = std::fs::read(d.join("f_nx.exr")).unwrap();
    refused_in(
        d,
        &[
            "convert",
            "f_nx.exr",
            "f_{face}.exr",
            "--to",
            "cube",
            "--from",
            "latlong",
        ],
        &["f_nx.exr", "would overwrite the input"],
    );
    assert_eq!(std::fs::read(d.join("f_nx.exr")).unwrap(), nx);
    std::fs::remove_file(d.join("f_nx.exr")).unwrap();
    assert_eq!(std::fs::read(d.join("s.exr")).unwrap(), bytes);
    assert_eq!(files(d), before);
}

#[test]
fn prefilter_and_render_refuse_every_name_of_their_inputs() {
    let (dir, bytes) = setup();
    let d = dir.path();
    let before = files(d);
    for name in other_names(d) {
        let lut = format!("{}", Path::new(&name).with_extension("exr").display());
        refused_in(
            d,
            &[
                "prefilter",
                "s.exr",
                "o.ktx2",
                "--lobe",
                "ggx",
                "--lut",
                &lut,
                "--size",
                "8",
            ],
            &["would overwrite the input"],
        );
        refused_in(
            d,
            &[
                "prefilter",
                "s.exr",
                "o.exr",
                "--lobe",
                "lambert",
                "--to",
                "latlong",
                "--sh",
                &name,
            ],
            &["--sh would overwrite the input"],
        );
        refused_in(
            d,
            &["render", "--env", "s.exr", "-o", &name, "--size", "16x16"],
            &["would overwrite the environment"],
        );
    }
    // A diagnostic channel written beside the image is the environment.
    std::fs::copy(d.join("s.exr"), d.join("r-st.exr")).unwrap();
    refused_in(
        d,
        &[
            "render", "--env", "r-st.exr", "-o", "r.png", "--aovs", "--size", "16x16",
        ],
        &["r-st.exr", "would overwrite the environment"],
    );
    std::fs::remove_file(d.join("r-st.exr")).unwrap();
    // Two outputs that are one file.
    refused_in(
        d,
        &[
            "prefilter",
            "s.exr",
            "o.ktx2",
            "--lobe",
            "ggx",
            "--size",
            "8",
            "--preview",
            "p.png",
            "--lut",
            "sub/../p.png",
        ],
        &["are the same file"],
    );
    assert_eq!(std::fs::read(d.join("s.exr")).unwrap(), bytes);
    assert_eq!(files(d), before);
}

/// Starts `args` in `dir`, waits for its first temporary file, sends `signal`, and returns
/// the exit status (128 + the signal's number when it killed the process).
#[cfg(unix)]
fn interrupt(dir: &Path, args: &[&str], signal: &str) -> i32 {
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_mirrorball"))
        .current_dir(dir)
        .args(args)
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            panic!("ended ({status}) before a temporary file was seen: make the job larger");
        }
        let temp = files(dir).iter().any(|f| f.ends_with(".tmp"));
        if temp {
            break;
        }
        assert!(started.elapsed().as_secs() < 120, "no temporary file");
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    std::process::Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    let status = child.wait().unwrap();
    use std::os::unix::process::ExitStatusExt;
    status
        .code()
        .unwrap_or_else(|| 128 + status.signal().unwrap())
}

/// Writes `f_{face}.exr` from `s.exr` in `d`: six 8² faces.
#[cfg(unix)]
fn small_set(d: &Path) {
    let (s, f) = (d.join("s.exr"), d.join("f_{face}.exr"));
    let (s, f) = (s.to_str().unwrap(), f.to_str().unwrap());
    ok(&["convert", s, f, "--to", "cube", "--size", "8", "-q"]);
}

#[cfg(unix)]
#[test]
fn an_interrupted_run_leaves_nothing_half_written() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::copy(asset("city.exr"), d.join("s.exr")).unwrap();
    let big = [
        "convert",
        "s.exr",
        "f_{face}.exr",
        "--to",
        "cube",
        "--size",
        "2048",
        "--compression",
        "none",
        "-q",
    ];
    // A new set: nothing lands.
    assert_eq!(interrupt(d, &big, "-INT"), 130);
    assert_eq!(files(d), ["s.exr"]);
    // An old set is kept whole: the new one lands entirely or not at all.
    small_set(d);
    let old: Vec<Vec<u8>> = ["px", "nx", "py", "ny", "pz", "nz"]
        .iter()
        .map(|f| std::fs::read(d.join(format!("f_{f}.exr"))).unwrap())
        .collect();
    assert_eq!(interrupt(d, &big, "-TERM"), 143);
    let now: Vec<Vec<u8>> = ["px", "nx", "py", "ny", "pz", "nz"]
        .iter()
        .map(|f| std::fs::read(d.join(format!("f_{f}.exr"))).unwrap())
        .collect();
    assert!(now == old, "the old set was changed");
    assert!(
        !files(d).iter().any(|f| f.ends_with(".tmp")),
        "{:?}",
        files(d)
    );

    // A killed run's temporary files stay; the next run that writes anything into the
    // folder removes them and says which.
    assert_eq!(interrupt(d, &big, "-KILL"), 128 + 9);
    let left: Vec<String> = files(d)
        .into_iter()
        .filter(|f| f.ends_with(".tmp"))
        .collect();
    assert!(!left.is_empty());
    let said = ok(&[
        "convert",
        d.join("s.exr").to_str().unwrap(),
        d.join("other.hdr").to_str().unwrap(),
        "--to",
        "latlong",
        "--size",
        "16",
    ]);
    for f in &left {
        assert!(
            said.contains(&format!("removed {}", d.join(f).display())),
            "{f}: {said}"
        );
    }
    assert!(
        !files(d).iter().any(|f| f.ends_with(".tmp")),
        "{:?}",
        files(d)
    );
}

/// Only mirrorball's own temporary files (`.NAME.PID.tmp`, a plain file) of processes that
/// no longer run are removed, from any folder a run writes into, and the run says so;
/// nothing else is touched, and a quiet run removes them without a word.
#[cfg(target_os = "linux")]
#[test]
fn a_run_removes_only_the_temporary_files_of_dead_processes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::copy(asset("city.exr"), d.join("s.exr")).unwrap();
    let out = d.join("out");
    std::fs::create_dir(&out).unwrap();
    // A process that has ended, and one that runs (this test's).
    let mut gone = std::process::Command::new("true").spawn().unwrap();
    gone.wait().unwrap();
    let (dead, live) = (gone.id(), std::process::id());
    let dead_tmp = format!(".x.exr.{dead}.tmp");
    let kept = [
        format!(".y.png.{live}.tmp"),
        format!("x.exr.{dead}.tmp"),
        format!(".x.exr.{dead}.tmp.bak"),
        ".x.exr.tmp".to_string(),
        format!(".x.exr.{dead}a.tmp"),
    ];
    for f in kept.iter().chain([&dead_tmp]) {
        std::fs::write(out.join(f), b"half").unwrap();
    }
    std::fs::create_dir(out.join(format!(".dir.{dead}.tmp"))).unwrap();
    let before = files(&out);
    let convert = |name: &str, quiet: bool| {
        let o = out.join(name);
        let mut args = vec!["convert", "s.exr", o.to_str().unwrap(), "--to", "latlong"];
        args.extend(["--size", "16"]);
        if quiet {
            args.push("-q");
        }
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_mirrorball"))
            .current_dir(d)
            .args(&args)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        stderr(&o)
    };
    let said = convert("a.exr", false);
    let want = format!("removed {}", out.join(&dead_tmp).display());
    assert!(said.contains(&want), "{said}");
    assert_eq!(said.matches("removed").count(), 1, "{said}");
    let mut now = before.clone();
    now.retain(|f| *f != dead_tmp);
    now.push("a.exr".into());
    now.sort();
    assert_eq!(files(&out), now);
    // Nothing more to remove; and a quiet run removes them without a word.
    assert!(!convert("b.exr", false).contains("removed"));
    std::fs::write(out.join(&dead_tmp), b"half").unwrap();
    assert_eq!(convert("c.exr", true), "");
    assert!(!out.join(&dead_tmp).exists());
}

#[cfg(unix)]
#[test]
fn an_output_that_is_a_symbolic_link_is_written_through() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("real.exr"), b"old").unwrap();
    std::os::unix::fs::symlink("real.exr", d.join("link.exr")).unwrap();
    ok(&[
        "convert",
        asset("city.exr").to_str().unwrap(),
        d.join("link.exr").to_str().unwrap(),
        "--to",
        "latlong",
        "--size",
        "32",
        "-q",
    ]);
    assert!(std::fs::symlink_metadata(d.join("link.exr"))
        .unwrap()
        .file_type()
        .is_symlink());
    let read = mirrorball_io::read(&d.join("real.exr"), &Default::default()).unwrap();
    assert_eq!(read.layers[0].width(), 32);
}

#[test]
fn the_longest_legal_names_can_be_written() {
    let dir = tempfile::tempdir().unwrap();
    for len in [240usize, 250, 255] {
        let name = format!("{}.exr", "n".repeat(len - 4));
        let out = dir.path().join(&name);
        ok(&[
            "convert",
            asset("city.exr").to_str().unwrap(),
            out.to_str().unwrap(),
            "--to",
            "latlong",
            "--size",
            "16",
            "-q",
        ]);
        assert!(out.exists(), "{len}");
    }
    assert_eq!(files(dir.path()).len(), 3);
}

#[test]
fn numbers_must_be_finite() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.exr");
    let o = out.to_str().unwrap();
    let city = asset("city.exr");
    let c = city.to_str().unwrap();
    for (flag, v) in [
        ("--yaw", "nan"),
        ("--pitch", "inf"),
        ("--roll", "-inf"),
        ("--exposure", "1e999"),
        ("--yaw", "ten"),
    ] {
        let r = run(&["convert", c, o, "--to", "cube", flag, v]);
        let e = stderr(&r);
        assert_eq!(r.status.code(), Some(2), "{flag} {v}: {e}");
        assert!(e.contains(flag) && e.contains(v), "{e}");
    }
    for (flag, v) in [("--fov", "nan"), ("--near", "inf"), ("--exposure", "NaN")] {
        let r = run(&["render", "--env", c, "-o", o, flag, v]);
        assert_eq!(r.status.code(), Some(2), "{flag} {v}: {}", stderr(&r));
    }
    assert!(!out.exists());
}

#[test]
fn a_job_too_large_for_memory_is_refused_before_it_starts() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.exr");
    let city = asset("city.exr");
    let (c, o) = (city.to_str().unwrap(), out.to_str().unwrap());
    for (extra, expect) in [
        (
            &["--size", "4096", "--max-memory", "1G"][..],
            "GB of memory",
        ),
        (
            &["--size", "256", "--max-memory", "1M"][..],
            "of --max-memory",
        ),
    ] {
        let args = [&["convert", c, o, "--to", "cube"][..], extra].concat();
        let r = run(&args);
        let e = stderr(&r);
        assert_eq!(r.status.code(), Some(2), "{e}");
        assert!(e.contains(expect) && e.contains("--size"), "{e}");
    }
    assert!(files(dir.path()).is_empty());
}

#[test]
fn default_sizes_are_powers_of_two() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let city = asset("city.exr");
    // 512×256 lat-long → cube faces of 128 (147 would keep the density); back → 512×256.
    let cube = d.join("c.exr");
    let e = ok(&[
        "convert",
        city.to_str().unwrap(),
        cube.to_str().unwrap(),
        "--to",
        "cube",
    ]);
    assert!(e.contains("128x128"), "{e}");
    let ll = d.join("l.png");
    let e = ok(&[
        "convert",
        cube.to_str().unwrap(),
        ll.to_str().unwrap(),
        "--to",
        "latlong",
    ]);
    assert!(e.contains("512x256"), "{e}");
    // Its own output reads back.
    ok(&["info", ll.to_str().unwrap()]);
}

#[test]
fn a_face_placeholder_where_there_is_one_layer_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let city = asset("city.exr");
    for (to, out) in [("latlong", "ll_{face}.exr"), ("cube", "c_{face}.ktx2")] {
        let o = dir.path().join(out);
        let r = run(&[
            "convert",
            city.to_str().unwrap(),
            o.to_str().unwrap(),
            "--to",
            to,
        ]);
        let e = stderr(&r);
        assert_eq!(r.status.code(), Some(2), "{e}");
        assert!(e.contains("{face}") && e.contains("leave"), "{e}");
    }
    assert!(files(dir.path()).is_empty());
}

/// Messages name values as the user spells them, never in Rust's debug form
/// (`Ggx { roughness: 2.0 }`, `Half`).
#[test]
fn messages_speak_the_users_words() {
    let dir = tempfile::tempdir().unwrap();
    let city = asset("city.exr");
    let c = city.to_str().unwrap();
    let png = dir.path().join("o.png");
    for (args, expect) in [
        (
            vec![
                "render",
                "--env",
                c,
                "--material",
                "greene:ggx=2",
                "-o",
                png.to_str().unwrap(),
            ],
            "ggx roughness 2 is outside [0, 1]",
        ),
        (
            vec![
                "convert",
                c,
                png.to_str().unwrap(),
                "--to",
                "latlong",
                "--precision",
                "half",
            ],
            "--precision half does not apply to .png",
        ),
    ] {
        let r = run(&args);
        let e = stderr(&r);
        assert_eq!(r.status.code(), Some(2), "{e}");
        assert!(
            e.contains(expect) && !e.contains(" { ") && !e.contains("Half"),
            "{e}"
        );
    }
}
