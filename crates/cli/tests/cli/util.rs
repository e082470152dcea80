use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn asset(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/env")
        .join(name)
}

/// Runs `mirrorball` with `args`.
pub fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mirrorball"))
        .args(args)
        .output()
        .expect("the binary runs")
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Asserts success and returns stderr.
pub fn ok(args: &[&str]) -> String {
    let o = run(args);
    assert!(
        o.status.success(),
        "mirrorball {args:?} failed: {}",
        stderr(&o)
    );
    stderr(&o) + &stdout(&o)
}

/// Files in `dir` and its folders (a folder listed as `name/`, then its files as
/// `name/file`), sorted (to check nothing half-written is left).
/// [`files`] less the record a sequence keeps of how it made each output
/// (`.mirrorball-frames`): what the user would call the outputs.
pub fn outputs(dir: &Path) -> Vec<String> {
    files(dir)
        .into_iter()
        .filter(|f| !f.ends_with(".mirrorball-frames"))
        .collect()
}

pub fn files(dir: &Path) -> Vec<String> {
    fn walk(dir: &Path, prefix: &str, v: &mut Vec<String>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let e = e.unwrap();
            let name = format!("{prefix}{}", e.file_name().to_string_lossy());
            if e.file_type().unwrap().is_dir() {
                v.push(format!("{name}/"));
                walk(&e.path(), &format!("{name}/"), v);
            } else {
                v.push(name);
            }
        }
    }
    let mut v = Vec::new();
    walk(dir, "", &mut v);
    v.sort();
    v
}
