//! The interval a projection parameter's value must lie in: the constructors check with it
//! and the messages print it, so the two cannot disagree.

use std::fmt;

/// An interval of valid values, each end open or closed (an infinite end is open), with
/// the unit the values are in.
///
/// ```
/// use mirrorball_core::projection::Range;
/// let fov = Range::above(0.0).to(360.0).unit("°");
/// assert!(fov.contains(360.0) && !fov.contains(0.0) && !fov.contains(f64::NAN));
/// assert_eq!(fov.to_string(), "(0°, 360°]");
/// assert_eq!(
///     fov.check("fov", -90.0).unwrap_err().message,
///     "fov must be in (0°, 360°]; fov=-90 was given"
/// );
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    lo: f64,
    lo_open: bool,
    hi: f64,
    hi_open: bool,
    unit: &'static str,
}

impl Range {
    /// `(lo, ∞)`: above `lo`.
    pub const fn above(lo: f64) -> Range {
        Range {
            lo,
            lo_open: true,
            hi: f64::INFINITY,
            hi_open: true,
            unit: "",
        }
    }
    /// `[lo, ∞)`: `lo` or more.
    pub const fn from(lo: f64) -> Range {
        Range {
            lo_open: false,
            ..Range::above(lo)
        }
    }
    /// The same lower end, up to and with `hi`.
    pub const fn to(self, hi: f64) -> Range {
        Range {
            hi,
            hi_open: false,
            ..self
        }
    }
    /// The same lower end, below `hi`.
    pub const fn below(self, hi: f64) -> Range {
        Range {
            hi,
            hi_open: true,
            ..self
        }
    }
    /// The same interval, its values in `unit` (printed after each end: `°`).
    pub const fn unit(self, unit: &'static str) -> Range {
        Range { unit, ..self }
    }
    /// The upper end.
    pub fn hi(&self) -> f64 {
        self.hi
    }
    /// Whether `v` lies in the interval (NaN never does).
    pub fn contains(&self, v: f64) -> bool {
        let lo = if self.lo_open {
            v > self.lo
        } else {
            v >= self.lo
        };
        let hi = if self.hi_open {
            v < self.hi
        } else {
            v <= self.hi
        };
        lo && hi
    }
    /// `v` if the interval holds it, else the message: `KEY must be in (0°, 360°]; KEY=V was
    /// given`, the request's fault.
    pub fn check(&self, key: &str, v: f64) -> Result<f64, crate::Error> {
        if self.contains(v) {
            Ok(v)
        } else {
            Err(crate::Error::request(format!(
                "{key} must be in {self}; {key}={v} was given"
            )))
        }
    }
}

/// A value rounded to 1e-9 for people, without a sign on zero.
fn num(v: f64) -> String {
    let r = (v * 1e9).round() / 1e9;
    format!("{}", if r == 0.0 { 0.0 } else { r })
}

impl fmt::Display for Range {
    /// `(0°, 360°]`, `[0, ∞)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let end = |v: f64| {
            if v.is_infinite() {
                if v > 0.0 { "∞" } else { "-∞" }.to_string()
            } else {
                format!("{}{}", num(v), self.unit)
            }
        };
        write!(
            f,
            "{}{}, {}{}",
            if self.lo_open { '(' } else { '[' },
            end(self.lo),
            end(self.hi),
            if self.hi_open { ')' } else { ']' }
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_open_and_closed() {
        let r = Range::from(0.0);
        assert!(r.contains(0.0) && r.contains(1e300) && !r.contains(-1e-300));
        assert!(!r.contains(f64::INFINITY) && !r.contains(f64::NAN));
        assert_eq!(r.to_string(), "[0, ∞)");
        let r = Range::above(0.0).below(180.0).unit("°");
        assert!(!r.contains(180.0) && r.contains(179.999) && !r.contains(0.0));
        assert_eq!(r.to_string(), "(0°, 180°)");
        assert_eq!(r.check("vfov", 45.0), Ok(45.0));
        assert_eq!(
            r.check("vfov", 180.0).unwrap_err().message,
            "vfov must be in (0°, 180°); vfov=180 was given"
        );
    }
}
