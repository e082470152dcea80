//! Write to a temporary file beside the target, then rename: never a half-written output,
//! and nothing left behind when the write fails or the process is interrupted.
//!
//! - Every temporary file is registered while it exists, so that [`interrupted`] (called
//!   on SIGINT/SIGTERM) can remove them all before the process exits.
//! - A set of files that belong together (six cube faces, a mip chain: an
//!   [`crate::OutputSet`]) is renamed into place by [`commit_all`] under one guard: an interrupt waits for the set to land, and no
//!   set starts landing after an interrupt, so a set is either all new or all old.
//! - Files written inside [`write_together`] (any writer here: cubes, images, notes) wait
//!   beside their destinations and land as one set when it ends, or not at all.
//! - An output that is a symbolic link is written through (the file it points to is
//!   replaced, the link kept), as `cp` does.
//! - A temporary file is named `.NAME.PID.tmp`; the first write of a run into a folder
//!   removes every file of that pattern there whose process is gone (a run killed by
//!   SIGKILL, a power loss), whatever it was to become; [`removed_leftovers`] says which.

use crate::Error;
use std::cell::RefCell;
use std::collections::HashSet;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, RwLock};

/// Temporary files being written or waiting to be renamed.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
/// Folders made for outputs still being written ([`made_folder`]): removed by
/// [`interrupted`] when it leaves them empty.
static FOLDERS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
/// Set by [`interrupted`] (under `PENDING`'s lock): no temporary file is made after it.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);
/// Held shared while files are renamed into place, exclusively by [`interrupted`].
static COMMITS: RwLock<()> = RwLock::new(());
/// The folders already cleared of dead processes' temporary files ([`remove_leftovers`]).
static CLEARED: Mutex<Option<HashSet<PathBuf>>> = Mutex::new(None);
/// The dead processes' temporary files removed, until [`removed_leftovers`] takes them.
static REMOVED: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

thread_local! {
    /// While [`write_together`] runs on this thread: the files it has staged.
    static GATHERED: RefCell<Option<Vec<Staged>>> = const { RefCell::new(None) };
}

/// Runs `work`, and every file written meanwhile on this thread through this crate's
/// writers ([`atomic_write`], [`crate::write_image`], the KTX2, DDS and KTX1 cube writers)
/// is kept beside its destination, not renamed into place; when `work` succeeds they all
/// land together ([`commit_all`]'s guard against interrupts), when it fails (or panics)
/// none does and their temporary files are removed, every destination keeping its old
/// file. Returns `work`'s value and the files written, in order. A call inside another
/// lands its own files when it ends.
///
/// ```
/// use std::io::Write;
/// let dir = tempfile::tempdir().unwrap();
/// let (a, b) = (dir.path().join("a.txt"), dir.path().join("b.txt"));
/// let note = |p: &std::path::Path| {
///     mirrorball_io::atomic_write(p, |w| w.write_all(b"x").map_err(|e| mirrorball_io::Error::io(p, e)))
/// };
/// let failed = mirrorball_io::write_together(|| {
///     note(&a)?;
///     assert!(!a.exists()); // written beside, not yet in place
///     Err::<(), _>(mirrorball_io::Error::request(&b, "no room".into()))
/// });
/// assert!(failed.is_err());
/// assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0); // nothing left
/// let ((), files) = mirrorball_io::write_together(|| { note(&a)?; note(&b) }).unwrap();
/// assert_eq!(files, [a.clone(), b.clone()]);
/// assert!(a.exists() && b.exists());
/// ```
pub fn write_together<T>(
    work: impl FnOnce() -> Result<T, Error>,
) -> Result<(T, Vec<PathBuf>), Error> {
    /// Puts back what was gathered before, also when `work` panics (dropping this call's
    /// staged files, which removes them).
    struct Restore(Option<Vec<Staged>>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let outer = self.0.take();
            let _ = GATHERED.try_with(|g| *g.borrow_mut() = outer);
        }
    }
    let restore = Restore(GATHERED.with(|g| g.borrow_mut().replace(Vec::new())));
    let out = work();
    let staged = GATHERED.with(|g| g.borrow_mut().take()).unwrap_or_default();
    drop(restore);
    let value = out?;
    let paths = staged.iter().map(|s| s.path().to_path_buf()).collect();
    commit_all(staged)?;
    Ok((value, paths))
}

