//! mirrorball-cli integration tests: the binary as a user runs it, and conversion quality on
//! the bundled HDRs.
mod analyze;
mod bad_input;
mod commands;
mod prefilter;
mod production;
mod quality;
mod render;
mod util;
