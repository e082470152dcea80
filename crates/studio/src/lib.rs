//! `mirrorball studio`: a web server on the loopback interface and the WebGL2 page it
//! embeds, which draws environment-mapped objects the way the CPU renderer
//! (`mirrorball-render`) does.
//!
//! The server does what the core crates do and sends the page what it needs to draw:
//! the scene (camera, objects, environment, as `mirrorball render` reads a scene file),
//! the meshes flattened into world space, and the environment's texels in its own or
//! another projection, each layer padded by one texel that the core's seam rule fills
//! ([`texture`]). The page draws with WebGL2; each projection's direction → texture
//! coordinates has one home, a `.glsl` file under `web/glsl/`.
//!
//! - [`guard`]: who may talk to the server (the token, the Host and Origin headers).
//! - [`state`]: what is loaded, and what the page is told about it (JSON).
//! - [`texture`], [`geometry`], [`grid`]: the binary payloads.
//! - [`lighting`]: the prefiltered GGX chain and the irradiance's SH9.
//! - [`server`]: the routes.
//!
//! Reading files is the embedding program's business ([`Host`]): the `mirrorball` binary
//! reads scenes and environments as its `render` and `convert` commands do, with their
//! messages, and this crate never opens a file by itself.

pub mod analysis;
pub mod error;
pub mod geometry;
pub mod grid;
pub mod guard;
pub mod lighting;
pub mod server;
pub mod state;
pub mod texture;
mod web;

pub use error::Error;
pub use server::{open_browser, Running, Studio};
pub use state::{Opened, SceneView};

use mirrorball_core::EnvMap;
use std::path::Path;

/// What the page asks to download ([`Host::export`]).
pub enum Export<'a> {
    /// A map in its projection: the page's current conversion, or the map as loaded.
    Map(&'a EnvMap),
    /// The prefiltered GGX cube chain the page is lit by, level 0 first.
    Chain(&'a [EnvMap]),
}

/// The containers [`Host::export`] is asked for, by extension: one file each (a chain only
/// in the cube containers, the last two).
pub const EXPORT_FORMATS: [&str; 6] = ["exr", "hdr", "png", "jpg", "ktx2", "dds"];

/// Reads what the studio shows: the files named on the command line and the uploads. Its
/// errors are the messages a person reads (on the command line, or on the page), each
/// with whose fault it is, which the server answers by ([`Error::status`]).
pub trait Host: Send + Sync + 'static {
    /// Reads the file `path` named on the command line: a scene file or an environment.
    fn open(&self, path: &Path) -> Result<Opened, Error>;
    /// Reads an uploaded file called `name` whose contents are `bytes`; `alongside`, the
    /// files uploaded with it (name and contents), are the only files an uploaded scene may
    /// name besides what the host bundles.
    fn upload(
        &self,
        name: &str,
        bytes: &[u8],
        alongside: &[(String, Vec<u8>)],
    ) -> Result<Opened, Error>;
    /// The scene shown before any scene is opened (an environment alone is shown on it).
    fn default_scene(&self) -> SceneView;
    /// `what` written as a file of container `format` (one of [`EXPORT_FORMATS`]), as the
    /// embedding program writes its own outputs: the file's bytes, or why it cannot be.
    fn export(&self, what: Export<'_>, format: &str) -> Result<Vec<u8>, Error>;
    /// The meshes the embedding program bundles, which the page offers beside the
    /// built-ins (none unless it says).
    fn bundled_meshes(&self) -> &'static [&'static str] {
        &[]
    }
    /// The bundled mesh `name` (one of [`Host::bundled_meshes`]).
    fn bundled_mesh(&self, name: &str) -> Result<mirrorball_render::Mesh, Error> {
        Err(Error::request(format!("no bundled mesh {name}")))
    }
}