/// Renames `staged` into place now, or, inside [`write_together`], keeps it for the set.
pub(crate) fn land(staged: Staged) -> Result<(), Error> {
    let staged = GATHERED.with(|g| match g.borrow_mut().as_mut() {
        Some(set) => {
            set.push(staged);
            None
        }
        None => Some(staged),
    });
    match staged {
        Some(s) => s.commit(),
        None => Ok(()),
    }
}

/// Calls `write` with a buffered writer on a temporary file in `path`'s directory, flushes
/// it, and renames it over `path` (inside [`write_together`], when the set lands). On any
/// error the temporary file is removed and `path` is left as it was: no reader ever sees a
/// half-written output.
///
/// The file is not synced to disk (`fsync`) before the rename, as `cp`, OpenEXR and image
/// editors do not: a sync waits for the disk and guards only against the machine losing
/// power, which is the file system's business (ext4, for one, flushes a file renamed over
/// another before the rename is committed).
///
/// ```
/// use std::io::Write;
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("note.txt");
/// mirrorball_io::atomic_write(&path, |w| {
///     w.write_all(b"hello").map_err(|e| mirrorball_io::Error::io(&path, e))
/// })
/// .unwrap();
/// assert_eq!(std::fs::read(&path).unwrap(), b"hello");
/// assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1); // no temporary left
/// ```
pub fn atomic_write<F>(path: &Path, write: F) -> Result<(), Error>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<(), Error>,
{
    land(stage(path, write)?)
}

/// A complete output written to a temporary file beside its destination, waiting to be
/// renamed into place by [`Staged::commit`] (or with others by [`commit_all`]); dropped
/// uncommitted, the temporary file is removed and the destination is left as it was.
#[must_use = "a staged file is removed unless committed"]
#[derive(Debug)]
pub(crate) struct Staged {
    /// The temporary file, until committed.
    tmp: Option<PathBuf>,
    /// Where it goes (through symbolic links).
    target: PathBuf,
    /// The destination as asked, for messages.
    path: PathBuf,
}

impl Staged {
    /// The destination.
    pub(crate) fn path(&self) -> &Path {
        &self.path
    }

    /// Renames the temporary file over the destination. On failure the temporary file is
    /// removed and the destination is left as it was.
    pub(crate) fn commit(self) -> Result<(), Error> {
        let _guard = COMMITS.read().unwrap_or_else(|e| e.into_inner());
        self.rename()
    }

    fn rename(mut self) -> Result<(), Error> {
        let tmp = self.tmp.take().expect("a staged file is committed once");
        let done = std::fs::rename(&tmp, &self.target).map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            Error::io_write(&self.path, e)
        });
        forget_pending(&tmp);
        done
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if let Some(tmp) = self.tmp.take() {
            let _ = std::fs::remove_file(&tmp);
            forget_pending(&tmp);
        }
    }
}

/// Renames a set of staged files into place together: an interrupt that comes meanwhile
/// waits for the whole set; one that came before keeps the set from landing. Every file is
/// tried; the first error is returned, and the files that failed are removed.
pub(crate) fn commit_all(staged: Vec<Staged>) -> Result<(), Error> {
    let _guard = COMMITS.read().unwrap_or_else(|e| e.into_inner());
    let results: Vec<Result<(), Error>> = staged.into_iter().map(Staged::rename).collect();
    results.into_iter().collect()
}

/// For a signal handler: waits for a set of files being renamed into place to land, keeps
/// any other from starting, and removes every temporary file still pending. Returns how
/// many it removed. The process is expected to exit right after; writes still running on
/// other threads fail harmlessly, their files gone.
pub fn interrupted() -> usize {
    let guard = COMMITS.write().unwrap_or_else(|e| e.into_inner());
    // Held until the process exits: no rename starts after an interrupt.
    std::mem::forget(guard);
    let pending = {
        let mut pending = PENDING.lock().unwrap_or_else(|e| e.into_inner());
        INTERRUPTED.store(true, Ordering::SeqCst);
        std::mem::take(&mut *pending)
    };
    let removed = pending
        .iter()
        .filter(|p| std::fs::remove_file(p).is_ok())
        .count();
    let folders = std::mem::take(&mut *FOLDERS.lock().unwrap_or_else(|e| e.into_inner()));
    for dir in folders.iter().rev() {
        let _ = std::fs::remove_dir(dir); // only when empty
    }
    removed
}

