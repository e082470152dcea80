//! Which files in a folder mirrorball wrote: a small record in the folder
//! ([`RECORD`], one `WRITER<TAB>NAME` line a file), so that a later run replaces only
//! files mirrorball wrote there, refuses to replace any other (unless told to), and a
//! writer that replaces its whole set (a bake, a views run) removes the files of its
//! earlier set that it no longer writes.
//!
//! Names are relative to the folder, `/` between folders; a line naming anything outside
//! the folder (`..`, an absolute path) is ignored, so a record cannot point a removal
//! elsewhere. The record is written through [`crate::atomic_write`], so inside
//! [`crate::write_together`] it lands with the files it lists.

use crate::Error;
use std::io::Write;
use std::path::{Component, Path, PathBuf};

/// The record's file name in a folder.
pub const RECORD: &str = ".mirrorball-files";

/// The record's first lines, for whoever opens it.
const HEADER: &str = "# The files mirrorball wrote in this folder (WRITER<TAB>NAME): it replaces \
only these, refuses any other (unless --overwrite),\n# and a bake or a views run removes the files of the \
run it replaces. Delete this file to make mirrorball forget them.\n";

/// A folder's record of the files mirrorball wrote in it ([`RECORD`]).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Owned {
    dir: PathBuf,
    /// `(writer, name)`, in the order written.
    entries: Vec<(String, String)>,
}

