//! The one JSON line per frame or job: what ran, how it ended, how long it took.

use serde_json::{json, Value};
use std::io::Write;
use std::time::Duration;

/// How a frame or job ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    Done,
    /// Its outputs existed (and so were complete): not run again.
    Skipped,
    Failed,
}

impl Status {
    fn name(self) -> &'static str {
        match self {
            Status::Done => "done",
            Status::Skipped => "skipped",
            Status::Failed => "failed",
        }
    }
}

/// Where the lines go: standard output, or standard error when standard output carries
/// frames; nowhere when not asked for.
#[derive(Clone, Copy, Debug)]
pub struct Log {
    pub on: bool,
    pub to_stderr: bool,
}

impl Log {
    /// Writes `fields` with `status` and `seconds` added, as one line.
    pub fn line(&self, mut fields: Value, status: Status, took: Duration, error: Option<&str>) {
        if !self.on {
            return;
        }
        if let Value::Object(m) = &mut fields {
            m.insert("status".into(), json!(status.name()));
            m.insert(
                "seconds".into(),
                json!((took.as_secs_f64() * 1e4).round() / 1e4),
            );
            if let Some(e) = error {
                m.insert("error".into(), json!(e));
            }
        }
        let text = format!("{fields}\n");
        // One write per line, so that lines of parallel jobs never interleave.
        let _ = if self.to_stderr {
            std::io::stderr().lock().write_all(text.as_bytes())
        } else {
            let mut out = std::io::stdout().lock();
            out.write_all(text.as_bytes()).and_then(|_| out.flush())
        };
    }
}