/// Marks `dir` as made for outputs now being written: an interrupt ([`interrupted`])
/// removes it if it leaves it empty, until [`keep_folder`] says the outputs are in place.
pub fn made_folder(dir: &Path) {
    FOLDERS
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .push(dir.to_path_buf());
}

/// `dir`, marked by [`made_folder`], holds what it was made for: an interrupt leaves it.
pub fn keep_folder(dir: &Path) {
    let mut folders = FOLDERS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(i) = folders.iter().rposition(|d| d == dir) {
        folders.remove(i);
    }
}

/// The first half of [`atomic_write`]: `write` fills a temporary file beside `path`, which
/// is flushed and closed. On any error the temporary file is removed.
pub(crate) fn stage<F>(path: &Path, write: F) -> Result<Staged, Error>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<(), Error>,
{
    let target = write_through(path);
    remove_leftovers(&target);
    let tmp = temp_path(&target, std::process::id());
    // Made and registered under one lock, so that an interrupt finds every temporary file.
    let file = {
        let mut pending = PENDING.lock().unwrap_or_else(|e| e.into_inner());
        if INTERRUPTED.load(Ordering::SeqCst) {
            return Err(Error::request(path, "interrupted".into()));
        }
        let file = File::create(&tmp).map_err(|e| Error::io_write(path, e))?;
        pending.push(tmp.clone());
        file
    };
    // From here an early return drops `staged`, which removes what was written.
    let staged = Staged {
        tmp: Some(tmp),
        target,
        path: path.to_path_buf(),
    };
    let mut w = BufWriter::with_capacity(1 << 20, file);
    write(&mut w)?;
    w.flush().map_err(|e| Error::io_write(path, e))?;
    let file = w
        .into_inner()
        .map_err(|e| Error::io_write(path, e.into_error()))?;
    drop(file);
    Ok(staged)
}

/// What a writer writes into: a buffered temporary file, or memory. Every writer
/// here encodes into one, so a format has one encoder for files and bytes.
pub(crate) trait Sink: Write + std::io::Seek + Send {}
impl<T: Write + std::io::Seek + Send> Sink for T {}

/// Where a writer's bytes go: a file, staged beside it ([`stage`]), or memory. The path
/// is the one errors name (for memory, the name the bytes are given).
#[derive(Clone, Copy)]
pub(crate) enum Dest<'a> {
    /// A temporary file beside this path, renamed into place when committed.
    File(&'a Path),
    /// A buffer in memory, called this in messages.
    Memory(&'a Path),
}

/// What a writer made of a [`Dest`].
#[must_use = "a staged file is removed unless committed"]
pub(crate) enum Written {
    /// A file staged beside its destination.
    Staged(Staged),
    /// The bytes of the file.
    Bytes(Vec<u8>),
}

impl Written {
    /// The staged file of a [`Dest::File`].
    pub(crate) fn staged(self) -> Staged {
        match self {
            Written::Staged(s) => s,
            Written::Bytes(_) => unreachable!("written to a file"),
        }
    }
    /// The bytes of a [`Dest::Memory`].
    pub(crate) fn bytes(self) -> Vec<u8> {
        match self {
            Written::Bytes(b) => b,
            Written::Staged(_) => unreachable!("written to memory"),
        }
    }
    /// Lands a staged file (inside [`write_together`], with its set); bytes are kept.
    pub(crate) fn land(self) -> Result<Option<Vec<u8>>, Error> {
        match self {
            Written::Staged(s) => land(s).map(|()| None),
            Written::Bytes(b) => Ok(Some(b)),
        }
    }
}

impl<'a> Dest<'a> {
    /// The path errors name.
    pub(crate) fn path(self) -> &'a Path {
        match self {
            Dest::File(p) | Dest::Memory(p) => p,
        }
    }
    /// Calls `write` with a sink on the destination: a staged temporary file ([`stage`]),
    /// or a buffer whose bytes come back.
    pub(crate) fn emit<F>(self, write: F) -> Result<Written, Error>
    where
        F: FnOnce(&mut dyn Sink) -> Result<(), Error>,
    {
        match self {
            Dest::File(path) => stage(path, |w| write(w)).map(Written::Staged),
            Dest::Memory(_) => {
                let mut out = std::io::Cursor::new(Vec::new());
                write(&mut out)?;
                Ok(Written::Bytes(out.into_inner()))
            }
        }
    }
}

