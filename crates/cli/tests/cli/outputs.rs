//! Every command that writes refuses an output it cannot write before it reads anything: a
//! read-only folder, a missing folder inside a read-only one, a name that is a folder. The
//! message names the output, the exit status is 1 or 2, nothing is left behind, and the
//! input is never opened: it is a FIFO no one writes, which would block the reader forever.
//! `compare --diff` into a read-only folder still prints its score, then fails.
//!
//! Root ignores permission bits, so as root the commands run as `nobody` (`setpriv`); where
//! that is impossible the read-only cases say so and are left out.
use crate::util::{asset, files, stderr, stdout};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// How the commands are run: as this user, or (as root) as `nobody`.
#[derive(Clone, Copy, PartialEq)]
enum Runner {
    Plain,
    Nobody,
}

/// The runner whose read-only folders really are read-only, or `None` (with the reason
/// printed) when root cannot become another user here.
fn runner() -> Option<Runner> {
    let root = Command::new("id")
        .arg("-u")
        .output()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
        .unwrap_or(false);
    if !root {
        return Some(Runner::Plain);
    }
    let works = Command::new("setpriv")
        .args(nobody_args())
        .arg("true")
        .status()
        .is_ok_and(|s| s.success());
    if works {
        Some(Runner::Nobody)
    } else {
        eprintln!(
            "outputs: running as root, and `setpriv` cannot run a command as nobody here: \
             the read-only folder cases are left out (root writes anywhere)"
        );
        None
    }
}

fn nobody_args() -> [&'static str; 4] {
    ["--reuid=65534", "--regid=65534", "--clear-groups", "--"]
}

/// Runs `mirrorball args` in `dir` as `runner` says; kills it after 60 s (a command that
/// opened its FIFO input would wait forever). Returns its output and how long it ran.
fn run_in(dir: &Path, runner: Runner, args: &[&str]) -> (Output, Duration) {
    let bin = env!("CARGO_BIN_EXE_mirrorball");
    let mut cmd = match runner {
        Runner::Plain => Command::new(bin),
        Runner::Nobody => {
            let mut c = Command::new("setpriv");
            c.args(nobody_args()).arg(bin);
            c
        }
    };
    let t = Instant::now();
    let mut child = cmd
        .current_dir(dir)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    while child.try_wait().unwrap().is_none() {
        if t.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("mirrorball {args:?} still ran after 60 s: it opened its input");
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    (child.wait_with_output().unwrap(), t.elapsed())
}

/// A folder everyone can write: `in.exr` a FIFO, `in/000.exr` another (a sequence of one),
/// `ro/` read-only, `taken.*` folders where files are named.
fn place() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Written by anyone: only `ro/` is read-only.
    set_mode(d, 0o777);
    std::fs::create_dir(d.join("in")).unwrap();
    for fifo in ["in.exr", "in/000.exr"] {
        let ok = Command::new("mkfifo").arg(d.join(fifo)).status().unwrap();
        assert!(ok.success());
    }
    for taken in ["taken.exr", "taken.ktx2", "taken.png", "taken.json"] {
        std::fs::create_dir(d.join(taken)).unwrap();
    }
    // Bake's README.md and the report's page as folders, in folders they may write.
    std::fs::create_dir_all(d.join("taken/README.md")).unwrap();
    std::fs::create_dir_all(d.join("report/index.html")).unwrap();
    std::fs::create_dir(d.join("ro")).unwrap();
    set_mode(&d.join("ro"), 0o555);
    dir
}

fn set_mode(p: &Path, mode: u32) {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(p, std::fs::Permissions::from_mode(mode)).unwrap();
}

/// Where a case puts the output.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Case {
    /// In the read-only folder.
    ReadOnly,
    /// In a folder that does not exist, inside the read-only one.
    MissingInReadOnly,
    /// A name that is a folder.
    Folder,
}

/// Each command that writes: `{o}` in its arguments is where its output goes, a file's
/// name before its extension, or a folder (`bake`, `demo` and `analyze` make theirs).
const COMMANDS: &[&[&str]] = &[
    &["convert", "in.exr", "{o}.exr", "--to", "cube"],
    &["convert", "in.exr", "{o}_{face}.exr", "--to", "cube"],
    &["convert", "in/%03d.exr", "{o}%03d.exr", "--to", "cube"],
    &["convert", "in.exr", "{o}.ktx2", "--to", "cube", "--mips"],
    &["prefilter", "in.exr", "{o}.ktx2", "--lobe", "ggx"],
    &[
        "prefilter",
        "in.exr",
        "{o}.exr",
        "--lobe",
        "ggx",
        "--to",
        "latlong",
    ],
    &[
        "prefilter",
        "in.exr",
        "p.ktx2",
        "--lobe",
        "ggx",
        "--sh",
        "{o}.json",
    ],
    &[
        "prefilter",
        "in.exr",
        "p.ktx2",
        "--lobe",
        "ggx",
        "--preview",
        "{o}.png",
    ],
    &[
        "prefilter",
        "in.exr",
        "p.ktx2",
        "--lobe",
        "ggx",
        "--lut",
        "{o}.exr",
    ],
    &["bake", "in.exr", "--for", "ktx2", "{o}"],
    &[
        "render", "--env", "in.exr", "-o", "{o}.png", "--size", "64x48",
    ],
    &[
        "render",
        "--env",
        "in.exr",
        "-o",
        "{o}.exr",
        "--turntable",
        "2",
    ],
    &["demo", "--out", "{o}", "--size", "64"],
    &["analyze", "--out", "{o}", "--size", "16"],
];