impl Owned {
    /// The record of `dir`: empty when the folder or its record does not exist. Lines that
    /// are not `WRITER<TAB>NAME` with a name inside the folder are ignored.
    pub fn read(dir: &Path) -> Result<Owned, Error> {
        let path = dir.join(RECORD);
        let text = match std::fs::read(&path) {
            Ok(bytes) => String::from_utf8_lossy(&bytes).into_owned(),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
            Err(e) if e.kind() == std::io::ErrorKind::NotADirectory => String::new(),
            Err(e) => return Err(Error::io(&path, e)),
        };
        let entries = text
            .lines()
            .filter(|l| !l.starts_with('#'))
            .filter_map(|l| l.split_once('\t'))
            .filter(|(w, n)| !w.is_empty() && inside(n) && *n != RECORD)
            .map(|(w, n)| (w.to_string(), n.to_string()))
            .collect();
        Ok(Owned {
            dir: dir.to_path_buf(),
            entries,
        })
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Whether mirrorball recorded writing `name` (relative to the folder).
    pub fn owns(&self, name: &str) -> bool {
        self.entries.iter().any(|(_, n)| n == name)
    }

    /// The names `writer` recorded, in the order written.
    pub fn written_by<'a>(&'a self, writer: &'a str) -> impl Iterator<Item = &'a str> {
        self.entries
            .iter()
            .filter(move |(w, _)| w == writer)
            .map(|(_, n)| n.as_str())
    }

    /// The first of `names` (relative to the folder) that exists and that mirrorball did
    /// not record writing: the file a run would replace without being asked to.
    pub fn unowned<S: AsRef<str>>(&self, names: &[S]) -> Option<PathBuf> {
        names
            .iter()
            .map(AsRef::as_ref)
            .filter(|n| !self.owns(n))
            .map(|n| self.dir.join(n))
            .find(|p| std::fs::symlink_metadata(p).is_ok())
    }

    /// Refuses, before any work, to replace a file mirrorball did not write (the first of
    /// `names` [`unowned`](Self::unowned) finds), unless `overwrite`. The message names
    /// the file; the fault is the request's.
    pub fn check<S: AsRef<str>>(&self, names: &[S], overwrite: bool) -> Result<(), Error> {
        match self.unowned(names) {
            Some(p) if !overwrite => Err(Error::request(
                &p,
                format!(
                    "exists, and mirrorball did not write it (this folder's {RECORD} does not \
                     list it): move it away, or give --overwrite to replace it"
                ),
            )),
            _ => Ok(()),
        }
    }

    /// Records that `writer` wrote `names` (added to what it wrote before).
    pub fn add<S: AsRef<str>>(&mut self, writer: &str, names: &[S]) {
        for n in names.iter().map(AsRef::as_ref).filter(|n| recordable(n)) {
            if let Some(e) = self.entries.iter_mut().find(|(_, m)| m == n) {
                e.0 = writer.to_string();
            } else {
                self.entries.push((writer.to_string(), n.to_string()));
            }
        }
    }

    /// Records that `writer`'s files are now `names` and nothing else: returns the names it
    /// recorded before and no longer writes (to be removed with
    /// [`remove`](Self::remove) once the new files are in place).
    pub fn replace<S: AsRef<str>>(&mut self, writer: &str, names: &[S]) -> Vec<String> {
        let keep: Vec<&str> = names.iter().map(AsRef::as_ref).collect();
        let mut stale = Vec::new();
        self.entries.retain(|(w, n)| {
            let gone = w == writer && !keep.contains(&n.as_str());
            if gone {
                stale.push(n.clone());
            }
            !gone
        });
        self.add(writer, names);
        stale
    }

    /// Writes the record into the folder (through [`crate::atomic_write`]: inside
    /// [`crate::write_together`] it lands with the set).
    pub fn write(&self) -> Result<(), Error> {
        let path = self.dir.join(RECORD);
        let mut text = HEADER.to_string();
        for (w, n) in &self.entries {
            text += &format!("{w}\t{n}\n");
        }
        crate::atomic_write(&path, |f| {
            f.write_all(text.as_bytes())
                .map_err(|e| Error::io(&path, e))
        })
    }

    /// Removes the files `names` (relative to the folder, as [`replace`](Self::replace)
    /// returns them) that are still there, and then any folder inside this one that they
    /// leave empty. A folder where a name's file was is left alone. Returns the files
    /// removed; one that cannot be removed is skipped.
    pub fn remove<S: AsRef<str>>(&self, names: &[S]) -> Vec<PathBuf> {
        let mut removed = Vec::new();
        for n in names.iter().map(AsRef::as_ref).filter(|n| inside(n)) {
            let p = self.dir.join(n);
            let is_file = std::fs::symlink_metadata(&p).is_ok_and(|m| !m.is_dir());
            if is_file && std::fs::remove_file(&p).is_ok() {
                removed.push(p.clone());
                let mut parent = p.parent();
                while let Some(d) = parent.filter(|d| *d != self.dir && d.starts_with(&self.dir)) {
                    if std::fs::remove_dir(d).is_err() {
                        break; // not empty
                    }
                    parent = d.parent();
                }
            }
        }
        removed
    }
}

/// Whether `name` is a relative path of plain names, inside the folder.
fn inside(name: &str) -> bool {
    let p = Path::new(name);
    !name.is_empty() && p.components().all(|c| matches!(c, Component::Normal(_)))
}

/// Whether `name` can be a line of the record.
fn recordable(name: &str) -> bool {
    inside(name) && name != RECORD && !name.contains(['\t', '\n', '\r'])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_record_reads_back_and_ignores_what_points_outside() {
        let dir = tempfile::tempdir().unwrap();
        let mut owned = Owned::read(dir.path()).unwrap();
        assert_eq!(owned, Owned::read(dir.path()).unwrap());
        assert!(owned.replace("bake", &["a.ktx2", "cube/px.hdr"]).is_empty());
        owned.add("prefilter", &["sky.sh.json", "bad\tname", "../up", RECORD]);
        owned.write().unwrap();
        let back = Owned::read(dir.path()).unwrap();
        assert_eq!(back, owned);
        assert_eq!(
            back.written_by("bake").collect::<Vec<_>>(),
            ["a.ktx2", "cube/px.hdr"]
        );
        assert!(back.owns("sky.sh.json") && !back.owns("../up") && !back.owns(RECORD));
        // A hand-made line naming a file outside the folder is not taken.
        let text = std::fs::read_to_string(dir.path().join(RECORD)).unwrap();
        std::fs::write(
            dir.path().join(RECORD),
            text + "bake\t../../etc/passwd\nbake\t/etc/passwd\nno tab\n",
        )
        .unwrap();
        assert_eq!(Owned::read(dir.path()).unwrap(), owned);
    }

    #[test]
    fn replacing_a_set_gives_the_stale_files_and_removes_only_those() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("cube")).unwrap();
        for f in ["a.ktx2", "cube/px.hdr", "mine.txt", "b.dds"] {
            std::fs::write(dir.path().join(f), b"x").unwrap();
        }
        let mut owned = Owned::read(dir.path()).unwrap();
        owned.replace("bake", &["a.ktx2", "cube/px.hdr"]);
        assert_eq!(
            owned.unowned(&["a.ktx2", "mine.txt", "b.dds"]),
            Some(dir.path().join("mine.txt"))
        );
        assert!(owned.check(&["a.ktx2", "new.png"], false).is_ok());
        let e = owned.check(&["b.dds"], false).unwrap_err();
        assert_eq!(e.fault(), crate::Fault::Request);
        assert!(e.to_string().contains("b.dds") && e.to_string().contains("--overwrite"));
        assert!(owned.check(&["b.dds"], true).is_ok());
        let stale = owned.replace("bake", &["b.dds"]);
        assert_eq!(stale, ["a.ktx2", "cube/px.hdr"]);
        let removed = owned.remove(&stale);
        assert_eq!(removed.len(), 2);
        let mut left: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        assert_eq!(left, ["b.dds", "mine.txt"], "the emptied cube/ went too");
    }
}
