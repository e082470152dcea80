//! # mirrorball-core
//!
//! The I/O-free heart of mirrorball: every world projection, exact in both directions and
//! with exact texel solid angles; environment maps; layouts; and antialiased conversion
//! between any two projections. No file I/O and no argument parsing happen here, so other
//! programs can embed it.
//!
//! ```
//! use mirrorball_core::{EnvMap, Projection, ProjectionKind, WorldProjection, resample, ResampleOptions};
//! // A small analytic environment: brightness = height of the direction.
//! let src = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 64, 3, |d| {
//!     [d.y as f32 + 1.0, 1.0, 1.0, 1.0]
//! });
//! let cube = resample(&src, ProjectionKind::Cube.default_projection(), 16, &ResampleOptions::default());
//! assert_eq!(cube.layers().len(), 6);
//! ```
#![warn(missing_docs)]

mod axis_map;
pub mod choice;
mod codes;
pub mod color;
mod envmap;
mod fault;
mod image;
pub mod layout;
pub mod metrics;
pub mod par;
pub mod projection;
mod remap;
mod resample;
pub mod work;

pub use axis_map::AxisMap;
pub use choice::{count, Choice, UnknownName};
pub use codes::{Codes, CodesError, Plane};
pub use envmap::{
    bilinear_blend, bilinear_corner, bilinear_corner4, bilinear_corner8, bilinear_mix,
    bilinear_taps, count_invalid, sample_texels, sanitize_layer, CornerLanes, EnvMap, EnvMapError,
    Stats,
};
pub use fault::{input_file_problem, Error, Fault};
pub use image::Image;
pub use layout::{guess, CellGrid, CubeCells, Guess, Layout, Stereo};
pub use projection::types::*;
pub use projection::{
    DirRun, Lookup, Projection, ProjectionKind, UnknownProjection, WorldProjection,
};
pub use remap::{Remap, RemapError, RemapRows};
pub use resample::{
    resample, resample_memory, resample_to_extent, Axis, Outside, ResampleOptions, Resampler,
    Rotation,
};

pub use glam;
/// The SIMD lanes the fast variants are written on.
pub use mirrorball_simd as simd;
pub use projection::{derivative, quadrature};
