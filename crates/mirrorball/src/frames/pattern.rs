//! File-name patterns of frame sequences: printf's `%d`/`%0Nd` (as ffmpeg's image2 reads
//! and writes them) and shell globs (`*`, `?`, `[…]`), in the file name only.
//!
//! An input pattern is expanded once, before any work: a printf pattern matches the names
//! it prints (`%05d` matches `00012` and `123456`, not `12`; `%d` matches `12`, not `012`),
//! each frame numbered by its digits, in number order; a glob matches by the usual rules,
//! frames numbered 0, 1, 2 … in name order (bytewise). An output pattern is printf only: a
//! frame's output is the pattern printed with the frame's number.

use crate::error::Error;
use std::path::{Path, PathBuf};

/// A printf pattern: `dir/prefix%0Wdsuffix`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Printf {
    dir: PathBuf,
    prefix: String,
    /// Zero-padded to this many digits (`%05d`: 5; `%d`: 0).
    width: usize,
    suffix: String,
}

impl Printf {
    /// The name of frame `n`.
    pub fn path(&self, n: u64) -> PathBuf {
        let name = format!("{}{:0w$}{}", self.prefix, n, self.suffix, w = self.width);
        self.dir.join(name)
    }

    /// The frame number `name` is printed from, if it is.
    fn number(&self, name: &str) -> Option<u64> {
        let digits = name
            .strip_prefix(&self.prefix)?
            .strip_suffix(&self.suffix)?;
        if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
            return None;
        }
        let n: u64 = digits.parse().ok()?;
        (format!("{n:0w$}", w = self.width) == digits).then_some(n)
    }
}

/// What a file argument names.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Pattern {
    Printf(Printf),
    Glob { dir: PathBuf, name: String },
}

/// One frame of an input sequence: its number and file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Frame {
    pub number: u64,
    pub path: PathBuf,
}

/// The folder and file name of `arg` (the folder `.` when it has none).
fn split(arg: &str) -> (PathBuf, String) {
    let p = Path::new(arg);
    let dir = match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = p
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    (dir, name)
}

/// The printf conversion of `name` (`%d` or `%0Nd`, `%%` for a `%`): `Ok(None)` when it has
/// none, an error for a `%` that is neither or for two conversions.
fn printf_parts(arg: &str, name: &str) -> Result<Option<(String, usize, String)>, Error> {
    let bad = |why: &str| {
        Error::request(format!(
            "{arg}: {why} (a frame pattern has one %d or %0Nd, and %% for a %)"
        ))
    };
    let b = name.as_bytes();
    let (mut i, mut text, mut found) = (0, String::new(), None::<(String, usize)>);
    while i < b.len() {
        if b[i] != b'%' {
            let ch = name[i..].chars().next().expect("in the string");
            text.push(ch);
            i += ch.len_utf8();
            continue;
        }
        if b.get(i + 1) == Some(&b'%') {
            text.push('%');
            i += 2;
            continue;
        }
        let digits_end = (i + 1..b.len())
            .find(|&k| !b[k].is_ascii_digit())
            .unwrap_or(b.len());
        if b.get(digits_end) != Some(&b'd') {
            return Err(bad("a % that is not %d, %0Nd or %%"));
        }
        let spec = &name[i + 1..digits_end];
        if !spec.is_empty() && !spec.starts_with('0') {
            return Err(bad(&format!(
                "%{spec}d pads with spaces, which file names should not have; use %0{spec}d"
            )));
        }
        let width: usize = if spec.is_empty() {
            0
        } else {
            spec.parse()
                .ok()
                .filter(|w| *w <= 20)
                .ok_or_else(|| bad("a width over 20 digits"))?
        };
        if found.is_some() {
            return Err(bad("two frame numbers in one name"));
        }
        found = Some((std::mem::take(&mut text), width));
        i = digits_end + 1;
    }
    Ok(found.map(|(prefix, width)| (prefix, width, text)))
}

fn has_glob(name: &str) -> bool {
    name.contains(['*', '?', '['])
}

impl Pattern {
    /// The pattern `arg` holds, `None` when it names one file (it has no pattern, or a file
    /// of that very name exists). Patterns in the folder part are refused.
    pub fn parse(arg: &str) -> Result<Option<Pattern>, Error> {
        if arg == "-" || Path::new(arg).is_file() {
            return Ok(None);
        }
        let (dir, name) = split(arg);
        let dir_text = dir.to_string_lossy();
        if printf_parts(arg, &dir_text).ok().flatten().is_some() || has_glob(&dir_text) {
            return Err(Error::request(format!(
                "{arg}: a frame pattern goes in the file name, not in the folder"
            )));
        }
        if let Some((prefix, width, suffix)) = printf_parts(arg, &name)? {
            return Ok(Some(Pattern::Printf(Printf {
                dir,
                prefix,
                width,
                suffix,
            })));
        }
        if has_glob(&name) {
            return Ok(Some(Pattern::Glob { dir, name }));
        }
        Ok(None)
    }

    /// An output pattern: printf only.
    pub fn output(arg: &str) -> Result<Option<Printf>, Error> {
        if arg == "-" {
            return Ok(None);
        }
        let (dir, name) = split(arg);
        if has_glob(&name) {
            return Err(Error::request(format!(
                "{arg}: an output pattern numbers frames with %d or %0Nd; * ? [ ] only match inputs"
            )));
        }
        Ok(
            printf_parts(arg, &name)?.map(|(prefix, width, suffix)| Printf {
                dir,
                prefix,
                width,
                suffix,
            }),
        )
    }