/// What `{o}` becomes in `case` for `args`, and the path and words the message must
/// hold; `None` where no folder can stand in the output's place.
fn target(case: Case, args: &[&str]) -> Option<(String, String, &'static str)> {
    let o = args.iter().find(|a| a.contains("{o}")).unwrap();
    let folder = *o == "{o}";
    let makes_folders = folder;
    let file = |name: &str| {
        o.replace("{o}", name)
            .replace("%03d", "000")
            .replace("{face}", "px")
    };
    Some(match case {
        Case::ReadOnly if folder => ("ro".into(), "ro".into(), "permission denied"),
        Case::ReadOnly if o.contains('%') => ("ro/".into(), file("ro/"), "permission denied"),
        // The output's name, or its first frame's or level's (`ro/out-0000.exr`, `_mip0`).
        Case::ReadOnly => ("ro/out".into(), "ro/out".into(), "permission denied"),
        Case::MissingInReadOnly if makes_folders => {
            ("ro/new".into(), "ro/new".into(), "permission denied")
        }
        // A sequence makes its output folder, not the folders above it.
        Case::MissingInReadOnly if o.contains('%') => (
            "ro/new/out".into(),
            "ro/new".into(),
            "cannot make the folder",
        ),
        Case::MissingInReadOnly => ("ro/new/out".into(), "ro/new".into(), "does not exist"),
        // Where bake's README.md, demo's and analyze's page go is a folder.
        Case::Folder if args[0] == "bake" => (
            "taken".into(),
            "taken/README.md".into(),
            "a folder is where",
        ),
        Case::Folder if folder => ("report".into(), "report/index.html".into(), "is a folder"),
        Case::Folder if o.contains('%') || o.contains("{face}") => return None,
        Case::Folder => ("taken".into(), file("taken"), "is a folder"),
    })
}

#[test]
fn outputs_that_cannot_be_written_are_refused_before_the_input_is_read() {
    let runner = runner();
    let dir = place();
    let d = dir.path();
    let before = files(d);
    let mut longest = Duration::ZERO;
    for &args in COMMANDS {
        for case in [Case::ReadOnly, Case::MissingInReadOnly, Case::Folder] {
            let Some((o, named, why)) = target(case, args) else {
                continue;
            };
            let run_as = match (case, runner) {
                (Case::Folder, _) => Runner::Plain,
                (_, Some(r)) => r,
                (_, None) => continue,
            };
            let args: Vec<String> = args.iter().map(|a| a.replace("{o}", &o)).collect();
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            let (out, took) = run_in(d, run_as, &args);
            let e = stderr(&out);
            let said = format!("{args:?} ({case:?}): {e}");
            assert!(matches!(out.status.code(), Some(1 | 2)), "{said}");
            assert!(!e.contains("panicked"), "{said}");
            assert!(e.contains(&named), "'{named}' not in {said}");
            assert!(e.contains(why), "'{why}' not in {said}");
            longest = longest.max(took);
            assert_eq!(files(d), before, "{args:?} ({case:?}) left something");
        }
    }
    // Before any work: a fraction of a second each (the FIFO inputs show nothing was read).
    assert!(longest < Duration::from_secs(5), "{longest:?}");
    eprintln!("outputs: the slowest refusal took {longest:?}");
}

#[test]
fn compare_prints_its_score_before_failing_to_write_the_difference() {
    let Some(runner) = runner() else { return };
    let dir = place();
    let d = dir.path();
    let city: PathBuf = d.join("city.exr");
    std::fs::copy(asset("city.exr"), &city).unwrap();
    set_mode(&city, 0o644);
    let (o, _) = run_in(
        d,
        runner,
        &["compare", "city.exr", "city.exr", "--diff", "ro/diff.png"],
    );
    let (out, e) = (stdout(&o), stderr(&o));
    assert_eq!(o.status.code(), Some(1), "{out}{e}");
    assert!(out.contains("log-PSNR inf dB"), "{out}");
    assert!(!out.contains("wrote"), "{out}");
    assert!(
        e.contains("--diff ro/diff.png: cannot write into the folder ro (permission denied)"),
        "{e}"
    );
    assert!(files(&d.join("ro")).is_empty());
}
