//! `convert --manifest FILE`: many conversions, each a job of its own.
//!
//! A manifest is JSON lines (`.jsonl`, `.ndjson`, `.json`, or any file whose first line
//! starts with `{`): one object a line, `{"input": …, "output": …, "options": "--to cube
//! --size 512"}` (`options` a string split at spaces, or an array of strings; optional); or
//! CSV: `input,output,options` a line, fields quoted with `"` when they hold commas, an
//! optional header line `input,output,options`. Blank lines and lines starting with `#` are
//! skipped. Job `k` runs exactly as `mirrorball convert INPUT OUTPUT <the command line's
//! other flags> <options>` would, the job's options winning over the command line's; its
//! input and output may be frame patterns.
//!
//! The whole manifest is read and every job's arguments parsed before the first job runs, so
//! a malformed line stops the run before any work, naming its line. Jobs are numbered from 0
//! in file order; `--shard i/n` runs slice `i` of them (see `shard.rs`). A job whose
//! outputs all exist is skipped: each output is written to a temporary file and renamed into
//! place only when whole, so an output that exists is complete, and a run killed anywhere
//! is resumed by running it again. Each job prints one JSON line (log.rs); a job that fails
//! does not stop the others, and the run then exits with status 1.

use super::log::{Log, Status};
use super::pattern::Pattern;
use super::record::{self, Verdict};
use super::shard::Shard;
use crate::error::CliError;
use crate::spec::ProjSpec;
use crate::{save, ConvertArgs};
use clap::{Args, FromArgMatches};
use mirrorball_core::WorldProjection;
use serde_json::{json, Value};
use std::collections::HashMap;
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// One line of a manifest.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Job {
    /// Its line in the file, from 1.
    pub line: usize,
    pub input: String,
    pub output: String,
    pub options: Vec<String>,
}

/// Reads the jobs of a manifest's `text`; `csv` picks the format (see the module's
/// documentation), `None` to tell by the first line.
pub fn parse(name: &str, text: &str, csv: Option<bool>) -> Result<Vec<Job>, CliError> {
    let lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let csv = csv.unwrap_or_else(|| {
        !text
            .lines()
            .map(str::trim)
            .find(|l| !l.is_empty() && !l.starts_with('#'))
            .is_some_and(|l| l.starts_with('{'))
    });
    let mut jobs = Vec::new();
    for (line, l) in lines {
        let bad = |why: String| CliError::request(format!("{name}:{line}: {why}"));
        let job = if csv {
            let fields = csv_fields(l).map_err(|e| bad(e.into()))?;
            if jobs.is_empty() && fields.first().map(String::as_str) == Some("input") {
                continue; // the header
            }
            if !(2..=3).contains(&fields.len()) {
                return Err(bad(format!(
                    "{} field(s); a CSV job is input,output[,options]",
                    fields.len()
                )));
            }
            Job {
                line,
                input: fields[0].clone(),
                output: fields[1].clone(),
                options: fields
                    .get(2)
                    .map(|o| o.split_whitespace().map(str::to_string).collect())
                    .unwrap_or_default(),
            }
        } else {
            let v: Value =
                serde_json::from_str(l).map_err(|e| bad(format!("not a JSON object: {e}")))?;
            let Value::Object(m) = v else {
                return Err(bad("not a JSON object".into()));
            };
            if let Some(k) = m
                .keys()
                .find(|k| !["input", "output", "options"].contains(&k.as_str()))
            {
                return Err(bad(format!(
                    "unknown key \"{k}\" (a job has input, output, options)"
                )));
            }
            let text_of = |k: &str| match m.get(k) {
                Some(Value::String(s)) if !s.is_empty() => Ok(s.clone()),
                Some(_) => Err(bad(format!("\"{k}\" must be a non-empty string"))),
                None => Err(bad(format!("no \"{k}\""))),
            };
            let options = match m.get("options") {
                None | Some(Value::Null) => Vec::new(),
                Some(Value::String(s)) => s.split_whitespace().map(str::to_string).collect(),
                Some(Value::Array(a)) => a
                    .iter()
                    .map(|o| o.as_str().map(str::to_string))
                    .collect::<Option<Vec<_>>>()
                    .ok_or_else(|| {
                        bad("\"options\" must be a string or an array of strings".into())
                    })?,
                Some(_) => {
                    return Err(bad(
                        "\"options\" must be a string or an array of strings".into()
                    ))
                }
            };
            Job {
                line,
                input: text_of("input")?,
                output: text_of("output")?,
                options,
            }
        };
        if job.input.is_empty() || job.output.is_empty() {
            return Err(bad("an empty input or output".into()));
        }
        jobs.push(job);
    }
    if jobs.is_empty() {
        return Err(CliError::request(format!(
            "{name}: no jobs in the manifest"
        )));
    }
    Ok(jobs)
}

