//! The crate's one error: a file, the problem, and whose fault it is.

use mirrorball_core::Fault;
use std::path::{Path, PathBuf};

/// A problem with a file, naming it, and whose [`Fault`] it is.
#[derive(Debug, thiserror::Error)]
#[error("{}: {problem}", path.display())]
pub struct Error {
    path: PathBuf,
    fault: Fault,
    problem: String,
    #[source]
    source: Option<std::io::Error>,
}

impl Error {
    /// The input file's fault: not an MP4/MOV, truncated, corrupt, or using something
    /// not handled.
    pub fn input(path: &Path, problem: impl Into<String>) -> Error {
        Error::new(path, Fault::Input, problem)
    }

    /// The request's fault: metadata the file or the format cannot carry.
    pub fn request(path: &Path, problem: impl Into<String>) -> Error {
        Error::new(path, Fault::Request, problem)
    }

    /// A failed read or write of `path`: a missing or cut-off file is the input's fault,
    /// any other failure the system's.
    pub fn io(path: &Path, e: std::io::Error) -> Error {
        let problem = match e.kind() {
            std::io::ErrorKind::NotFound => "no such file".to_string(),
            std::io::ErrorKind::UnexpectedEof => {
                "file is truncated (unexpected end of file)".into()
            }
            std::io::ErrorKind::PermissionDenied => "permission denied".into(),
            _ => e.to_string(),
        };
        Error {
            fault: Fault::of_io(e.kind()),
            path: path.to_path_buf(),
            problem,
            source: Some(e),
        }
    }

    pub(crate) fn new(path: &Path, fault: Fault, problem: impl Into<String>) -> Error {
        Error {
            path: path.to_path_buf(),
            fault,
            problem: problem.into(),
            source: None,
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

    /// What went wrong, without the file's name.
    pub fn problem(&self) -> &str {
        &self.problem
    }
}
