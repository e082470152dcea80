//! Mode 4, Greene's reflection cones (Greene 1986, §5–6): the rays through a pixel's four
//! corners, reflected off the surface, bound a region of the world projection; that region
//! is filtered rather than point-sampled, so a highly curved surface (where a pixel's
//! reflected rays fan out over much of the sphere) does not alias. The background is filtered
//! the same way over the pixel's primary-ray footprint.
//!
//! The corner rays are found on the hit triangle's plane extended to the pixel's corners,
//! with the normal interpolated there (the triangle's barycentric coordinates
//! extrapolated). Their spread is the pixel's footprint as ray differentials,
//! `∂d/∂x = ½((c₁ − c₀) + (c₂ − c₃))` and `∂d/∂y = ½((c₃ − c₀) + (c₂ − c₁))` for corners in
//! pixel order `(−,−) (+,−) (+,+) (−,+)` ([`crate::lookup::footprint`]), and the region is
//! filtered by `mirrorball_filter::Sampler` over the filter crate's solid-angle-weighted mip
//! pyramid, built once per environment ([`crate::EnvCache`]): Heckbert's EWA by default,
//! or trilinear when the environment's filter is [`crate::Filter::Trilinear`]. The footprint
//! is carried to texture space through the projection's Jacobian, so the same cone filters
//! the same piece of sphere whatever the projection.
