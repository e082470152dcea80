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
    let tmp = temp_path(path);
    let result = (|| {
        let file = File::create(&tmp).map_err(|e| Error::io(path, e))?;
        let mut w = BufWriter::with_capacity(1 << 20, file);
        write(&mut w)?;
        w.flush().map_err(|e| Error::io(path, e))?;
        let file = w
            .into_inner()
            .map_err(|e| Error::io(path, e.into_error()))?;
        drop(file);
        std::fs::rename(&tmp, path).map_err(|e| Error::io(path, e))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let unique = format!(".{}.{}.tmp", name, std::process::id());
    path.with_file_name(unique)
}
