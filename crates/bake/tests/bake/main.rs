//! mirrorball-bake integration tests: each engine's files read back by readers that are not
//! mirrorball's (`ddsfile` and `texture2ddecoder` for DDS BC6H, `ktx` for Filament's KTX1,
//! the `ktx2` crate), their texels against the float chain, their axes against a
//! direction-coded environment, and the request's checks.
mod common;
mod dds;
mod filament;
mod flow;
mod folder;
mod ktx2;
