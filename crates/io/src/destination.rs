//! Whether an output can be written where it is asked for, told before any work starts:
//! the name is not a folder, its folder exists (or, where the command makes folders, the
//! nearest one that exists is a folder), that folder can be written, and its file system
//! has room for the bytes expected.
//!
//! Writability is asked of the kernel (`access(2)` with `W_OK | X_OK`), so a read-only
//! mount and an immutable folder are refused for every user, root included, and permission
//! bits for everyone else, just as the write itself would be.

use crate::Error;
use std::path::{Path, PathBuf};

/// Which folders of an output the command makes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Folders {
    /// None: the output's folder must exist (convert, prefilter, render, compare).
    #[default]
    Exist,
    /// The output's own folder, in a folder that exists (bake's OUT-DIR).
    MakeOne,
    /// The output's folder and every folder above it that is missing (demo's and
    /// analyze's `--out`).
    MakeAll,
}

/// The folder an output lands in: the folder of the file `path` names once symbolic links
/// are followed, as the writers write through them; `.` for a bare name.
pub fn output_folder(path: &Path) -> PathBuf {
    let target = crate::atomic::write_through(path);
    match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// The nearest folder of `dir` (itself or above it) that exists, with the missing folders
/// between, the outermost first.
fn nearest_existing(dir: &Path) -> (PathBuf, Vec<PathBuf>) {
    let mut missing = Vec::new();
    let mut at = dir.to_path_buf();
    loop {
        if std::fs::symlink_metadata(&at).is_ok() {
            missing.reverse();
            return (at, missing);
        }
        missing.push(at.clone());
        at = match at.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
    }
}

/// Refuses `path` as an output that cannot be written, before anything is: a name that is
/// a folder, a folder that is missing (beyond what `folders` lets the command make) or is a
/// file, a folder that cannot be written (a read-only file system, no permission). The
/// error names `path`; a missing or unwritable folder is also named.
pub fn check_writable(path: &Path, folders: Folders) -> Result<(), Error> {
    if path.is_dir() {
        return Err(Error::request(path, "is a folder; give a file name".into()));
    }
    let dir = output_folder(path);
    let (existing, missing) = nearest_existing(&dir);
    let allowed = match folders {
        Folders::Exist => 0,
        Folders::MakeOne => 1,
        Folders::MakeAll => usize::MAX,
    };
    if !existing.is_dir() {
        return Err(Error::request(
            path,
            format!("{} is a file, not a folder", existing.display()),
        ));
    }
    if missing.len() > allowed {
        let first = &missing[0];
        return Err(Error::request(
            path,
            match folders {
                Folders::Exist => format!("the folder {} does not exist", first.display()),
                _ => format!(
                    "the folder {} does not exist (only {} is made)",
                    first.display(),
                    dir.display()
                ),
            },
        ));
    }
    if let Err(e) = access_writable(&existing) {
        let why = match e.kind() {
            std::io::ErrorKind::PermissionDenied => "permission denied".to_string(),
            _ => e.to_string(),
        };
        let what = if missing.is_empty() {
            format!("cannot write into the folder {}", existing.display())
        } else {
            format!(
                "cannot make the folder {} in {}",
                missing[0].display(),
                existing.display()
            )
        };
        return Err(Error::system(path, format!("{what} ({why})")));
    }
    Ok(())
}

/// Whether files can be made in the folder `dir`: `Ok` or the kernel's reason.
#[cfg(target_os = "linux")]
fn access_writable(dir: &Path) -> std::io::Result<()> {
    use std::os::unix::ffi::OsStrExt;
    let c = std::ffi::CString::new(dir.as_os_str().as_bytes())
        .map_err(|_| std::io::Error::from(std::io::ErrorKind::InvalidInput))?;
    // SAFETY: `c` is a valid NUL-terminated path that outlives the call.
    let r = unsafe { libc::access(c.as_ptr(), libc::W_OK | libc::X_OK) };
    if r == 0 {
        Ok(())
    } else {
        Err(std::io::Error::last_os_error())
    }
}

/// Elsewhere, a folder marked read-only is refused; the write tells the rest.
#[cfg(not(target_os = "linux"))]
fn access_writable(dir: &Path) -> std::io::Result<()> {
    match std::fs::metadata(dir)?.permissions().readonly() {
        true => Err(std::io::Error::from(std::io::ErrorKind::PermissionDenied)),
        false => Ok(()),
    }
}

/// Bytes the file system that would hold `path` has free for this process (its nearest
/// existing folder's file system; root may use the blocks reserved for it); `None` where
/// that cannot be told.
pub fn free_bytes(path: &Path) -> Option<u64> {
    let (existing, _) = nearest_existing(&output_folder(path));
    free_in(&existing)
}

#[cfg(target_os = "linux")]
fn free_in(dir: &Path) -> Option<u64> {
    use std::os::unix::ffi::OsStrExt;
    let c = std::ffi::CString::new(dir.as_os_str().as_bytes()).ok()?;
    // SAFETY: `statvfs` is plain data, written whole by a successful call; `c` is a valid
    // NUL-terminated path.
    let mut s: libc::statvfs = unsafe { std::mem::zeroed() };
    if unsafe { libc::statvfs(c.as_ptr(), &mut s) } != 0 {
        return None;
    }
    // SAFETY: no arguments, no failure.
    let root = unsafe { libc::geteuid() } == 0;
    let blocks = if root { s.f_bfree } else { s.f_bavail };
    Some((blocks as u64).saturating_mul(s.f_frsize as u64))
}

#[cfg(not(target_os = "linux"))]
fn free_in(_dir: &Path) -> Option<u64> {
    None
}

/// The file system's identity of `path`'s nearest existing folder (device number), so
/// that outputs on one file system are counted together; `None` where not known.
pub fn file_system(path: &Path) -> Option<u64> {
    let (existing, _) = nearest_existing(&output_folder(path));
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        std::fs::metadata(existing).ok().map(|m| m.dev())
    }
    #[cfg(not(unix))]
    {
        let _ = existing;
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folders_are_walked_up_to_the_nearest_that_exists() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let deep = d.join("a/b/c.exr");
        assert!(check_writable(&deep, Folders::Exist)
            .unwrap_err()
            .to_string()
            .contains("does not exist"));
        assert!(check_writable(&deep, Folders::MakeOne).is_err());
        assert!(check_writable(&deep, Folders::MakeAll).is_ok());
        assert!(check_writable(&d.join("a/c.exr"), Folders::MakeOne).is_ok());
        std::fs::write(d.join("f"), b"x").unwrap();
        let e = check_writable(&d.join("f/x.exr"), Folders::MakeAll).unwrap_err();
        assert!(e.to_string().contains("is a file, not a folder"), "{e}");
        let e = check_writable(d, Folders::Exist).unwrap_err();
        assert!(e.to_string().contains("is a folder"), "{e}");
        assert!(free_bytes(&deep).is_some_and(|b| b > 0));
        assert_eq!(file_system(&deep), file_system(&d.join("x")));
    }
}
