//! Memory a job will need, estimated before it starts and refused, with a message that says
//! how much and what to do, when it would not fit (instead of the allocator's abort).

use crate::error::Error;
use std::sync::OnceLock;

/// `--max-memory`, when given.
static MAX: OnceLock<u64> = OnceLock::new();

/// Sets the limit from `--max-memory`.
pub fn set_max(bytes: Option<u64>) {
    if let Some(b) = bytes {
        let _ = MAX.set(b);
    }
}

/// The limit: `--max-memory`, or else the memory the system has available now (Linux:
/// `MemAvailable` in `/proc/meminfo`); `None` when neither is known.
fn limit() -> Option<(u64, &'static str)> {
    if let Some(&m) = MAX.get() {
        return Some((m, "--max-memory"));
    }
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some((kb * 1024, "available memory"))
}

/// What the process holds before any map: its code and libraries, its threads' stacks and
/// the allocator's own (a conversion of a 512×256 map to 16×8 peaks at 10.5–12.5 MB).
pub const PROCESS: u64 = 10 << 20;

/// Refuses `what` when it needs more than the limit: `held` bytes it already holds (a
/// source read into memory) and `more` it will allocate at its peak, besides the process
/// itself ([`PROCESS`]). `hint` says what to change ("a smaller --size").
pub fn check(what: &str, held: u64, more: u64, hint: &str) -> Result<(), Error> {
    let Some((max, source)) = limit() else {
        return Ok(());
    };
    // Memory available now excludes what is already held.
    let max = if MAX.get().is_some() {
        max
    } else {
        max.saturating_add(held).saturating_add(PROCESS)
    };
    let bytes = held.saturating_add(more).saturating_add(PROCESS);
    if bytes <= max {
        return Ok(());
    }
    Err(Error::request(format!(
        "{what} needs about {} of memory, more than the {} of {source}; use {hint}, or raise --max-memory",
        human(bytes),
        human(max)
    )))
}

/// Refuses converting `what` when it would not fit: the source (`held`), the conversion's
/// own (`scratch`: the source's pyramid) and the output (`made`) while converting; then,
/// the source dropped, the output and what writing it copies (`written`).
pub fn check_convert(
    what: &str,
    held: u64,
    (scratch, made, written): (u64, u64, u64),
    hint: &str,
) -> Result<(), Error> {
    let converting = held.saturating_add(scratch).saturating_add(made);
    let writing = made.saturating_add(written);
    check(
        what,
        held,
        converting.max(writing).saturating_sub(held),
        hint,
    )
}

/// `bytes` for people: "12.9 GB".
pub fn human(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= 1e9 {
        format!("{:.1} GB", b / 1e9)
    } else if b >= 1e6 {
        format!("{:.0} MB", b / 1e6)
    } else {
        format!("{:.0} kB", (b / 1e3).max(1.0))
    }
}

/// Parses a `--max-memory` value: bytes, or a number with K, M, G or T (powers of 1024;
/// an optional `B` or `iB` after it). Text that is none is the request's fault.
pub fn parse_bytes(s: &str) -> Result<u64, crate::Error> {
    bytes_text(s).map_err(crate::Error::request)
}

fn bytes_text(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let lower = t.to_ascii_lowercase();
    let digits = lower.trim_end_matches(['b', 'i']);
    let (num, mult) = match digits.chars().last() {
        Some('k') => (&digits[..digits.len() - 1], 1u64 << 10),
        Some('m') => (&digits[..digits.len() - 1], 1 << 20),
        Some('g') => (&digits[..digits.len() - 1], 1 << 30),
        Some('t') => (&digits[..digits.len() - 1], 1 << 40),
        _ => (digits, 1),
    };
    match num.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v * (mult as f64) < 1.8e19 => {
            Ok((v * mult as f64) as u64)
        }
        _ => Err(format!("'{s}' is not a memory size (for example 8G, 512M)")),
    }
}

/// Refuses prefiltering `what` when it would not fit: the source `env` is held, the
/// prefilterer holds `working` bytes at its peak (its working cube and pyramids:
/// `Prefilterer::memory_for_outputs`), and `made` texels of the source's channels are the
/// outputs (prefilter's chain, a bake's cubes).
pub fn check_prefilter(
    what: &str,
    env: &mirrorball_core::EnvMap,
    working: u64,
    made: u64,
    hint: &str,
) -> Result<(), Error> {
    let c = env.channels() as u64;
    let held = f32_texels(
        env.width() as u64 * env.height() as u64 * env.layers().len() as u64,
        c,
    );
    check(
        what,
        held,
        working.saturating_add(f32_texels(made, c)),
        hint,
    )
}

/// Bytes of `texels` texels of `channels` `f32` channels.
pub fn f32_texels(texels: u64, channels: u64) -> u64 {
    texels.saturating_mul(channels).saturating_mul(4)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse() {
        assert_eq!(parse_bytes("8G").unwrap(), 8 << 30);
        assert_eq!(parse_bytes("512MiB").unwrap(), 512 << 20);
        assert_eq!(parse_bytes("1.5k").unwrap(), 1536);
        assert_eq!(parse_bytes("1000").unwrap(), 1000);
        for bad in ["", "G", "-1G", "nan", "x", "1e30T"] {
            let e = parse_bytes(bad).unwrap_err();
            assert_eq!(e.fault, mirrorball_core::Fault::Request, "{bad}");
        }
    }
}
