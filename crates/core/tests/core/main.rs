//! mirrorball-core integration tests: one binary, one module per concern.
#![allow(clippy::needless_range_loop)]
mod conventions;
mod hostile;
mod layouts;
mod projections;
mod properties;
mod resampling;
mod util;
