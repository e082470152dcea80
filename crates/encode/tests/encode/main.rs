//! The mirrorball-encode integration tests: one binary, one module per concern.
mod bc6h;
mod formats;
