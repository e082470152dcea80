//! Write to a temporary file beside the target, then rename: never a half-written output.

use crate::Error;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Calls `write` with a buffered writer on a temporary file in `path`'s directory, flushes
/// it, and renames it over `path`. On any error the temporary file is removed and `path` is
/// left as it was: no reader ever sees a half-written output.
///
/// The file is not synced to disk (`fsync`) before the rename, as `cp`, OpenEXR and image
/// editors do not: a sync waits for the disk (10–15 ms a file here, a third of writing six
/// cube faces) and guards only against the machine losing power, which is the file
/// system's business (ext4, for one, flushes a file renamed over another before the
/// rename is committed).
pub fn atomic_write<F>(path: &Path, write: F) -> Result<(), Error>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<(), Error>,
{
    stage(path, write)?.commit()
}

/// A complete output written to a temporary file beside its destination, waiting to be
/// renamed into place by [`Staged::commit`]; dropped uncommitted, the temporary file is
/// removed and the destination is left as it was.
///
/// Renaming is split from writing because renaming over an existing file can be slow: on
/// ext4 it starts writing the new file out (about 2 ms for a 12 MB cube face here) and
/// frees the old file's blocks (about 6 ms on this `discard`-mounted disk), 7–12 ms in all,
/// mostly waiting. A caller writing many files can commit each on another thread and go on
/// writing the next.
#[must_use = "a staged file is removed unless committed"]
#[derive(Debug)]
pub struct Staged {
    /// The temporary file, until committed.
    tmp: Option<PathBuf>,
    path: PathBuf,
}

impl Staged {
    /// The destination.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Renames the temporary file over the destination. On failure the temporary file is
    /// removed and the destination is left as it was.
    pub fn commit(mut self) -> Result<(), Error> {
        let tmp = self.tmp.take().expect("a staged file is committed once");
        std::fs::rename(&tmp, &self.path).map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            Error::io(&self.path, e)
        })
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if let Some(tmp) = self.tmp.take() {
            let _ = std::fs::remove_file(tmp);
        }
    }
}

/// The first half of [`atomic_write`]: `write` fills a temporary file beside `path`, which
/// is flushed and closed. On any error the temporary file is removed.
pub(crate) fn stage<F>(path: &Path, write: F) -> Result<Staged, Error>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<(), Error>,
{
    let staged = Staged {
        tmp: Some(temp_path(path)),
        path: path.to_path_buf(),
    };
    let tmp = staged.tmp.as_deref().expect("just set");
    // From here an early return drops `staged`, which removes what was written.
    let file = File::create(tmp).map_err(|e| Error::io(path, e))?;
    let mut w = BufWriter::with_capacity(1 << 20, file);
    write(&mut w)?;
    w.flush().map_err(|e| Error::io(path, e))?;
    let file = w
        .into_inner()
        .map_err(|e| Error::io(path, e.into_error()))?;
    drop(file);
    Ok(staged)
}

fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let unique = format!(".{}.{}.tmp", name, std::process::id());
    path.with_file_name(unique)
}
