//! The memory each command says it needs before it starts (the refusal under
//! `--max-memory 1`: "needs about N of memory") held to the peak resident memory of the same
//! run measured by the kernel: at least 0.9× the peak (a job that fits is not refused for
//! want of a margin, one that does not fit is refused before it starts) and at most 1.5×.
//! Each run peaks at a few hundred MB, where the job's maps dominate the process's own.
//!
//! A test binary of its own: a child's `ru_maxrss` is the larger of its own peak and the
//! resident memory of the process it was spawned from (the kernel counts the memory it
//! leaves at `exec`), so a child's measured peak is its own only when it is above this
//! process's peak, which the other tests' in-process maps would not let it be (this one's,
//! mostly its own mapped binary, is about 100 MB).

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn asset(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/env")
        .join(name)
}

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mirrorball"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// This process's own peak resident memory, in bytes.
fn own_peak() -> u64 {
    // SAFETY: `rusage` is plain integers and structs of them: all zeros is a valid value.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: a pointer to a local that outlives the call.
    let r = unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) };
    assert_eq!(r, 0, "getrusage");
    usage.ru_maxrss as u64 * 1024
}

/// The estimate `mirrorball args` states when refused under `--max-memory 1`, in bytes.
fn estimate(args: &[&str]) -> u64 {
    let o = run(&[args, &["--max-memory", "1", "-q"][..]].concat());
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
    let about = e
        .split("needs about ")
        .nth(1)
        .unwrap_or_else(|| panic!("{args:?} states no estimate: {e}"));
    let mut words = about.split_whitespace();
    let n: f64 = words.next().and_then(|w| w.parse().ok()).expect("a number");
    let unit = match words.next() {
        Some("GB") => 1e9,
        Some("MB") => 1e6,
        Some("kB") => 1e3,
        u => panic!("{args:?}: unit {u:?} in {e}"),
    };
    (n * unit) as u64
}

/// The peak resident memory of `mirrorball args`, in bytes (its own, from `wait4`); the run
/// must succeed (its stderr goes to `log`).
fn peak(args: &[&str], log: &Path) -> u64 {
    // Reaped below by `wait4`, which also gives its resource use.
    #[allow(clippy::zombie_processes)]
    let child = Command::new(env!("CARGO_BIN_EXE_mirrorball"))
        .args(args)
        .arg("-q")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(log).unwrap())
        .spawn()
        .expect("the binary runs");
    let mut status = 0;
    // SAFETY: `rusage` is plain integers and structs of them: all zeros is a valid value.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: this child's id and pointers to two locals that outlive the call; the child is
    // reaped here, once (std's `Child`, dropped unwaited, leaves it be).
    let pid = unsafe { libc::wait4(child.id() as libc::pid_t, &mut status, 0, &mut usage) };
    assert_eq!(pid, child.id() as libc::pid_t, "wait4");
    assert!(
        libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0,
        "mirrorball {args:?} failed: {}",
        std::fs::read_to_string(log).unwrap_or_default()
    );
    // Linux counts `ru_maxrss` in KiB.
    usage.ru_maxrss as u64 * 1024
}

#[test]
fn estimates_hold_to_the_measured_peak() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let city = asset("city.exr");
    let city = city.to_str().unwrap();
    // Sources: lat-long maps of 1024×512 and 2048×1024 texels, and a sequence of three.
    for size in ["1024", "2048"] {
        let out = p(&format!("ll{size}.exr"));
        let args = [
            "convert", city, &out, "--to", "latlong", "--size", size, "-q",
        ];
        let o = run(&args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    }
    let (ll1k, ll2k) = (p("ll1024.exr"), p("ll2048.exr"));
    std::fs::create_dir(p("seq")).unwrap();
    for i in 1..=3 {
        std::fs::copy(&ll2k, p(&format!("seq/f{i}.exr"))).unwrap();
    }
    std::fs::create_dir(p("frames")).unwrap();
    std::fs::create_dir(p("bevy")).unwrap();
    std::fs::create_dir(p("ktx2")).unwrap();
    let (seq, frames) = (p("seq/f%d.exr"), p("frames/o%d.exr"));
    let (cube, ll, ktx2, r) = (p("cube.exr"), p("ll.exr"), p("chain.ktx2"), p("r.exr"));
    let (bevy, ktx2_bake) = (p("bevy"), p("ktx2"));
    let cases: Vec<Vec<&str>> = vec![
        // Down to a cube in a cross (the picture twice the faces).
        vec!["convert", &ll2k, &cube, "--to", "cube", "--size", "1024"],
        // Up from a small map: the output and its packed copy.
        vec!["convert", city, &ll, "--to", "latlong", "--size", "4096"],
        // A stereo pair from one eye: both eyes, packed and joined.
        vec![
            "convert", &ll2k, &cube, "--to", "cube", "--size", "512", "--stereo", "tb",
        ],
        // Frames in flight.
        vec!["convert", &seq, &frames, "--to", "cube", "--size", "1024"],
        vec!["render", "--env", city, "--size", "2500x2500", "-o", &r],
        // A chain finer than the source: the working cube stays at the source's density.
        vec!["prefilter", &ll1k, &ktx2, "--lobe", "ggx", "--size", "1024"],
        // A chain as fine as the source: level 0 is the working cube itself.
        vec!["prefilter", &ll2k, &ktx2, "--lobe", "ggx", "--size", "1024"],
        vec![
            "bake",
            &ll1k,
            "--for",
            "ktx2",
            &ktx2_bake,
            "--size",
            "1024",
            "--samples",
            "16",
        ],
        vec![
            "bake",
            &ll1k,
            "--for",
            "bevy",
            &bevy,
            "--size",
            "1024",
            "--samples",
            "16",
        ],
    ];
    let mut table = Vec::new();
    let mut wrong = Vec::new();
    let mut least_peak = u64::MAX;
    for args in &cases {
        let t = std::time::Instant::now();
        let est = estimate(args);
        let peak = peak(args, &dir.path().join("log.txt"));
        least_peak = least_peak.min(peak);
        let secs = t.elapsed().as_secs_f64();
        let ratio = est as f64 / peak as f64;
        let line = format!(
            "{:<60} estimate {:>5} MB, peak {:>5} MB, {ratio:.2}x ({secs:.1}s)",
            args.join(" ").replace(dir.path().to_str().unwrap(), ""),
            est / 1_000_000,
            peak / 1_000_000
        );
        assert!(peak > 150_000_000, "a case too small to judge: {line}");
        if !(0.9..=1.5).contains(&ratio) {
            wrong.push(line.clone());
        }
        table.push(line);
        // Frames a rerun would skip.
        let _ = std::fs::remove_dir_all(p("frames"));
        std::fs::create_dir(p("frames")).unwrap();
    }
    println!("{}", table.join("\n"));
    // A child's peak is the larger of its own and what it inherits of this process (see the
    // module's note): above this process's peak, it is the child's own.
    assert!(
        own_peak() < least_peak,
        "the test process peaked at {} MB, a child at {} MB: the children's peaks may be this process's",
        own_peak() / 1_000_000,
        least_peak / 1_000_000
    );
    assert!(
        wrong.is_empty(),
        "estimates outside 0.9–1.5× the peak:\n{}\n(all:\n{})",
        wrong.join("\n"),
        table.join("\n")
    );
}
