//! The mirrorball library's integration tests: one binary, one module per concern.
mod bytes;
mod faults;
