//! # mirrorball-filter
//!
//! Filtering and prefiltered lighting on top of `mirrorball-core` (no file I/O, no argument
//! parsing). Greene's "Applications of World Projections" (1986) is the starting point: a
//! reflection cone covers a region of the world projection, and that region must be
//! filtered; diffuse and specular illumination come from prefiltered maps — today, mip
//! mapped cube maps.
//!
//! ## Sampling
//!
//! * [`mip`]: mip pyramids for every projection, built with exact solid-angle weights (box,
//!   energy-exact, or a tent that filters across cube edges and corners, the longitude wrap
//!   and the poles through [`WorldProjection::wrap_texel`](mirrorball_core::WorldProjection::wrap_texel)).
//! * [`sampler`]: nearest, bilinear, trilinear, EWA (Greene & Heckbert; Heckbert) and
//!   summed-area-table ([`sat`], Crow) lookups over any projection, given a direction and a
//!   [`Footprint`] (a cone or ray differentials) carried to texture space through the
//!   projection's Jacobian; EWA weights texels by their elliptical distance measured on the
//!   sphere, so the same cone gives the same result on a cube, a sphere map or a lat-long
//!   map (tested to 1%).
//!
//! ## Prefiltered maps
//!
//! A [`Prefilterer`] takes a map of any projection and renders lobes into any projection:
//! every output texel is the lobe's prefiltered value at its own centre direction,
//! `P(n) = ∫ L K(n·l) dω / ∫ K(n·l) dω` (see [`lobe`]), so a constant environment comes out
//! constant and a cube output has no seams.
//!
//! * **Lambert** (`E/π`, Miller & Hoffman's and Greene's diffuse illumination map):
//!   [`irradiance`]'s moment hierarchy gives the brute-force texel sum to a tolerance
//!   (≈1e-5 relative) at a few thousand operations per direction; [`sh`] gives the nine
//!   coefficients of Ramamoorthi & Hanrahan, projected with exact texel solid angles, with
//!   Hann, Lanczos or automatic (non-negative) windows against ringing.
//! * **Phong** (`max(r·l, 0)^s`, Miller & Hoffman, Greene) and **GGX** (split-sum, Karis
//!   2013): [`specular`]'s filtered importance sampling (Křivánek & Colbert 2008) in a
//!   seamless solid-angle-weighted pyramid of a working cube, with the texels brighter than
//!   8× the mean split off and summed exactly as point sources through a cluster tree (so a
//!   sun costs little and blurs correctly); one roughness per mip level with the linear,
//!   UE4 and Filament mappings ([`RoughnessMapping`]).
//! * [`brdf_lut`]: the split-sum `(A, B)` table; [`robust`]: clamping or soft compression of
//!   extreme texels with an account of the energy removed.
//! * [`reference`](mod@reference): the brute-force sums every fast path is tested against.
//!
//! ## Accuracy (tests, 256 Fibonacci directions)
//!
//! Norm: relative L2 over directions and RGB channels, `‖P − R‖₂/‖R‖₂`, against
//! [`BruteForce`] on the bundled HDRs (as 6×128² cubes), an analytic environment and a
//! lat-long source: Lambert ≤ 1e-4 (bound 1%), GGX roughness 0.1–1 and Phong ≤ 3e-3
//! (bound 2%). SH9 coefficients match the plain `f64` projection to 2e-7 of the largest.
//!
//! ```
//! use mirrorball_core::{EnvMap, ProjectionKind};
//! use mirrorball_filter::{chain_lobes, Lobe, LobeKind, PrefilterOptions, Prefilterer, RoughnessMapping};
//! let sky = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 64, 3, |d| {
//!     let v = (1.0 + d.y) as f32;
//!     [v, v, v, 1.0]
//! });
//! let pf = Prefilterer::new(&sky, PrefilterOptions::default());
//! let cube = ProjectionKind::Cube.default_projection();
//! let lobes = chain_lobes(LobeKind::Ggx, &RoughnessMapping::Linear, 5);
//! let chain = pf.render_chain(&lobes, cube, 16); // 16², 8², 4², 2², 1²
//! assert_eq!(chain.len(), 5);
//! let irradiance = pf.render(&Lobe::Lambert, cube, 8);
//! // Facing up, a white Lambertian surface sees the bright upper sky: E/π = 1 + 2/3.
//! let up = irradiance.sample(mirrorball_core::glam::DVec3::Y)[0];
//! assert!((up - 5.0 / 3.0).abs() < 0.02, "{up}");
//! ```
#![warn(missing_docs)]

pub mod brdf_lut;
mod bright;
mod cube;
pub mod directions;
pub mod irradiance;
pub mod lobe;
pub mod mip;
mod prefilter;
pub mod reference;
pub mod robust;
pub mod sampler;
pub mod sat;
pub mod sh;
pub mod specular;

pub use brdf_lut::{BrdfLut, Visibility};
pub use irradiance::IrradianceMethod;
pub use lobe::{Lobe, LobeKind};
pub use mip::{MipChain, MipFilter};
pub use prefilter::{chain_lobes, chain_work, cube_work, work, PrefilterOptions, Prefilterer};
pub use reference::BruteForce;
pub use robust::{compress, Compression, EnergyReport};
pub use sampler::{Filter, Footprint, Sampler};
pub use sat::SummedAreaTable;
pub use sh::{Sh9, Window};
pub use specular::RoughnessMapping;
