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

impl Fault {
    /// Whose fault a failed read of a file is, from the I/O error's kind: a file that is
    /// not there, or ends early, is the input's; one that is there but cannot be read
    /// (permissions, a device error) is the system's.
    pub fn of_io(kind: std::io::ErrorKind) -> Fault {
        match kind {
            std::io::ErrorKind::NotFound | std::io::ErrorKind::UnexpectedEof => Fault::Input,
            _ => Fault::System,
        }
    }
}
