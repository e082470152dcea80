//! # mirrorball-analysis
//!
//! Measures every world projection's distortion and error, exactly, from the same projection
//! code the converter uses ([`mirrorball_core::WorldProjection`]), and draws it.
//!
//! * [`texels`]: per-texel solid angle (full and rim texels), anisotropy, used area, front and
//!   back shares, the front/back crossover radius; sizes for an equal texel budget.
//! * [`profile`]: Zimmons' one-dimensional measure (angle per pixel from the centre out).
//! * [`cone`]: the region a reflection cone covers (Greene's figure 2).
//! * [`frustum`]: the share of the sphere a camera frustum sees (Greene §9).
//! * [`indexing`]: per-vertex versus per-pixel reflection vectors and texture coordinates on
//!   a mirror line, a mirror quad and a tessellated sphere (Zimmons' figures 34–36).
//! * [`claims`]: the seed documents' numbers against ours.
//! * [`report`], [`plot`], [`png`]: the report as JSON, SVG and HTML text (no file I/O here:
//!   everything is returned as strings; `mirrorball analyze` writes them).
//!
//! ```
//! use mirrorball_analysis::texels::{crossover, texel_stats};
//! use mirrorball_core::ProjectionKind;
//! let sphere = ProjectionKind::Sphere.default_projection();
//! // Zimmons: the front/back crossover of a sphere map is at 1/(2√2) in texture units.
//! let c = crossover(&sphere, 512).unwrap();
//! assert!((c.radius_uv - 0.5 / 2f64.sqrt()).abs() < 1e-12);
//! // The sphere map is equal-area: every full texel sees the same solid angle.
//! let s = texel_stats(&sphere, 32);
//! assert!((s.full.ratio - 1.0).abs() < 1e-9);
//! ```
//!
//! **Cost.** [`analyze`] with every projection at a budget of 6×512² texels (1.57 M texels
//! each: a 1254² sphere map, a 1774×887 lat-long) evaluates every texel's exact solid angle
//! and Jacobian, about 11 s of CPU time in a release build, spread over the cores by rayon:
//! `time target/release/mirrorball analyze --texel-budget 1572864 --out /tmp/a` took 5.9–6.4 s
//! on the project's 2-core machine (shared with other work). The exact solid angles of the
//! continuous cube, angular map and fisheye (Gauss–Legendre over transcendental integrands)
//! are the largest part.
#![warn(missing_docs)]

pub mod claims;
pub mod cone;
pub mod frustum;
pub mod geom;
pub mod indexing;
pub mod jacobian;
pub mod plot;
pub mod png;
pub mod profile;
pub mod report;
pub mod texels;

pub use report::{
    analyze, analyze_projection, html, json, Analysis, Config, Figure, ProjectionEntry, Report,
    Sizing,
};
