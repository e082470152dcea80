//! Frames: many maps of one shape converted by one plan. File-name patterns of sequences
//! ([`pattern`]), slices of a job for array schedulers ([`shard`]), raw video frames in
//! FFmpeg's pixel formats ([`pipe`]), where each texel of a packed raw frame comes from
//! ([`packing`]), the read → convert → write loop ([`pipeline`]), the JSON line a job
//! logs ([`log`]), what made each output so that a rerun skips only its own ([`record`]),
//! and a sequence's or a pipe's run ([`sequence`]: [`run`] a [`FramesRequest`]).

pub mod log;
pub mod packing;
pub mod pattern;
pub mod pipe;
pub mod pipeline;
pub mod record;
pub mod sequence;
pub mod shard;

pub use sequence::{run, FramesRequest};
