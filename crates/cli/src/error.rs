//! The CLI's error: a message for people and whose fault it is, which picks the exit
//! status.

use mirrorball_core::Fault;
use std::fmt;

/// What went wrong, and whose fault it is.
#[derive(Debug)]
pub struct CliError {
    /// The message, naming the file and the problem.
    pub message: String,
    /// Whose fault: the exit status follows ([`CliError::code`]).
    pub fault: Fault,
}

impl CliError {
    /// The request's fault (exit status 2).
    pub fn request(message: impl Into<String>) -> CliError {
        CliError::new(Fault::Request, message)
    }
    /// The input's fault (exit status 1).
    pub fn input(message: impl Into<String>) -> CliError {
        CliError::new(Fault::Input, message)
    }
    /// The system's fault (exit status 1).
    pub fn system(message: impl Into<String>) -> CliError {
        CliError::new(Fault::System, message)
    }
    /// `message`, `fault`'s.
    pub fn new(fault: Fault, message: impl Into<String>) -> CliError {
        CliError {
            message: message.into(),
            fault,
        }
    }
    /// The exit status: 2 when the request cannot be met, 1 when the input or the system
    /// failed.
    pub fn code(&self) -> u8 {
        match self.fault {
            Fault::Request => 2,
            Fault::Input | Fault::System => 1,
        }
    }
    /// The same fault, with `context` before the message.
    pub fn context(self, context: impl fmt::Display) -> CliError {
        CliError {
            message: format!("{context}: {}", self.message),
            fault: self.fault,
        }
    }
}

impl From<mirrorball_io::Error> for CliError {
    fn from(e: mirrorball_io::Error) -> CliError {
        CliError::new(e.fault(), e.to_string())
    }
}

impl From<mirrorball_render::RenderError> for CliError {
    fn from(e: mirrorball_render::RenderError) -> CliError {
        CliError::new(e.fault(), e.to_string())
    }
}

impl From<mirrorball_render::MeshError> for CliError {
    fn from(e: mirrorball_render::MeshError) -> CliError {
        CliError::new(e.fault(), e.to_string())
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}