/// The fields of one CSV line (RFC 4180 quoting, one line a record).
fn csv_fields(l: &str) -> Result<Vec<String>, &'static str> {
    let mut fields = vec![String::new()];
    let mut chars = l.chars().peekable();
    let mut quoted = false;
    while let Some(c) = chars.next() {
        let f = fields.last_mut().expect("one field at least");
        match (quoted, c) {
            (true, '"') if chars.peek() == Some(&'"') => {
                chars.next();
                f.push('"');
            }
            (true, '"') => quoted = false,
            (true, c) => f.push(c),
            (false, '"') if f.trim().is_empty() => {
                f.clear();
                quoted = true;
            }
            (false, '"') => return Err("a quote inside an unquoted field"),
            (false, ',') => fields.push(String::new()),
            (false, c) => f.push(c),
        }
    }
    if quoted {
        return Err("a quoted field is not closed");
    }
    Ok(fields.into_iter().map(|f| f.trim().to_string()).collect())
}

/// The command line's own `convert` flags, as given, less `--manifest`, `--shard` and the
/// global `--max-memory` (already in force): what every job is run with before its own
/// options.
fn base_flags() -> Vec<OsString> {
    let args: Vec<OsString> = std::env::args_os().skip(1).collect();
    let at = args
        .iter()
        .position(|a| a == "convert")
        .map_or(0, |k| k + 1);
    let mut out = Vec::new();
    let mut it = args[at..].iter();
    while let Some(a) = it.next() {
        let s = a.to_string_lossy();
        const TAKEN: [&str; 3] = ["--manifest", "--shard", "--max-memory"];
        if TAKEN.contains(&s.as_ref()) {
            it.next();
        } else if !TAKEN.iter().any(|t| s.starts_with(&format!("{t}="))) {
            out.push(a.clone());
        }
    }
    out
}

/// Job `job`'s arguments: `convert INPUT OUTPUT <base> <options>`, later flags winning.
fn job_args(base: &[OsString], job: &Job) -> Result<ConvertArgs, String> {
    let cmd = ConvertArgs::augment_args(clap::Command::new("convert"))
        .no_binary_name(true)
        .args_override_self(true);
    let tokens: Vec<OsString> = [job.input.clone().into(), job.output.clone().into()]
        .into_iter()
        .chain(base.iter().cloned())
        .chain(job.options.iter().map(OsString::from))
        .collect();
    let m = cmd.try_get_matches_from(tokens).map_err(|e| {
        e.to_string()
            .lines()
            .next()
            .unwrap_or_default()
            .trim_start_matches("error: ")
            .to_string()
    })?;
    let a = ConvertArgs::from_arg_matches(&m).map_err(|e| e.to_string())?;
    if a.frames.manifest.is_some() || a.frames.shard.is_some() {
        return Err("--manifest and --shard go on the command line, not in a job".into());
    }
    if a.to.is_empty() {
        return Err("no --to (give it on the command line or in the job's options)".into());
    }
    Ok(a)
}

/// The files job `a` writes, when it is one conversion (`None` for frame patterns, which
/// skip their done frames themselves).
fn outputs(a: &ConvertArgs) -> Option<Vec<PathBuf>> {
    if Pattern::output(&a.output).ok()?.is_some() || a.output == "-" {
        return None;
    }
    let layers = ProjSpec::parse(&a.to).ok()?.build(None).ok()?.layer_count();
    let opts = save::SaveOptions {
        layout: a.layout.as_deref().and_then(|l| l.parse().ok()),
        write: Default::default(),
        mips: a.mips,
        keep_invalid: a.input_args.keep_invalid,
    };
    Some(
        save::layer_files(&a.output, layers, &opts)
            .unwrap_or_else(|| vec![PathBuf::from(&a.output)]),
    )
}

