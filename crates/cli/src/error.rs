//! The CLI's error: a message for people and an exit status.

use std::fmt;

/// What went wrong, and the exit status it earns.
#[derive(Debug)]
pub struct CliError {
    /// The message, naming the file and the problem.
    pub message: String,
    /// 1: the input or the system failed; 2: the request cannot be met.
    pub code: i32,
}

impl CliError {
    /// The request's fault (exit status 2).
    pub fn request(message: impl Into<String>) -> CliError {
        CliError {
            message: message.into(),
            code: 2,
        }
    }
    /// The input's or the system's fault (exit status 1).
    pub fn input(message: impl Into<String>) -> CliError {
        CliError {
            message: message.into(),
            code: 1,
        }
    }
}

impl From<mirrorball_io::Error> for CliError {
    fn from(e: mirrorball_io::Error) -> CliError {
        let code = match e.fault() {
            mirrorball_io::Fault::Request => 2,
            _ => 1,
        };
        CliError {
            message: e.to_string(),
            code,
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}