/// Runs `work` with the name of a scratch file beside `path` (`.NAME.PART.PID.tmp`) for
/// a writer that opens files by name (FFmpeg's muxers), registered as every temporary file
/// is: removed when `work` ends, whatever it returns, and by [`interrupted`] (Ctrl-C). What
/// `work` made there lands only if it copies it into place itself ([`atomic_write`]).
///
/// ```
/// let dir = tempfile::tempdir().unwrap();
/// let out = dir.path().join("movie.mp4");
/// let kept = mirrorball_io::with_scratch(&out, "mux", |scratch| {
///     std::fs::write(scratch, b"frames").unwrap();
///     Ok::<_, mirrorball_io::Error>(std::fs::read(scratch).unwrap())
/// })
/// .unwrap();
/// assert_eq!(kept, b"frames");
/// assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0); // nothing left
/// ```
pub fn with_scratch<T, E: From<Error>>(
    path: &Path,
    part: &str,
    work: impl FnOnce(&Path) -> Result<T, E>,
) -> Result<T, E> {
    let target = write_through(path);
    remove_leftovers(&target);
    let name = target
        .file_name()
        .map(|n| format!("{}.{part}", n.to_string_lossy()))
        .unwrap_or_else(|| part.to_string());
    let tmp = temp_path(&target.with_file_name(name), std::process::id());
    {
        let mut pending = PENDING.lock().unwrap_or_else(|e| e.into_inner());
        if INTERRUPTED.load(Ordering::SeqCst) {
            return Err(Error::request(path, "interrupted".into()).into());
        }
        pending.push(tmp.clone());
    }
    let done = work(&tmp);
    let _ = std::fs::remove_file(&tmp);
    forget_pending(&tmp);
    done
}

fn forget_pending(tmp: &Path) {
    let mut pending = PENDING.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(i) = pending.iter().position(|p| p == tmp) {
        pending.swap_remove(i);
    }
}

/// The file `path` names once symbolic links are followed (at most 40 of them, as Linux
/// does); `path` itself when it is no link, or a loop.
pub(crate) fn write_through(path: &Path) -> PathBuf {
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        let is_link = std::fs::symlink_metadata(&p)
            .map(|m| m.file_type().is_symlink())
            .unwrap_or(false);
        if !is_link {
            return p;
        }
        let Ok(next) = std::fs::read_link(&p) else {
            return p;
        };
        p = match p.parent() {
            Some(dir) if next.is_relative() => dir.join(next),
            _ => next,
        };
    }
    path.to_path_buf()
}

/// Longest file name most file systems take (ext4, XFS, APFS, NTFS: 255 bytes).
const NAME_MAX: usize = 255;

/// What a temporary file for `path` is called, less its `.PID.tmp`: `.NAME`, or for names
/// too long to take the suffix, a prefix of `NAME` and a hash of the whole name.
fn temp_base(path: &Path) -> String {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    // `.` + name + `.` + pid (at most 10 digits) + `.tmp`.
    let room = NAME_MAX - 1 - 1 - 10 - 4;
    if name.len() <= room {
        return format!(".{name}");
    }
    let hash = fnv1a(name.as_bytes());
    let mut cut = room - 17; // `~` and 16 hex digits
    while !name.is_char_boundary(cut) {
        cut -= 1;
    }
    format!(".{}~{hash:016x}", &name[..cut])
}

fn temp_path(path: &Path, pid: u32) -> PathBuf {
    path.with_file_name(format!("{}.{pid}.tmp", temp_base(path)))
}

