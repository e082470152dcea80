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

/// A conversion ([`crate::resample`]) per source texel (its pyramid built and read) and per
/// output texel made.
const RESAMPLE_SRC: u64 = 40;
const RESAMPLE_OUT: u64 = 40;

/// The work of converting a map of `src_texels` texels into one of `out_texels`.
pub fn resample(src_texels: u64, out_texels: u64) -> u64 {
    src_texels * RESAMPLE_SRC + out_texels * RESAMPLE_OUT
}

/// A layer's texel copied into a packed picture ([`crate::Layout::pack`]; the picture's
/// allocation included).
pub const PACK: u64 = 50;

/// Counts `units` of finished work.
pub fn add(units: u64) {
    DONE.fetch_add(units, Ordering::Relaxed);
}

/// The work finished by this process's writers so far.
pub fn done() -> u64 {
    DONE.load(Ordering::Relaxed)
}
