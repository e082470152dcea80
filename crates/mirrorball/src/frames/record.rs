//! What made each output of a sequence or a manifest, so that a rerun skips only the
//! outputs the same request made from the same input, and converts the others again.
//!
//! Each output folder holds a record, [`RECORD`]: one line per output written,
//! `STAMP<TAB>NAME`, appended once the output is renamed into place (so a line never
//! names a file that was not whole). `STAMP` is 16 hex digits of FNV-1a over the request's
//! settings ([`settings`]: every `convert` flag that decides the output, and mirrorball's
//! version) and the input file's length and modification time; the last line for a name
//! wins. Lines are appended with `O_APPEND`, one `write` each, so the shards of one
//! sequence share a folder's record without losing lines.
//!
//! A rerun decides each existing output by its line ([`Made::verdict`]): the same stamp
//! is skipped; another stamp (other flags, a newer input) is converted again; no line (an
//! output another tool made, or mirrorball before it kept records) is kept, and the run
//! says how many, as `--overwrite` converts them too.

use super::sequence::FramesRequest;
use crate::error::Error;
use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The record's file name in an output folder.
pub const RECORD: &str = ".mirrorball-frames";

/// The request's settings as one text: `r` less what does not decide an output (the input
/// and output names, which each line's name and the input's stamp stand for; the shard,
/// `overwrite`, `json`), with mirrorball's version, so that another version's outputs are
/// made again.
pub fn settings(r: &FramesRequest) -> String {
    let mut r = r.clone();
    r.convert.input.clear();
    r.convert.output.clear();
    r.shard = None;
    r.overwrite = false;
    r.json = false;
    format!("mirrorball {} {r:?}", env!("CARGO_PKG_VERSION"))
}

/// The stamp of an output made with `settings` from the file `input` (its length and
/// modification time; nothing of it for a pipe or a file that cannot be read).
pub fn stamp(settings: &str, input: &Path) -> u64 {
    let meta = std::fs::metadata(input).ok();
    let len = meta.as_ref().map_or(0, |m| m.len());
    let modified = meta
        .and_then(|m| m.modified().ok())
        .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
        .map_or(0, |d| d.as_nanos());
    let text = format!("{settings}\n{len}\n{modified}");
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

/// How an existing output stands against the request that would make it now.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Made by the same settings from the same input: skipped.
    Same,
    /// Made by other settings or from another input: converted again.
    Other,
    /// No record of how it was made: kept.
    Unknown,
}

/// The records of the output folders looked at, each read once.
#[derive(Default)]
pub struct Made {
    folders: HashMap<PathBuf, HashMap<String, u64>>,
}

impl Made {
    /// How `out`, an existing output, stands against `stamp`.
    pub fn verdict(&mut self, out: &Path, stamp: u64) -> Verdict {
        let (dir, name) = split(out);
        let lines = self.folders.entry(dir).or_insert_with_key(|d| read(d));
        match lines.get(&name) {
            Some(&s) if s == stamp => Verdict::Same,
            Some(_) => Verdict::Other,
            None => Verdict::Unknown,
        }
    }
}

/// Appends `out`'s line to its folder's record, once `out` is in place.
pub fn note(out: &Path, stamp: u64) -> Result<(), Error> {
    let (dir, name) = split(out);
    let path = dir.join(RECORD);
    let line = format!("{stamp:016x}\t{name}\n");
    std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .and_then(|mut f| f.write_all(line.as_bytes()))
        .map_err(|e| {
            Error::system(format!(
                "{}: cannot record how {name} was made: {e}",
                path.display()
            ))
        })
}

/// What a rerun says of the outputs that exist (of frames or jobs, `noun`): `skipped` kept
/// (`unknown` of them with no record of how they were made), `again` made by other
/// settings or from other inputs.
pub fn kept_lines(noun: &str, skipped: u64, unknown: u64, again: u64) -> Vec<String> {
    let mut lines = Vec::new();
    // "1 frame …: its output exists", "3 frames …: their outputs exist".
    let said = |n: u64, what: &str| {
        let (its, exist, were, them) = match n {
            1 => ("its output", "exists", "was", "it"),
            _ => ("their outputs", "exist", "were", "them"),
        };
        let what = what
            .replace("{its}", its)
            .replace("{exist}", exist)
            .replace("{were}", were)
            .replace("{them}", them);
        format!("{} {what}", mirrorball_core::count(n, noun))
    };
    if skipped > unknown {
        lines.push(said(
            skipped - unknown,
            "skipped: {its} {exist}, made with these settings from these inputs",
        ));
    }
    if unknown > 0 {
        lines.push(said(
            unknown,
            &format!(
                "skipped: {{its}} {{exist}}, with no record of the settings that made {{them}} ({RECORD}); --overwrite converts {{them}} again"
            ),
        ));
    }
    if again > 0 {
        lines.push(said(
            again,
            "converted again: {its} {were} made with other settings or from other inputs",
        ));
    }
    lines
}

/// The folder (`.` for a bare name) and the file name of `out`.
fn split(out: &Path) -> (PathBuf, String) {
    let dir = match out.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = out
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    (dir, name)
}

/// The stamps `dir`'s record gives, the last line for a name winning; lines that are not
/// `HEX<TAB>NAME` are ignored (a record cut short by a full disk loses only its last line).
fn read(dir: &Path) -> HashMap<String, u64> {
    let text = std::fs::read(dir.join(RECORD)).unwrap_or_default();
    String::from_utf8_lossy(&text)
        .lines()
        .filter_map(|l| l.split_once('\t'))
        .filter_map(|(s, n)| Some((n.to_string(), u64::from_str_radix(s, 16).ok()?)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_last_line_wins_and_other_stamps_differ() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("f001.png");
        note(&out, 7).unwrap();
        note(&out, 9).unwrap();
        std::fs::write(dir.path().join(RECORD).as_path(), {
            let mut t = std::fs::read(dir.path().join(RECORD)).unwrap();
            t.extend_from_slice(b"garbage\nzz\tf002.png\n");
            t
        })
        .unwrap();
        let mut made = Made::default();
        assert_eq!(made.verdict(&out, 9), Verdict::Same);
        assert_eq!(
            Made::default().verdict(&out, 7),
            Verdict::Other,
            "an older line does not count"
        );
        assert_eq!(
            made.verdict(&dir.path().join("f002.png"), 9),
            Verdict::Unknown
        );
    }

    #[test]
    fn stamps_follow_the_settings_and_the_input() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("in.exr");
        std::fs::write(&input, b"one").unwrap();
        let a = stamp("--size 64", &input);
        assert_eq!(a, stamp("--size 64", &input));
        assert_ne!(a, stamp("--size 65", &input));
        std::fs::write(&input, b"longer").unwrap();
        assert_ne!(a, stamp("--size 64", &input), "a changed input");
    }
}
