//! The mirrorball-io integration tests: one binary, one module per concern.
mod bytes;
mod cube;
mod encoded;
mod flat;
mod hostile;
mod imf_envmap;
mod mutate;
mod openexr;
mod panorama;
mod quality;
mod ranges;
mod records;
