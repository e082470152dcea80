//! Errors by whose fault they are: the request's a `ValueError` (or `TypeError`) naming the
//! argument, the input's `mirrorball.InputError` (a `ValueError`), a file that is missing or
//! cannot be read the `OSError` Python itself raises (`FileNotFoundError`,
//! `PermissionError`), the system's an `OSError`.

use mirrorball_core::Fault;
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use std::path::Path;

pyo3::create_exception!(
    mirrorball,
    InputError,
    PyValueError,
    "A file (or data) whose content mirrorball cannot use: truncated, corrupt, or of a shape no projection has. A ValueError."
);

/// A request error naming `arg`.
pub fn request(arg: &str, problem: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("{arg}: {problem}"))
}

/// An error of `fault` saying `message`.
pub fn by_fault(fault: Fault, message: String) -> PyErr {
    match fault {
        Fault::Input => InputError::new_err(message),
        Fault::Request => PyValueError::new_err(message),
        Fault::System => PyOSError::new_err(message),
    }
}

/// Python's own `OSError` (its subclass by errno: `FileNotFoundError`, `PermissionError`,
/// `IsADirectoryError`) for `e` on `path`, with `filename` set.
pub fn os_error(path: &Path, e: &std::io::Error) -> PyErr {
    let errno = e.raw_os_error().unwrap_or(0);
    let strerror = match e.kind() {
        std::io::ErrorKind::NotFound => "No such file or directory".to_string(),
        std::io::ErrorKind::PermissionDenied => "Permission denied".to_string(),
        _ => e.to_string(),
    };
    // OSError(errno, strerror, filename) becomes the subclass the errno names.
    PyOSError::new_err((errno, strerror, path.display().to_string()))
}

/// An io error as Python's: the OS's own error where one caused it, else by fault.
pub fn io(e: mirrorball_io::Error) -> PyErr {
    use std::error::Error as _;
    if let Some(os) = e.source().and_then(|s| s.downcast_ref::<std::io::Error>()) {
        if e.fault() == Fault::System || os.kind() == std::io::ErrorKind::NotFound {
            return os_error(e.path(), os);
        }
    }
    by_fault(e.fault(), e.to_string())
}

/// Checks that `path` can be opened for reading, raising Python's own `OSError` subclass
/// when it cannot (missing, permission denied, a folder).
pub fn check_readable(path: &Path) -> PyResult<()> {
    match std::fs::metadata(path) {
        Err(e) => return Err(os_error(path, &e)),
        Ok(m) if m.is_dir() => {
            return Err(PyOSError::new_err((
                21,
                "Is a directory".to_string(),
                path.display().to_string(),
            )))
        }
        Ok(_) => {}
    }
    std::fs::File::open(path)
        .map(drop)
        .map_err(|e| os_error(path, &e))
}