/// 64-bit FNV-1a: a stable hash (the same in every build) for shortened temporary names.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The first time this process writes into `path`'s folder: removes every temporary file
/// there (the pattern `.NAME.PID.tmp`, a plain file) whose process no longer runs on this
/// machine, and notes it for [`removed_leftovers`]. Nothing else is touched: not a file of
/// another pattern, not one of a live process (nor of this one).
fn remove_leftovers(path: &Path) {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    {
        let mut cleared = CLEARED.lock().unwrap_or_else(|e| e.into_inner());
        if !cleared.get_or_insert_with(HashSet::new).insert(dir.clone()) {
            return;
        }
    }
    let removed: Vec<PathBuf> = leftovers_in(&dir)
        .into_iter()
        .filter(|f| std::fs::remove_file(f).is_ok())
        .collect();
    REMOVED
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .extend(removed);
}

/// The temporary files of processes that no longer run that this process has removed so
/// far (each once), for the caller to say so.
///
/// ```
/// let dir = tempfile::tempdir().unwrap();
/// // A process id no machine hands out (above Linux's limit of 2^22).
/// let left = dir.path().join(".sky.exr.4999999.tmp");
/// std::fs::write(&left, b"half").unwrap();
/// mirrorball_io::atomic_write(&dir.path().join("note.txt"), |_| Ok(())).unwrap();
/// if cfg!(target_os = "linux") {
///     assert!(!left.exists());
///     assert!(mirrorball_io::removed_leftovers().contains(&left));
/// }
/// ```
pub fn removed_leftovers() -> Vec<PathBuf> {
    std::mem::take(&mut *REMOVED.lock().unwrap_or_else(|e| e.into_inner()))
}

/// The temporary files in `dir` whose process is gone.
fn leftovers_in(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return out;
    };
    let mut alive: HashSet<u32> = HashSet::new();
    for e in entries.flatten() {
        let name = e.file_name();
        let Some(name) = name.to_str() else { continue };
        let Some((_, pid)) = parse_temp_name(name) else {
            continue;
        };
        if pid == std::process::id() || alive.contains(&pid) {
            continue;
        }
        if !e.file_type().is_ok_and(|t| t.is_file()) {
            continue;
        }
        if process_alive(pid) {
            alive.insert(pid);
            continue;
        }
        out.push(e.path());
    }
    out
}

/// `(".NAME", pid)` of a temporary file's name `.NAME.PID.tmp`.
fn parse_temp_name(name: &str) -> Option<(&str, u32)> {
    let rest = name.strip_suffix(".tmp")?;
    let (base, pid) = rest.rsplit_once('.')?;
    if !base.starts_with('.') || base.len() < 2 || pid.is_empty() {
        return None;
    }
    if !pid.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    Some((base, pid.parse().ok()?))
}

/// Whether process `pid` exists. Where that cannot be told, every process is taken to be
/// alive, so that nothing is removed.
fn process_alive(pid: u32) -> bool {
    if cfg!(target_os = "linux") {
        Path::new("/proc").join(pid.to_string()).exists()
    } else {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temp_names_fit_the_file_system() {
        for len in [1usize, 100, 238, 239, 240, 250, 255] {
            let name = "é".repeat(len / 2) + &"a".repeat(len % 2);
            let p = Path::new("/x").join(&name);
            let t = temp_path(&p, u32::MAX);
            let t_name = t.file_name().unwrap().to_str().unwrap();
            assert!(t_name.len() <= NAME_MAX, "{len}: {}", t_name.len());
            assert_eq!(
                parse_temp_name(t_name),
                Some((temp_base(&p).as_str(), u32::MAX))
            );
        }
        // Short names keep their plain form; long ones that share a prefix stay apart.
        assert_eq!(temp_base(Path::new("sky.exr")), ".sky.exr");
        let a = "a".repeat(250) + "1.exr";
        let b = "a".repeat(250) + "2.exr";
        assert_ne!(temp_base(Path::new(&a)), temp_base(Path::new(&b)));
    }

    #[test]
    fn temp_names_are_recognised() {
        assert_eq!(parse_temp_name(".sky.exr.123.tmp"), Some((".sky.exr", 123)));
        assert_eq!(parse_temp_name("sky.exr.123.tmp"), None);
        assert_eq!(parse_temp_name(".sky.exr.12a.tmp"), None);
        assert_eq!(parse_temp_name(".sky.exr.tmp"), None);
    }
}
