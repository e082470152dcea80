//! Progress bars for long work, drawn only when stderr is a terminal.

use indicatif::{ProgressBar, ProgressStyle};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// Runs `work` with a counter it advances; a bar shows `counter / total` meanwhile.
pub fn with_progress<T: Send>(
    label: &str,
    total: u64,
    quiet: bool,
    work: impl FnOnce(Arc<AtomicU64>) -> T + Send,
) -> T {
    let counter = Arc::new(AtomicU64::new(0));
    if quiet || total == 0 {
        return work(counter);
    }
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template("{msg:>10} [{bar:40}] {percent:>3}% {elapsed}/{eta}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_message(label.to_string());
    // The updater waits on a channel with a timeout rather than sleeping, so that it ends
    // the moment the work does.
    let (done, wait) = std::sync::mpsc::channel::<()>();
    std::thread::scope(|s| {
        let (c, b) = (counter.clone(), bar.clone());
        s.spawn(move || loop {
            b.set_position(c.load(Ordering::Relaxed));
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
