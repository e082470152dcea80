//! Sizes the user asks for (`--size` of every command, `--env-size`, each side of render's
//! `WIDTHxHEIGHT`): one parser and one rule, `MIN..=MAX`, and one message for a size
//! outside it, zero, negative or too large alike. `MAX` is the largest size whose pictures
//! the output's container holds and mirrorball reads back ([`pictures`]); a size that would
//! not fit in memory is refused in the same words once the job's need is known
//! (`budget::check_size`).

use crate::error::Error;
use mirrorball_io::{Format, Limits};

/// The values a size may take, and why the largest is the largest.
#[derive(Clone, Debug)]
pub struct Bound {
    pub min: u32,
    pub max: u32,
    /// Why nothing above `max` is taken ("the largest cube face a .ktx2 holds").
    pub why: String,
}

impl Bound {
    /// The tighter of two bounds (the larger minimum, the smaller maximum and its reason).
    pub fn and(self, other: Bound) -> Bound {
        let min = self.min.max(other.min);
        if other.max < self.max {
            Bound { min, ..other }
        } else {
            Bound { min, ..self }
        }
    }

    /// `value` when it lies within the bound; otherwise the rule's one message: "--size
    /// -5: outside 1..=16384 (…)".
    pub fn check(&self, flag: &str, value: i64) -> Result<u32, Error> {
        if value >= self.min as i64 && value <= self.max as i64 {
            return Ok(value as u32);
        }
        Err(self.refusal(flag, &value.to_string()))
    }

    /// The rule's message for `shown`, a value outside the bound as the user gave it.
    pub fn refusal(&self, flag: &str, shown: &str) -> Error {
        Error::request(format!(
            "{flag} {shown}: outside {}..={} ({})",
            self.min, self.max, self.why
        ))
    }
}

/// A size flag's value for clap: any whole number, so that zero and negative sizes reach
/// the rule and its message (which knows the largest size). Text that is no number is the
/// request's fault.
pub fn parse(s: &str) -> Result<i64, crate::Error> {
    s.trim()
        .parse::<i64>()
        .map_err(|_| crate::Error::request(format!("'{s}' is not a whole number of texels")))
}

/// `--size`'s text, `W` or `WxH` (also `W×H`), as numbers (each checked against the
/// container's bound in the plan that takes it).
pub fn parse_extent(s: &str) -> Result<(i64, Option<i64>), crate::Error> {
    let s = s.trim();
    match s.split_once(['x', 'X', '×']) {
        Some((w, h)) => Ok((parse(w)?, Some(parse(h)?))),
        None => Ok((parse(s)?, None)),
    }
}

/// The largest `s` in `1..=hi` for which `fits(s)` holds, `fits` holding up to some size
/// and not beyond it; 0 when it holds for none.
pub fn largest(hi: u32, fits: impl Fn(u32) -> bool) -> u32 {
    let (mut lo, mut hi) = (0u32, hi);
    while lo < hi {
        let mid = lo + (hi - lo).div_ceil(2);
        if fits(mid) {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    lo
}

/// Why a file of `format` holds no larger side ([`Format::max_side`]), for messages.
fn side_reason(format: Format) -> &'static str {
    match format {
        Format::Jpeg => "a JPEG's sides are 16-bit",
        Format::Ktx2 | Format::Dds | Format::Ktx1 => "the largest cube face GPUs take",
        Format::BabylonEnv | Format::GltfIbl => "the largest cube face GPUs take",
        Format::Exr | Format::Hdr | Format::Png | Format::Webp => "the format's own limit",
    }
}

/// The sizes of an output of `format` whose pictures, `(width, height)` of each file (or
/// cube face) at a size as `picture` gives them, the container holds and mirrorball reads
/// back (its reading bounds, `mirrorball_io::Limits`); `what` names the output in the
/// reason ("a .ktx2 cube").
pub fn pictures(format: Format, what: &str, picture: impl Fn(u32) -> (u64, u64)) -> Bound {
    let read = Limits::default();
    let (side, side_why) = (format.max_side(), side_reason(format));
    let read_side = read.max_dimension as u64;
    let fits_side = |s| {
        let (w, h) = picture(s);
        w.max(h) <= side.min(read_side)
    };
    let fits = |s| {
        let (w, h) = picture(s);
        fits_side(s) && w.saturating_mul(h) <= read.max_texels
    };
    let max = largest(1 << 20, fits);
    let why = if fits_side(max + 1) {
        format!(
            "{what}: mirrorball reads pictures of at most {} texels",
            read.max_texels
        )
    } else if side <= read_side {
        format!("{what}: {side_why}, at most {side} texels a side")
    } else {
        format!("{what}: mirrorball reads pictures of at most {read_side} texels a side")
    };
    Bound { min: 1, max, why }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_largest_size_is_found_exactly() {
        for n in [0u32, 1, 2, 3, 1000, 4096, 1 << 20] {
            assert_eq!(largest(1 << 20, |s| s <= n), n, "{n}");
        }
    }

    #[test]
    fn the_bound_follows_the_container_and_the_reader() {
        // A cube face in a GPU container; a lat-long picture twice as wide as high, held
        // by the reader's texel bound (2²⁸: 23170 × 11585 is the last that fits).
        let k = pictures(Format::Ktx2, "a .ktx2 cube", |s| (s as u64, s as u64));
        assert_eq!(k.max, 16384, "{k:?}");
        let l = pictures(Format::Exr, "a latlong .exr", |s| (s as u64, s as u64 / 2));
        assert_eq!(l.max, 23170, "{l:?}");
        assert!(l.why.contains("268435456"), "{}", l.why);
        // A JPEG's sides are 16-bit: a thin strip twice as wide as the size is 65536 wide
        // at 32768, long before its texels reach the reader's bound (an hstrip cube of
        // 6688² faces reaches that bound first).
        let c = pictures(Format::Jpeg, "a cube .jpg", |s| (6 * s as u64, s as u64));
        assert_eq!(c.max, 6688, "{c:?}");
        let j = pictures(Format::Jpeg, "a strip .jpg", |s| {
            (2 * s as u64, s as u64 / 16)
        });
        assert_eq!(j.max, 32767, "{j:?}");
        for v in [-5i64, 0, 32768] {
            let e = j.check("--size", v).unwrap_err();
            assert_eq!(e.fault, mirrorball_core::Fault::Request);
            assert!(
                e.message
                    == format!("--size {v}: outside 1..=32767 (a strip .jpg: a JPEG's sides are 16-bit, at most 65535 texels a side)"),
                "{}",
                e.message
            );
        }
        assert_eq!(j.check("--size", 32767).unwrap(), 32767);
        let e = parse("12x").unwrap_err();
        assert!(e.message.contains("whole number"), "{e}");
        assert_eq!(e.fault, mirrorball_core::Fault::Request);
        assert_eq!(parse("-5").unwrap(), -5);
    }
}
