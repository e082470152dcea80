//! The crate's one error: the problem, whose fault it is, and the file once it is known.

use mirrorball_core::Fault;
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A problem, whose [`Fault`] it is, and the file it was found in, once known: a box, an
/// XML or a mapping is checked before its file is named (`problem` alone), and the file's
/// reader names it ([`Error::at`]: `path: problem`).
///
/// - **Input**: a file that is not an MP4/MOV, is truncated or corrupt, a box or its
///   payload that breaks the format, or metadata mirrorball cannot read.
/// - **Request**: metadata a picture or format cannot carry (a picture whose size cannot
///   hold the mapping asked for, V1 asked for a cube).
/// - **System**: a read or write that failed for another reason.
#[derive(Clone, Debug)]
pub struct Error {
    path: Option<PathBuf>,
    fault: Fault,
    problem: String,
    source: Option<Arc<std::io::Error>>,
}

/// `path: problem`, or `problem` before the file is known.
impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.path {
            Some(path) => write!(f, "{}: {}", path.display(), self.problem),
            None => f.write_str(&self.problem),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.source.as_deref().map(|e| e as _)
    }
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
    /// The input file's fault: not an MP4/MOV, truncated, corrupt, or using something
    /// not handled.
    pub fn input(path: &Path, problem: impl Into<String>) -> Error {
        Error::new(path, Fault::Input, problem)
    }

    /// The request's fault: metadata the file or the format cannot carry.
    pub fn request(path: &Path, problem: impl Into<String>) -> Error {
        Error::new(path, Fault::Request, problem)
    }

    /// The input's fault, found before its file is named (a box, a payload, an XML):
    /// the file's reader names it with [`Error::at`].
    pub fn malformed(problem: impl Into<String>) -> Error {
        Error::unnamed(Fault::Input, problem)
    }

    /// The request's fault, found before a file is named: metadata a picture or the
    /// format cannot carry (a size that cannot hold a mapping).
    pub fn unfit(problem: impl Into<String>) -> Error {
        Error::unnamed(Fault::Request, problem)
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
            path: Some(path.to_path_buf()),
            problem,
            source: Some(Arc::new(e)),
        }
    }

    pub(crate) fn new(path: &Path, fault: Fault, problem: impl Into<String>) -> Error {
        Error {
            path: Some(path.to_path_buf()),
            ..Error::unnamed(fault, problem)
        }
    }

    fn unnamed(fault: Fault, problem: impl Into<String>) -> Error {
        Error {
            path: None,
            fault,
            problem: problem.into(),
            source: None,
        }
    }

    /// The same error found in `path` (a file already named keeps its name).
    pub fn at(mut self, path: &Path) -> Error {
        self.path.get_or_insert_with(|| path.to_path_buf());
        self
    }

    /// The same error with `context` before the problem: `context: problem`.
    pub fn within(mut self, context: impl fmt::Display) -> Error {
        self.problem = format!("{context}: {}", self.problem);
        self
    }

    /// Whose fault it is.
    pub fn fault(&self) -> Fault {
        self.fault
    }

    /// The file concerned, once known.
    pub fn path(&self) -> Option<&Path> {
        self.path.as_deref()
    }

    /// What went wrong, without the file's name.
    pub fn problem(&self) -> &str {
        &self.problem
    }

    /// The kind of the I/O error behind it, if one is (a full disk: `StorageFull`).
    pub fn io_kind(&self) -> Option<std::io::ErrorKind> {
        self.source.as_ref().map(|e| e.kind())
    }
}
