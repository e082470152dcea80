//! mirrorball-cli integration tests: the binary as a user runs it, and conversion quality on
//! the bundled HDRs.
mod analyze;
mod bad_input;
mod commands;
#[allow(dead_code)]
#[path = "../../src/error.rs"]
mod error;
mod hostile;
mod prefilter;
mod quality;
mod render;
#[allow(dead_code)]
#[path = "../../src/spec.rs"]
mod spec;
mod util;
