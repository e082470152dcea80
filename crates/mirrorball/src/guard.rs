//! No output may be an input, nor two outputs one file: checked on the files themselves
//! (device and inode), so that `./s.exr`, `$PWD/s.exr`, `sub/../s.exr`, hard links and
//! symbolic links are all caught, before anything is written. Every output can be written
//! where it is asked for (its name no folder, its folder there or makeable, writable:
//! `mirrorball_io::check_writable`), and, once the command knows about how many bytes it
//! writes, its file system has room for them: all before any input is read.

use crate::error::Error;
use mirrorball_io::Folders;
use std::path::{Path, PathBuf};

/// The files a command reads and writes, gathered while its plan is made.
#[derive(Default)]
pub struct Files {
    inputs: Vec<(String, PathBuf)>,
    outputs: Vec<(String, PathBuf)>,
    /// Output names as given, from which the files written are named (prefilter's levels,
    /// a turntable's frames): none may be a folder.
    names: Vec<(String, PathBuf)>,
    /// Which folders of the outputs the command makes.
    folders: Folders,
}

impl Files {
    /// No files yet.
    pub fn new() -> Files {
        Files::default()
    }

    /// A file the command reads; `what` names it for messages ("the input", "--env").
    pub fn input(&mut self, what: &str, path: impl Into<PathBuf>) -> &mut Files {
        self.inputs.push((what.to_string(), path.into()));
        self
    }

    /// The file(s) of an input argument: one per layer when the name holds `{face}`.
    pub fn input_arg(&mut self, what: &str, arg: &str) -> &mut Files {
        if arg.contains(crate::load::FACE) {
            for n in crate::load::layer_names(6)
                .iter()
                .chain(crate::load::layer_names(2))
            {
                self.input(what, arg.replace(crate::load::FACE, n));
            }
            self
        } else {
            self.input(what, arg)
        }
    }

    /// A file the command writes; `what` names it for messages ("the output", "--sh").
    pub fn output(&mut self, what: &str, path: impl Into<PathBuf>) -> &mut Files {
        self.outputs.push((what.to_string(), path.into()));
        self
    }

    /// An output's name as given, when the files written are named from it (`NAME_mip0.exr`,
    /// `NAME-0000.png`): a folder of that name is refused as a file's would be.
    pub fn named(&mut self, what: &str, path: impl Into<PathBuf>) -> &mut Files {
        self.names.push((what.to_string(), path.into()));
        self
    }

    /// The command makes the outputs' folders as `folders` says (by default none: each
    /// must exist).
    pub fn making(&mut self, folders: Folders) -> &mut Files {
        self.folders = folders;
        self
    }

    /// Refuses the request when an output is one of the inputs or two outputs are one
    /// file, and refuses an output that cannot be written ([`Files::writable`]).
    pub fn check(&self) -> Result<(), Error> {
        self.distinct()?;
        self.writable()
    }

    /// Refuses an output whose name is a folder, whose folder is missing (beyond what the
    /// command makes) or cannot be written: the message names the output.
    pub fn writable(&self) -> Result<(), Error> {
        if let Some((what, name)) = self.names.iter().find(|(_, p)| p.is_dir()) {
            return Err(Error::request(format!(
                "{what} {}: is a folder; give a file name (the files are named from it)",
                name.display()
            )));
        }
        let mut seen = std::collections::HashSet::new();
        for (what, out) in &self.outputs {
            // Each folder once: a chain of levels or faces shares one.
            let folder = mirrorball_io::output_folder(out);
            if out.is_dir() || seen.insert(folder) {
                mirrorball_io::check_writable(out, self.folders).map_err(|e| {
                    Error::new(
                        e.fault(),
                        format!("{what} {}: {}", e.path().display(), e.problem()),
                    )
                })?;
            }
        }
        Ok(())
    }

