//! Whose fault an error is: the one distinction every crate's errors keep, from the
//! library up to the CLI's exit status.

/// Whose fault an error is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Fault {
    /// The input (a file, or data handed to the library) is missing, truncated, corrupt,
    /// or uses something we do not decode.
    Input,
    /// The request cannot be met (wrong extension for the data, unsupported option, values
    /// out of range, options that do not go together).
    Request,
    /// The system failed (permissions, disk full, a reader's own failure).
    System,
}
