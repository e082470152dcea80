//! Projection specifications on the command line: `NAME[:key=value[:key=value…]]`, parsed
//! by the core crate's [`ProjectionSpec`] (the same text files record; its module documents
//! the keys).

use crate::error::Error;
pub use mirrorball_core::projection::{parse_dir, ProjectionSpec as ProjSpec};
use mirrorball_core::{Choice, Layout};
use mirrorball_io::Precision;

/// Turns an error of a setting into a request error naming the option.
pub fn bad(option: &str, e: impl std::fmt::Display) -> Error {
    Error::request(format!("{option}: {e}"))
}

/// The value of `T` that `given` (the text of `flag`) names, or the request's error
/// `FLAG: unknown 'given' (a, b, c)`, listing the canonical names.
pub fn parse_flag<T: Choice>(flag: &str, given: &str) -> Result<T, Error> {
    T::parse_name(given).map_err(|e| {
        Error::request(format!(
            "{flag}: unknown '{}' ({})",
            e.given.to_ascii_lowercase(),
            e.list()
        ))
    })
}

/// A layout flag's value, if given.
pub fn parse_layout(flag: &str, given: Option<&str>) -> Result<Option<Layout>, Error> {
    given
        .map(str::parse::<Layout>)
        .transpose()
        .map_err(|e| bad(flag, e))
}

/// `--precision`'s value, if given.
pub fn parse_precision(p: Option<&str>) -> Result<Option<Precision>, Error> {
    p.map(|p| parse_flag("--precision", p)).transpose()
}
