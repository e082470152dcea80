//! Errors that say whose fault they are.

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub use mirrorball_core::Fault;

/// A file problem, naming the file.
#[derive(Clone, Debug)]
pub struct Error {
    path: PathBuf,
    fault: Fault,
    problem: String,
    source: Option<Arc<std::io::Error>>,
}

/// Equal when the file, the fault, the problem and the I/O error's kind are.
impl PartialEq for Error {
    fn eq(&self, other: &Error) -> bool {
        self.path == other.path
            && self.fault == other.fault
            && self.problem == other.problem
            && self.io_kind() == other.io_kind()
    }
}

impl Error {
    /// The input file's fault.
    pub fn input(path: &Path, problem: String) -> Error {
        Error {
            path: path.to_path_buf(),
            fault: Fault::Input,
            problem,
            source: None,
        }
    }
    /// The request's fault.
    pub fn request(path: &Path, problem: String) -> Error {
        Error {
            path: path.to_path_buf(),
            fault: Fault::Request,
            problem,
            source: None,
        }
    }
    /// The system's fault (a folder that cannot be written, a full disk).
    pub fn system(path: &Path, problem: String) -> Error {
        Error {
            path: path.to_path_buf(),
            fault: Fault::System,
            problem,
            source: None,
        }
    }
    /// The system's fault, from an I/O error. A missing input file is the input's fault.
    pub fn io(path: &Path, e: std::io::Error) -> Error {
        let problem = match e.kind() {
            std::io::ErrorKind::NotFound => "no such file".to_string(),
            std::io::ErrorKind::UnexpectedEof => {
                "file is truncated (unexpected end of file)".to_string()
            }
            std::io::ErrorKind::PermissionDenied => "permission denied".into(),
            _ => e.to_string(),
        };
        let fault = Fault::of_io(e.kind());
        Error {
            path: path.to_path_buf(),
            fault,
            problem,
            source: Some(Arc::new(e)),
        }
    }
    /// The system's fault, from an I/O error writing `path`: a folder that is not there,
    /// cannot be written or is full is the system's whatever the error's kind (a missing
    /// *input* is the input's: [`Error::io`]). The kind is kept ([`Error::io_kind`]).
    pub fn io_write(path: &Path, e: std::io::Error) -> Error {
        let problem = match e.kind() {
            std::io::ErrorKind::NotFound => "cannot write: no such folder".to_string(),
            std::io::ErrorKind::PermissionDenied => "cannot write: permission denied".into(),
            _ => format!("cannot write: {e}"),
        };
        Error {
            path: path.to_path_buf(),
            fault: Fault::System,
            problem,
            source: Some(Arc::new(e)),
        }
    }
    /// Refuses `path` as an input before any reader opens it: missing, a directory, or
    /// empty, each said so ([`mirrorball_core::input_file_problem`]).
    pub fn check_input(path: &Path) -> Result<(), Error> {
        match mirrorball_core::input_file_problem(&std::fs::metadata(path)) {
            None => Ok(()),
            Some((fault, problem)) => Err(Error {
                path: path.to_path_buf(),
                fault,
                problem,
                source: None,
            }),
        }
    }
    /// Whose fault it is.
    pub fn fault(&self) -> Fault {
        self.fault
    }
    /// The file concerned.
    pub fn path(&self) -> &Path {
        &self.path
    }
    /// The kind of the I/O error behind it, if one is (a full disk: `StorageFull`).
    pub fn io_kind(&self) -> Option<std::io::ErrorKind> {
        self.source.as_ref().map(|e| e.kind())
    }
    /// What went wrong, without the file name.
    pub fn problem(&self) -> &str {
        &self.problem
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.path.display(), self.problem)
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.source.as_deref().map(|e| e as _)
    }
}
