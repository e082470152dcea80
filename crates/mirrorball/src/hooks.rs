//! What a long job tells its caller while it runs: lines for people (what was read and
//! decided, warnings, what was written) and the progress of its work. The CLI prints the
//! lines and draws bars; the studio and Python keep or drop them; [`Quiet`] drops all.

use std::sync::atomic::AtomicU64;
use std::sync::Arc;

/// A job's caller.
pub trait Hooks: Sync {
    /// A line for people.
    fn note(&self, line: &str);

    /// Runs `work`, which advances the counter it is given towards `total` (a job's units:
    /// frames, rows), while the caller shows it as `label`.
    fn progress(&self, label: &str, total: u64, work: &mut (dyn FnMut(Arc<AtomicU64>) + Send));
}

/// Hooks that say nothing and show nothing.
pub struct Quiet;

impl Hooks for Quiet {
    fn note(&self, _: &str) {}

    fn progress(&self, _: &str, _: u64, work: &mut (dyn FnMut(Arc<AtomicU64>) + Send)) {
        work(Arc::new(AtomicU64::new(0)))
    }
}
