//! mirrorball-render integration tests: analytic checks of every indexing mode, the GL
//! texgen formula, meshes and loading, and small golden images.
mod analytic;
mod capture;
mod features;
mod golden;
mod hostile;
mod meshes;
mod names;
mod util;