    /// The files the pattern matches, in frame order (see the module's documentation);
    /// refused when it matches none.
    pub fn expand(&self, arg: &str) -> Result<Vec<Frame>, Error> {
        let dir = match self {
            Pattern::Printf(p) => &p.dir,
            Pattern::Glob { dir, .. } => dir,
        };
        let entries = std::fs::read_dir(dir).map_err(|e| {
            Error::request(format!(
                "{arg}: cannot list the folder {}: {e}",
                dir.display()
            ))
        })?;
        let mut names: Vec<String> = entries
            .filter_map(|e| e.ok())
            .filter(|e| e.file_type().map(|t| !t.is_dir()).unwrap_or(false))
            .filter_map(|e| e.file_name().to_str().map(str::to_string))
            .filter(|n| !n.starts_with('.'))
            .collect();
        let mut frames: Vec<Frame> = match self {
            Pattern::Printf(p) => names
                .iter()
                .filter_map(|n| {
                    p.number(n).map(|number| Frame {
                        number,
                        path: dir.join(n),
                    })
                })
                .collect(),
            Pattern::Glob { name, .. } => {
                names.retain(|n| glob_match(name.as_bytes(), n.as_bytes()));
                names.sort();
                names
                    .into_iter()
                    .enumerate()
                    .map(|(i, n)| Frame {
                        number: i as u64,
                        path: dir.join(n),
                    })
                    .collect()
            }
        };
        frames.sort_by_key(|f| f.number);
        if frames.is_empty() {
            return Err(Error::request(format!(
                "{arg}: the pattern matches no file in {}",
                dir.display()
            )));
        }
        Ok(frames)
    }
}

/// Whether `name` matches the shell glob `pat` (`*` any run, `?` one character, `[abc]`,
/// `[a-z]`, `[!…]` one of a set); bytes, not characters, for `?` outside ASCII.
pub fn glob_match(pat: &[u8], name: &[u8]) -> bool {
    // Iterative with one backtrack point: the last `*`.
    let (mut p, mut n) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while n < name.len() {
        if p < pat.len() {
            match pat[p] {
                b'*' => {
                    star = Some((p, n));
                    p += 1;
                    continue;
                }
                b'?' => {
                    p += 1;
                    n += 1;
                    continue;
                }
                b'[' => {
                    if let Some((hit, next)) = class(&pat[p..], name[n]) {
                        if hit {
                            p += next;
                            n += 1;
                            continue;
                        }
                    } else if name[n] == b'[' {
                        p += 1;
                        n += 1;
                        continue;
                    }
                }
                c if c == name[n] => {
                    p += 1;
                    n += 1;
                    continue;
                }
                _ => {}
            }
        }
        match star {
            Some((sp, sn)) => {
                p = sp + 1;
                n = sn + 1;
                star = Some((sp, sn + 1));
            }
            None => return false,
        }
    }
    pat[p..].iter().all(|&c| c == b'*')
}

/// A `[…]` class at the start of `pat`: whether `c` is in it and the class's length;
/// `None` when the bracket is not closed (then it is a plain `[`).
fn class(pat: &[u8], c: u8) -> Option<(bool, usize)> {
    let mut i = 1;
    let negate = matches!(pat.get(i), Some(b'!' | b'^'));
    if negate {
        i += 1;
    }
    let mut hit = false;
    let mut first = true;
    while i < pat.len() {
        if pat[i] == b']' && !first {
            return Some((hit != negate, i + 1));
        }
        first = false;
        if pat.get(i + 1) == Some(&b'-') && pat.get(i + 2).is_some_and(|&e| e != b']') {
            hit |= (pat[i]..=pat[i + 2]).contains(&c);
            i += 3;
        } else {
            hit |= pat[i] == c;
            i += 1;
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn globs_match_as_shells_do() {
        let m = |p: &str, n: &str| glob_match(p.as_bytes(), n.as_bytes());
        assert!(m("*.exr", "a.exr") && m("*.exr", ".exr") && !m("*.exr", "a.exr.tmp"));
        assert!(m("f?.png", "f1.png") && !m("f?.png", "f12.png"));
        assert!(m("[ab]*", "b9") && !m("[ab]*", "c9") && m("[!ab]*", "c9"));
        assert!(m("x[0-9]y", "x5y") && !m("x[0-9]y", "xay"));
        assert!(m("a*b*c", "aXbYbZc") && !m("a*b*c", "aXbYbZ"));
        assert!(m("[", "[") && m("a[b", "a[b"));
    }

    #[test]
    fn printf_patterns_print_and_match_the_same_names() {
        let Some(Pattern::Printf(p)) = Pattern::parse("out/f_%05d.exr").unwrap() else {
            panic!("a printf pattern")
        };
        assert_eq!(p.path(12), Path::new("out/f_00012.exr"));
        assert_eq!(p.number("f_00012.exr"), Some(12));
        assert_eq!(p.number("f_123456.exr"), Some(123456));
        assert_eq!(p.number("f_12.exr"), None);
        assert_eq!(p.number("f_0001x.exr"), None);
        let Some(Pattern::Printf(q)) = Pattern::parse("100%%_%d.png").unwrap() else {
            panic!("a printf pattern")
        };
        assert_eq!(q.path(7), Path::new("./100%_7.png"));
        assert_eq!(q.number("100%_07.png"), None);
        for bad in [
            "a%s.exr",
            "a%5d.exr",
            "a%d_%d.exr",
            "dir%d/a.exr",
            "d*/a.exr",
        ] {
            let e = Pattern::parse(bad).unwrap_err();
            assert_eq!(e.fault, mirrorball_core::Fault::Request, "{bad}");
        }
        assert_eq!(Pattern::parse("plain.exr").unwrap(), None);
        assert!(Pattern::output("o/*.png").is_err());
    }
}
