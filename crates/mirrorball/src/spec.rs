//! Projection specifications on the command line: `NAME[:key=value[:key=value…]]`, parsed
//! by the core crate's [`ProjectionSpec`] (the same text files record; its module documents
//! the keys).

use crate::error::Error;
pub use mirrorball_core::projection::{parse_dir, ProjectionSpec as ProjSpec};

/// Turns a CLI string error into a request error naming the option.
pub fn bad(option: &str, e: String) -> Error {
    Error::request(format!("{option}: {e}"))
}
