//! # mirrorball
//!
//! Environment (reflection) maps and world projections, as one library under every front
//! end: the `mirrorball` command line, the studio and the Python package call these
//! functions; none of them decides a file's contents or a conversion itself.
//!
//! The layers below it are re-exported: [`core`] (projections, maps, layouts, resampling
//! and planned remaps; no I/O), [`io`] (every container, atomic writes), [`filter`] (mip
//! pyramids, samplers, SH9, prefiltering) and [`renderer`] (the CPU renderer).
//!
//! ## Reading and writing
//! - [`load`]: a file (or one file per layer, `{face}` in the name) into an [`EnvMap`] with
//!   its projection and layout, from what the file records or guessed from its shape
//!   ([`InputPlan`] says what the caller knows); [`load::read_prepared`] also zeroes
//!   invalid values and returns the lines saying what was decided; [`load::from_bytes`]
//!   reads a file's contents held in memory the same way.
//! - [`save`]: a map into any writable container; the extension picks it
//!   ([`save::check`] refuses a container or layout that cannot hold the projection before
//!   any work), [`save::SaveOptions`] the precision, layout and compression;
//!   [`save::to_bytes`] makes the same file in memory.
//! - [`fit`]: what an output cannot hold, measured before it is written.
//!
//! ## Limits, checked before any work
//! - [`size`]: one size rule for every command (the container's and the reader's bound).
//! - [`budget`]: memory estimates, refused with a message when a job would not fit.
//! - [`guard`]: no output is an input or another output; every output can be written.
//!
//! ## Conversions
//! - [`convert`]: a [`convert::ConvertRequest`] (plain values) becomes a checked
//!   [`convert::ConvertPlan`] before any file is read; the plan reads, checks memory and
//!   converts.
//! - [`frames`]: many frames by one planned remap: file-name patterns, `--shard i/n`, raw
//!   video frames as FFmpeg's `rawvideo` pixel formats (`pipe`), the packing of a planned
//!   remap straight into output bytes, the three-stage read → convert → write loop
//!   (`pipeline`), and [`frames::run`] of a [`frames::FramesRequest`].
//!
//! - [`render`]: a [`render::RenderRequest`] (the scene file's schema and the materials'
//!   grammar in [`render::schema`] and [`materials`]) becomes a checked
//!   [`render::RenderPlan`]; [`render::run`] loads, renders and writes.
//!
//! - [`prefilter`]: a [`prefilter::PrefilterRequest`] becomes a checked
//!   [`prefilter::Plan`]; [`prefilter::run`] reads, prefilters and writes the chain, its SH9
//!   JSON, preview and BRDF table.
//!
//! - [`views`]: a [`views::ViewsRequest`] becomes a checked [`views::ViewsPlan`];
//!   [`views::run`] cuts a panorama into a rig of pinhole views and writes them with the
//!   camera files COLMAP and nerfstudio read, and masks of what the panorama covers.
//!
//! Long jobs tell their caller what they do through [`Hooks`] (lines for people, progress);
//! [`Quiet`] says nothing.
//!
//! ## Errors
//! Every function returns [`Error`]: a message naming the file or setting and the problem,
//! and its [`Fault`] (the input, the request or the system).

pub mod bake;
pub mod budget;
pub mod compare;
pub mod convert;
pub mod demo;
pub mod error;
pub mod fit;
pub mod frames;
pub mod guard;
pub mod hooks;
pub mod info;
pub mod load;
pub mod materials;
pub mod prefilter;
pub mod render;
pub mod save;
pub mod size;
pub mod spec;
pub mod v360;
pub mod views;

pub use error::Error;
pub use hooks::{Hooks, Quiet};
pub use load::{load, InputPlan, Source};
pub use mirrorball_core as core;
pub use mirrorball_core::{EnvMap, Fault, Layout, Projection, ProjectionKind};
pub use mirrorball_filter as filter;
pub use mirrorball_io as io;
pub use mirrorball_render as renderer;
pub use mirrorball_spherical as spherical;
pub use save::{save, SaveOptions, Saved};
pub use spec::ProjSpec;
