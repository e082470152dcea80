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

/// Why a path named as an input cannot be read as a file, with whose fault it is, from what
/// `std::fs::metadata(path)` returned (core does no I/O: the caller looks): not there (the
/// input's), a directory (the input's), a file of 0 bytes (the input's, called empty, not
/// truncated), or the system's reason (permissions, a folder in the path that is a file).
/// `None` for a regular file with bytes in it, and for anything else that is there (a
/// pipe or a device: its length says nothing). Every reader of input files (images,
/// meshes, scenes, manifests) asks it first, so each says these the same way.
///
/// ```
/// use mirrorball_core::{input_file_problem, Fault};
/// let dir = std::env::temp_dir();
/// let (fault, problem) = input_file_problem(&std::fs::metadata(&dir)).unwrap();
/// assert_eq!((fault, problem.as_str()), (Fault::Input, "is a directory, not a file"));
/// let none = std::fs::metadata(dir.join("no-such-file-here.exr"));
/// assert_eq!(input_file_problem(&none).unwrap().1, "no such file");
/// ```
pub fn input_file_problem(meta: &std::io::Result<std::fs::Metadata>) -> Option<(Fault, String)> {
    use std::io::ErrorKind;
    match meta {
        Err(e) => Some(match e.kind() {
            ErrorKind::NotFound => (Fault::Input, "no such file".to_string()),
            ErrorKind::PermissionDenied => (Fault::System, "permission denied".to_string()),
            k => (Fault::of_io(k), e.to_string()),
        }),
        Ok(m) if m.is_dir() => Some((Fault::Input, "is a directory, not a file".to_string())),
        Ok(m) if m.is_file() && m.len() == 0 => {
            Some((Fault::Input, "the file is empty (0 bytes)".to_string()))
        }
        Ok(_) => None,
    }
}

/// The core's error: a message for people, naming the setting or value and the problem,
/// and whose fault it is. A projection's or layout's text that cannot be read, a value
/// out of its range, a picture a layout cannot unpack: the request's (the caller named
/// them); front ends keep the fault as they pass the message on.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Error {
    /// The message.
    pub message: String,
    /// Whose fault.
    pub fault: Fault,
}

impl Error {
    /// The request's fault.
    pub fn request(message: impl Into<String>) -> Error {
        Error {
            message: message.into(),
            fault: Fault::Request,
        }
    }
    /// The input's fault.
    pub fn input(message: impl Into<String>) -> Error {
        Error {
            message: message.into(),
            fault: Fault::Input,
        }
    }
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Error {}
