//! The library's one error: a message for people, naming the file or the setting and the
//! problem, and whose fault it is (core's [`Fault`]: the input, the request or the system),
//! which front ends turn into an exit status, an HTTP status or a Python exception.

use mirrorball_core::Fault;
use std::fmt;

/// What went wrong, and whose fault it is.
#[derive(Debug)]
pub struct Error {
    /// The message, naming the file and the problem.
    pub message: String,
    /// Whose fault.
    pub fault: Fault,
    /// The kind of the I/O error behind it, if one is ([`Error::io_kind`]).
    io_kind: Option<std::io::ErrorKind>,
}

impl Error {
    /// The request's fault.
    pub fn request(message: impl Into<String>) -> Error {
        Error::new(Fault::Request, message)
    }
    /// The input's fault.
    pub fn input(message: impl Into<String>) -> Error {
        Error::new(Fault::Input, message)
    }
    /// The system's fault.
    pub fn system(message: impl Into<String>) -> Error {
        Error::new(Fault::System, message)
    }
    /// `message`, `fault`'s.
    pub fn new(fault: Fault, message: impl Into<String>) -> Error {
        Error {
            message: message.into(),
            fault,
            io_kind: None,
        }
    }
    /// The kind of the I/O error behind it, if one is: a front end tells a full disk
    /// (`StorageFull`) from the system's other failures by it.
    pub fn io_kind(&self) -> Option<std::io::ErrorKind> {
        self.io_kind
    }
    /// The same fault, with `context` before the message.
    pub fn context(self, context: impl fmt::Display) -> Error {
        Error {
            message: format!("{context}: {}", self.message),
            ..self
        }
    }
}

impl From<mirrorball_core::Error> for Error {
    fn from(e: mirrorball_core::Error) -> Error {
        Error::new(e.fault, e.message)
    }
}

impl From<mirrorball_io::Error> for Error {
    fn from(e: mirrorball_io::Error) -> Error {
        Error {
            io_kind: e.io_kind(),
            ..Error::new(e.fault(), e.to_string())
        }
    }
}

impl From<mirrorball_render::RenderError> for Error {
    fn from(e: mirrorball_render::RenderError) -> Error {
        Error::new(e.fault(), e.to_string())
    }
}

impl From<mirrorball_render::MeshError> for Error {
    fn from(e: mirrorball_render::MeshError) -> Error {
        Error::new(e.fault(), e.to_string())
    }
}

impl From<mirrorball_bake::Error> for Error {
    fn from(e: mirrorball_bake::Error) -> Error {
        Error::new(e.fault, e.message)
    }
}

impl From<mirrorball_spherical::Error> for Error {
    fn from(e: mirrorball_spherical::Error) -> Error {
        Error {
            io_kind: e.io_kind(),
            ..Error::new(e.fault(), e.to_string())
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Error {}
