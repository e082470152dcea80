//! mirrorball-core integration tests: one binary, one module per concern.
mod conventions;
mod layouts;
mod projections;
mod resampling;
mod util;
