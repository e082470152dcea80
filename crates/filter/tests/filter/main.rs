//! mirrorball-filter integration tests: one binary, one module per concern.
//!
//! Accuracy is stated in two norms over a set of directions (a spherical Fibonacci lattice
//! of at least 256, so every direction counts about equally):
//!
//! * relative L2: `‖P − R‖₂ / ‖R‖₂`, the sums running over directions and RGB channels —
//!   the asserted norm (< 1% Lambert, < 2% GGX and Phong);
//! * per-direction relative error `Σ_c |P_c − R_c| / Σ_c |R_c|`, whose maximum is reported
//!   (printed with `--nocapture`) and bounded more loosely where the reference is dark.
#![allow(clippy::needless_range_loop)]
mod accuracy;
mod brdf;
mod furnace;
mod lobe_shape;
mod mips;
mod robust;
mod samplers;
mod seams;
mod sh;
mod util;
