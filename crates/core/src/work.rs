//! Work finished by the writers, counted for progress bars. Encoders and container writers
//! add what they finish as they go, and a bar over a stage that ends in writing files reads
//! [`done`] before and during it: one counter for the process, so that an encoder deep in
//! a container's code needs no handle passed down to it.
//!
//! Units are about a nanosecond of one core on the machine they were measured on, as
//! `mirrorball_filter`'s prefilter counts its own, so that a bar over both stages moves at
//! an even pace: only the ratios between steps matter.

use std::sync::atomic::{AtomicU64, Ordering};

static DONE: AtomicU64 = AtomicU64::new(0);

/// Counts `units` of finished work.
pub fn add(units: u64) {
    DONE.fetch_add(units, Ordering::Relaxed);
}

/// The work finished by this process's writers so far.
pub fn done() -> u64 {
    DONE.load(Ordering::Relaxed)
}
