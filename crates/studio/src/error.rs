//! The studio's one error: a message for people and whose fault it is (core's [`Fault`]),
//! with the I/O error's kind where one caused it, so that the server answers by cause
//! ([`Error::status`]): the page's request or the file it sent is a 4xx, the machine's
//! failure (a full disk) a 5xx.

use axum::http::StatusCode;
use mirrorball_core::Fault;
use std::fmt;
use std::io::ErrorKind;

/// What went wrong, whose fault it is, and the I/O error's kind when one caused it.
#[derive(Debug, Clone)]
pub struct Error {
    /// The message, naming the file or setting and the problem.
    pub message: String,
    /// Whose fault.
    pub fault: Fault,
    /// The kind of the I/O error behind a system fault (a full disk: `StorageFull`).
    pub io_kind: Option<ErrorKind>,
}

impl Error {
    /// `message`, `fault`'s.
    pub fn new(fault: Fault, message: impl Into<String>) -> Error {
        Error {
            message: message.into(),
            fault,
            io_kind: None,
        }
    }
    /// The request's fault (a setting the page sent).
    pub fn request(message: impl Into<String>) -> Error {
        Error::new(Fault::Request, message)
    }
    /// The input's fault (a file's contents).
    pub fn input(message: impl Into<String>) -> Error {
        Error::new(Fault::Input, message)
    }
    /// The system's fault (the disk, the network, a thread).
    pub fn system(message: impl Into<String>) -> Error {
        Error::new(Fault::System, message)
    }
    /// An I/O error's, `context` before its message: whose fault its kind says
    /// ([`Fault::of_io`]), the kind kept.
    pub fn io(context: impl fmt::Display, e: &std::io::Error) -> Error {
        Error {
            message: format!("{context}: {e}"),
            fault: Fault::of_io(e.kind()),
            io_kind: Some(e.kind()),
        }
    }
    /// The same error, with `context` before the message.
    pub fn context(self, context: impl fmt::Display) -> Error {
        Error {
            message: format!("{context}: {}", self.message),
            ..self
        }
    }
    /// The same error, `kind` its I/O error's.
    pub fn with_io_kind(mut self, kind: Option<ErrorKind>) -> Error {
        self.io_kind = kind;
        self
    }

    /// The HTTP status that answers it: 400 for the request's fault, 422 (Unprocessable
    /// Content) for the input's, 507 (Insufficient Storage) for a full disk or quota, 500
    /// for the system's other failures.
    pub fn status(&self) -> StatusCode {
        match self.fault {
            Fault::Request => StatusCode::BAD_REQUEST,
            Fault::Input => StatusCode::UNPROCESSABLE_ENTITY,
            Fault::System => match self.io_kind {
                Some(ErrorKind::StorageFull | ErrorKind::QuotaExceeded) => {
                    StatusCode::INSUFFICIENT_STORAGE
                }
                _ => StatusCode::INTERNAL_SERVER_ERROR,
            },
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Error {}
