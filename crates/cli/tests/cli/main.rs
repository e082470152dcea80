//! mirrorball-cli integration tests: the binary as a user runs it, and conversion quality on
//! the bundled HDRs.
mod analyze;
mod bad_input;
mod bake;
mod batch_docs;
mod commands;
mod frames;
mod hostile;
mod names;
mod outputs;
mod prefilter;
mod production;
mod quality;
mod ranges;
mod render;
mod roundtrip;
mod safety;
mod tables;
mod util;
mod v360;
mod video;
mod views;
mod views_quality;
mod zoneplate;