    /// Refuses the job when a file system that would hold outputs has less room than
    /// `bytes`, about what the outputs take in all (each file system is asked for all of
    /// it: outputs are rarely spread over several).
    pub fn room(&self, bytes: u64) -> Result<(), Error> {
        let mut seen = std::collections::HashSet::new();
        for (what, out) in &self.outputs {
            if !seen.insert(mirrorball_io::file_system(out)) {
                continue;
            }
            let Some(free) = mirrorball_io::free_bytes(out) else {
                continue;
            };
            if free < bytes {
                return Err(Error::system(format!(
                    "{what} {}: the outputs need about {}, but its file system ({}) has {} free; free some space or write elsewhere",
                    out.display(),
                    crate::budget::human(bytes),
                    mirrorball_io::output_folder(out).display(),
                    crate::budget::human(free)
                )));
            }
        }
        Ok(())
    }

    /// No output is an input, no two outputs one file.
    pub fn distinct(&self) -> Result<(), Error> {
        for (what_out, out) in &self.outputs {
            for (what_in, inp) in &self.inputs {
                if mirrorball_io::same_file(inp, out) {
                    return Err(Error::request(format!(
                        "{}: {what_out} would overwrite {what_in} {} (the same file); choose another name",
                        out.display(),
                        inp.display()
                    )));
                }
            }
        }
        let ids: Vec<Option<PathBuf>> = self.outputs.iter().map(|(_, p)| identity(p)).collect();
        for (i, (what_a, a)) in self.outputs.iter().enumerate() {
            for (j, (what_b, b)) in self.outputs.iter().enumerate().skip(i + 1) {
                let same = match (&ids[i], &ids[j]) {
                    (Some(x), Some(y)) => x == y,
                    _ => false,
                } || mirrorball_io::same_file(a, b);
                if same {
                    return Err(Error::request(format!(
                        "{}: {what_a} and {what_b} ({}) are the same file; give them different names",
                        a.display(),
                        b.display()
                    )));
                }
            }
        }
        Ok(())
    }
}

/// Where `p` will be written: its folder resolved (symbolic links, `..`) joined with its
/// name, or the file itself resolved when it exists; `None` when the folder does not exist.
fn identity(p: &Path) -> Option<PathBuf> {
    if let Ok(c) = std::fs::canonicalize(p) {
        return Some(c);
    }
    let name = p.file_name()?;
    let dir = match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    Some(std::fs::canonicalize(dir).ok()?.join(name))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_of_the_input_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let input = d.join("s.exr");
        std::fs::write(&input, b"x").unwrap();
        std::fs::create_dir(d.join("sub")).unwrap();
        std::fs::hard_link(&input, d.join("hard.exr")).unwrap();
        #[cfg(unix)]
        std::os::unix::fs::symlink(&input, d.join("soft.exr")).unwrap();
        let mut names = vec![
            d.join("./s.exr"),
            d.join("sub/../s.exr"),
            d.join("hard.exr"),
        ];
        if cfg!(unix) {
            names.push(d.join("soft.exr"));
        }
        for out in names {
            let mut f = Files::new();
            f.input("the input", &input).output("the output", &out);
            let e = f.check().expect_err(&out.display().to_string());
            assert_eq!(e.fault, mirrorball_core::Fault::Request);
            assert!(
                e.message.contains("would overwrite the input"),
                "{}",
                e.message
            );
        }
        let mut f = Files::new();
        f.input("the input", &input)
            .output("the output", d.join("t.exr"));
        assert!(f.check().is_ok());
    }

    #[test]
    fn two_outputs_that_are_one_file_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::create_dir(d.join("sub")).unwrap();
        let mut f = Files::new();
        f.output("the output", d.join("a.png"))
            .output("--preview", d.join("sub/../a.png"));
        assert!(f.check().unwrap_err().message.contains("are the same file"));
        let mut f = Files::new();
        f.output("the output", d.join("a.png"))
            .output("--preview", d.join("b.png"));
        assert!(f.check().is_ok());
    }
}
