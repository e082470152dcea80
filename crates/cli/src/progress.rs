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
    let done = Arc::new(AtomicU64::new(0));
    std::thread::scope(|s| {
        let (c, d, b) = (counter.clone(), done.clone(), bar.clone());
        s.spawn(move || {
            while d.load(Ordering::Relaxed) == 0 {
                b.set_position(c.load(Ordering::Relaxed));
                std::thread::sleep(Duration::from_millis(50));
            }
        });
        let out = work(counter.clone());
        done.store(1, Ordering::Relaxed);
        bar.finish_and_clear();
        out
    })
}
