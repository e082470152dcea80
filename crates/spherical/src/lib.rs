//! # mirrorball-spherical
//!
//! 360° metadata, in pure Rust: what tells a player that a video or photo is a panorama.
//!
//! - **Video** (MP4 and MOV): Spherical Video V2 (`st3d`, and `sv3d` with `svhd` and `proj`:
//!   `prhd` and `equi`, `cbmp`, or for the equi-angular cube a mesh, `mshp`) in each video
//!   track's visual sample entry ([`v2`], [`mesh`]), and V1's GSpherical XML in a `uuid`
//!   box in the track ([`v1`]). [`read`] says what a file carries; [`tag::plan`] rewrites
//!   the movie box with metadata added, replaced or removed, moving chunk offsets as it
//!   grows, and [`tag::Tagging::write_to`] streams the new file (the media data is copied,
//!   never decoded or held in memory).
//! - **Photos**: GPano XMP ([`gpano`]) for lat-long and VR180 pictures, which mirrorball-io
//!   embeds in the PNG and JPEG files it writes.
//!
//! Which of mirrorball's projections each format can state, and how, is one table:
//! [`Mapping`] (see [`mapping`]).
//!
//! Every declared size in a file is checked against the room its container really has
//! before anything is allocated ([`bmff`]). Every function that can fail returns the one
//! [`Error`], which carries core's [`mirrorball_core::Fault`]: a box, payload or XML that
//! breaks its format is the input's ([`Error::malformed`]), metadata a picture's size or
//! the format cannot carry the request's ([`Error::unfit`]); the file's reader names the
//! file ([`Error::at`]).
#![warn(missing_docs)]

pub mod bmff;
mod error;
pub mod gpano;
pub mod mapping;
pub mod mesh;
pub mod movie;
pub mod tag;
pub mod v1;
pub mod v2;
mod xml;

pub use error::Error;
pub use mapping::{Crop, Kind, Mapping};
pub use mesh::crc32;
pub use movie::{read, Reading, VideoTrack};
pub use tag::{plan, Change, Summary, Tagging};
pub use v2::StereoMode;
