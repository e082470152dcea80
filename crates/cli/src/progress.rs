//! Progress bars for long work, drawn only when stderr is a terminal.
//!
//! A bar's position is read from a counter the work advances. Work measured in
//! `mirrorball_core::work`'s units (the prefilter, the encoders and container writers: about
//! a nanosecond of one core each) runs under [`with_work_progress`], whose bar also counts
//! what the writers finish, so that one bar crosses stages at an even pace and its time
//! left holds from the start.
//!
//! With `MIRRORBALL_PROGRESS_LOG=FILE` in the environment, each bar also appends a line
//! `label seconds position total` to FILE every 50 ms, drawn or not: how a bar's pace and
//! time left are measured (`bench/progress_eta.py`).

use indicatif::{ProgressBar, ProgressStyle};
use std::io::Write;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Runs `work` with a counter it advances; a bar shows `counter / total` meanwhile.
pub fn with_progress<T: Send>(
    label: &str,
    total: u64,
    quiet: bool,
    work: impl FnOnce(Arc<AtomicU64>) -> T + Send,
) -> T {
    run(label, total, quiet, false, work)
}

/// [`with_progress`] for work counted in `mirrorball_core::work`'s units: the bar's
/// position is the counter plus what the process's writers finish meanwhile.
pub fn with_work_progress<T: Send>(
    label: &str,
    total: u64,
    quiet: bool,
    work: impl FnOnce(Arc<AtomicU64>) -> T + Send,
) -> T {
    run(label, total, quiet, true, work)
}

fn run<T: Send>(
    label: &str,
    total: u64,
    quiet: bool,
    writers: bool,
    work: impl FnOnce(Arc<AtomicU64>) -> T + Send,
) -> T {
    let counter = Arc::new(AtomicU64::new(0));
    let log = std::env::var_os("MIRRORBALL_PROGRESS_LOG");
    if (quiet && log.is_none()) || total == 0 {
        return work(counter);
    }
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(total)
    };
    bar.set_length(total);
    // Frames (a sequence's, a video's) are counted one by one: their count and rate shown.
    let template = if matches!(label, "frames" | "video") {
        "{msg:>10} [{bar:40}] {pos}/{len} frames, {per_sec} {elapsed}/{eta}"
    } else {
        "{msg:>10} [{bar:40}] {percent:>3}% {elapsed}/{eta}"
    };
    bar.set_style(
        ProgressStyle::with_template(template)
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_message(label.to_string());
    let mut log = log.and_then(|p| {
        std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(p)
            .ok()
    });
    let written0 = mirrorball_core::work::done();
    let t0 = Instant::now();
    // The updater waits on a channel with a timeout rather than sleeping, so that it ends
    // the moment the work does.
    let (done, wait) = std::sync::mpsc::channel::<()>();
    std::thread::scope(|s| {
        let (c, b) = (counter.clone(), bar.clone());
        let label = label.to_string();
        s.spawn(move || loop {
            let written = match writers {
                true => mirrorball_core::work::done().saturating_sub(written0),
                false => 0,
            };
            let at = (c.load(Ordering::Relaxed) + written).min(total);
            b.set_position(at);
            if let Some(f) = log.as_mut() {
                let _ = writeln!(f, "{label} {:.3} {at} {total}", t0.elapsed().as_secs_f64());
            }
            match wait.recv_timeout(Duration::from_millis(50)) {
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => continue,
                _ => break,
            }
        });
        let out = work(counter.clone());
        drop(done);
        bar.finish_and_clear();
        out
    })
}

/// Runs `write`, the writing of files the writers count (`mirrorball_io::write_work`
/// gives `total`), under a bar; under a spinner when they count nothing (`total` 0).
pub fn writing<T: Send>(total: u64, quiet: bool, write: impl FnOnce() -> T + Send) -> T {
    if total == 0 {
        return with_spinner("writing", quiet, write);
    }
    with_work_progress("writing", total, quiet, |_| write())
}

/// Runs `work` while a spinner with the elapsed time says `label`: for work that cannot
/// count its progress (encoding and writing a file).
pub fn with_spinner<T: Send>(label: &str, quiet: bool, work: impl FnOnce() -> T + Send) -> T {
    if quiet {
        return work();
    }
    let bar = ProgressBar::new_spinner();
    bar.set_style(
        ProgressStyle::with_template("{msg:>10} {spinner} {elapsed}").expect("valid template"),
    );
    bar.set_message(label.to_string());
    bar.enable_steady_tick(Duration::from_millis(100));
    let out = work();
    bar.finish_and_clear();
    out
}

/// The library's [`mirrorball::Hooks`] for a command: lines printed on standard error and
/// progress drawn as a bar, unless quiet.
pub struct Printer {
    pub quiet: bool,
}

impl mirrorball::Hooks for Printer {
    fn note(&self, line: &str) {
        if !self.quiet {
            eprintln!("{line}");
        }
    }

    fn progress(&self, label: &str, total: u64, work: &mut (dyn FnMut(Arc<AtomicU64>) + Send)) {
        with_progress(label, total, self.quiet, work)
    }

    fn work_progress(
        &self,
        label: &str,
        total: u64,
        work: &mut (dyn FnMut(Arc<AtomicU64>) + Send),
    ) {
        with_work_progress(label, total, self.quiet, work)
    }
}