pub fn run(a: &ConvertArgs) -> Result<(), CliError> {
    let name = a
        .frames
        .manifest
        .as_deref()
        .expect("routed here for --manifest");
    if !a.input.is_empty() || !a.output.is_empty() {
        return Err(CliError::request(format!(
            "--manifest {name}: the jobs' inputs and outputs are in the manifest; give no INPUT OUTPUT on the command line"
        )));
    }
    let shard = a.frames.shard.as_deref().map(Shard::parse).transpose()?;
    mirrorball_io::Error::check_input(std::path::Path::new(name))
        .map_err(|e| CliError::from(e).context("--manifest"))?;
    let text = std::fs::read_to_string(name)
        .map_err(|e| CliError::request(format!("--manifest {name}: {e}")))?;
    let csv = match std::path::Path::new(name)
        .extension()
        .and_then(|e| e.to_str())
    {
        Some("csv") => Some(true),
        Some("jsonl" | "ndjson" | "json") => Some(false),
        _ => None,
    };
    let jobs = parse(name, &text, csv)?;
    let base = base_flags();
    let mut parsed = Vec::with_capacity(jobs.len());
    let mut seen: HashMap<&str, usize> = HashMap::new();
    for job in &jobs {
        let args = job_args(&base, job)
            .map_err(|e| CliError::request(format!("{name}:{}: {e}", job.line)))?;
        if let Some(first) = seen.insert(&job.output, job.line) {
            return Err(CliError::request(format!(
                "{name}:{}: the output {} is line {first}'s too; each job needs its own",
                job.line, job.output
            )));
        }
        parsed.push(args);
    }
    let range = shard.map_or(0..jobs.len(), |s| s.range(jobs.len()));
    let log = Log {
        on: true,
        to_stderr: false,
    };
    let (mut done, mut skipped, mut failed) = (0, 0, 0);
    let (mut unknown, mut again) = (0u64, 0u64);
    let mut made = record::Made::default();
    for k in range.clone() {
        let (job, args) = (&jobs[k], parsed[k].clone());
        let fields = json!({"job": k, "line": job.line, "input": job.input, "output": job.output});
        let t = Instant::now();
        // A job of one conversion is recorded as a sequence's frame is (`record.rs`).
        let outs = outputs(&args);
        let stamp = record::stamp(
            &record::settings(&super::frames_request(&args)?),
            Path::new(&args.input),
        );
        if let Some(o) = outs.as_ref().filter(|o| o.iter().all(|p| p.exists())) {
            match made.verdict(&o[0], stamp) {
                _ if a.frames.overwrite => {}
                Verdict::Other => again += 1,
                v => {
                    skipped += 1;
                    unknown += u64::from(v == Verdict::Unknown);
                    log.line(fields, Status::Skipped, t.elapsed(), None);
                    continue;
                }
            }
        }
        match super::super::convert::run(args) {
            Ok(()) => {
                if let Some(o) = &outs {
                    record::note(&o[0], stamp)?;
                }
                done += 1;
                log.line(fields, Status::Done, t.elapsed(), None);
            }
            Err(e) => {
                failed += 1;
                log.line(fields, Status::Failed, t.elapsed(), Some(&e.message));
                if !a.quiet {
                    eprintln!("mirrorball: job {k} (line {}): {e}", job.line);
                }
            }
        }
    }
    if !a.quiet {
        for line in record::kept_lines("job", skipped, unknown, again) {
            eprintln!("{line}");
        }
        eprintln!(
            "jobs {}..{} of {}: {done} done, {skipped} skipped (outputs exist), {failed} failed",
            range.start,
            range.end,
            jobs.len()
        );
    }
    if failed > 0 {
        return Err(CliError::input(format!(
            "{failed} of {} failed",
            mirrorball_core::count(range.len() as u64, "job")
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_lines_and_csv_give_the_same_jobs() {
        let j = parse(
            "m.jsonl",
            "# panoramas\n{\"input\": \"a.exr\", \"output\": \"a.ktx2\", \"options\": \"--to cube --size 64\"}\n\n{\"input\": \"b.exr\", \"output\": \"b.png\", \"options\": [\"--to\", \"latlong\"]}\n",
            None,
        )
        .unwrap();
        let c = parse(
            "m.csv",
            "input,output,options\na.exr,a.ktx2,--to cube --size 64\n\"b.exr\",b.png,\"--to latlong\"\n",
            None,
        )
        .unwrap();
        assert_eq!(j.len(), 2);
        assert_eq!(j[0].options, ["--to", "cube", "--size", "64"]);
        assert_eq!((j[1].line, c[1].line), (4, 3));
        for (a, b) in j.iter().zip(&c) {
            assert_eq!(
                (&a.input, &a.output, &a.options),
                (&b.input, &b.output, &b.options)
            );
        }
        assert_eq!(
            csv_fields("\"a,b\",\"say \"\"hi\"\"\",c").unwrap(),
            ["a,b", "say \"hi\"", "c"]
        );
    }

    #[test]
    fn a_malformed_line_is_named() {
        for (text, says) in [
            (
                "{\"input\": \"a\", \"output\": \"b\"}\n{\"input\": \"a\"\n",
                "m:2: not a JSON object",
            ),
            (
                "{\"input\": \"a\", \"output\": \"b\"}\n\n{\"input\": \"a\"}\n",
                "m:3: no \"output\"",
            ),
            (
                "{\"input\": \"a\", \"ouput\": \"b\"}\n",
                "m:1: unknown key \"ouput\"",
            ),
            (
                "{\"input\": \"a\", \"output\": \"b\", \"options\": 3}\n",
                "m:1: \"options\" must be",
            ),
            ("a.exr,b.exr\nc.exr\n", "m:2: 1 field(s)"),
            ("a.exr,\"b.exr\n", "m:1: a quoted field is not closed"),
            ("# nothing\n", "m: no jobs"),
        ] {
            let e = parse("m", text, None).unwrap_err();
            assert!(e.message.contains(says), "{text:?}: {}", e.message);
            assert_eq!(crate::error::exit_code(&e), 2);
        }
    }
}
