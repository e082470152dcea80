//! What an output cannot hold, said before it is written: each map measured against the
//! storage of its file (`mirrorball_io::Range::measure_map`, the table in
//! `mirrorball_encode::range`), NaN and infinities the work made replaced by 0 unless
//! `--keep-invalid`, and one line saying how many texels are clipped, the largest value, the
//! share of the energy lost (solid-angle weighted) and how to keep it.
//!
//! Display-referred outputs (8- and 16-bit PNG, JPEG) are white past 1 by nature, after
//! exposure and tone curve: their clipping is not reported. The writers clip every value
//! by the same table ([`mirrorball_io::Range::fit`]), so what is reported is what is written.

use mirrorball_core::{EnvMap, Image};
use mirrorball_io::{Clipped, Encoding, Storage};
use std::borrow::Cow;

/// What writing one file changes: its storage, and each map it holds measured (a level of
/// a chain, an eye of a pair, a layer written on its own, or the one map).
#[derive(Clone, Debug)]
pub struct Report {
    /// How the file stores values.
    pub storage: Storage,
    /// Each map measured, in the file's order.
    pub parts: Vec<Clipped>,
    /// What a part is, for the line when there are several ("level").
    pub part: &'static str,
    /// Each part's name for the line, when not "`part` i" ("the diffuse cube").
    pub labels: Vec<String>,
    /// What the parts are of: "map", or "picture" (a rendered frame, every pixel alike).
    pub whole: &'static str,
    /// NaN and infinite values the work made, replaced by 0 (`--keep-invalid` off).
    pub replaced: u64,
}

impl Report {
    /// Nothing measured yet, for a file in `storage`.
    pub fn new(storage: Storage) -> Report {
        Report {
            storage,
            parts: Vec::new(),
            part: "level",
            labels: Vec::new(),
            whole: "map",
            replaced: 0,
        }
    }

    /// Everything measured as one: counts summed, the largest value.
    pub fn sum(&self) -> Clipped {
        self.parts.iter().fold(Clipped::default(), |a, &b| a + b)
    }

    /// The measured parts of `other` (another file of the same storage, or the next levels)
    /// after these.
    pub fn extend(&mut self, other: Report) {
        let named = |r: &Report| r.labels.len() == r.parts.len() && !r.parts.is_empty();
        if named(self) || named(&other) {
            let mut labels = self.names();
            labels.extend(other.names());
            self.labels = labels;
        }
        self.parts.extend(other.parts);
        self.replaced += other.replaced;
    }

    /// Stops of exposure that bring the largest value inside the storage's range.
    pub fn stops_to_fit(&self) -> u32 {
        self.sum().stops_to_fit(&self.storage.range())
    }

    /// Whether values past the range are clipped (and reported: not display codes).
    pub fn clips(&self) -> bool {
        !self.storage.range().display && self.sum().texels > 0
    }

    /// The one line for `file`, or `None` when nothing is lost: the clipped texels, the
    /// largest value, the share of the energy lost (the part that loses the most, when the
    /// file holds several), what else was replaced, and `keep`: the ways to keep it
    /// ("--precision float"), joined by "or".
    pub fn line(&self, file: &str, keep: &[String]) -> Option<String> {
        let all = self.sum();
        let range = self.storage.range();
        let mut said = Vec::new();
        if self.clips() {
            let mut s = format!(
                "{} texel{} past {}'s largest value {}, written as it (the largest {})",
                all.texels,
                if all.texels == 1 { "" } else { "s" },
                self.storage.name(),
                largest_values(&range.max),
                number(all.largest)
            );
            s += &self.share_text();
            said.push(s);
        }
        if all.negative > 0 && !range.display {
            said.push(format!(
                "{} negative value(s) written as 0 ({} holds none)",
                all.negative,
                self.storage.name()
            ));
        }
        if self.replaced > 0 {
            said.push(format!(
                "{} NaN or infinite value(s) made by the work written as 0 (--keep-invalid keeps them)",
                self.replaced
            ));
        } else if all.invalid > 0 && !range.special {
            said.push(format!(
                "{} NaN or infinite value(s) written as 0 or the largest value ({} holds none)",
                all.invalid,
                self.storage.name()
            ));
        }
        if said.is_empty() {
            return None;
        }
        let mut line = format!("warning: {file}: {}", said.join("; "));
        if self.clips() && !keep.is_empty() {
            line += &format!("; to keep it: {}", keep.join(", or "));
        }
        Some(line)
    }

    /// Each part's name: its label, or "`part` i".
    fn names(&self) -> Vec<String> {
        if self.labels.len() == self.parts.len() {
            return self.labels.clone();
        }
        (0..self.parts.len())
            .map(|i| format!("{} {i}", self.part))
            .collect()
    }

    /// ": 4.1% of the map's energy lost", or of the part that loses the most.
    fn share_text(&self) -> String {
        let shares: Vec<Option<f64>> = self.parts.iter().map(Clipped::share).collect();
        let worst = shares
            .iter()
            .enumerate()
            .filter_map(|(i, s)| s.map(|s| (i, s)))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        match worst {
            Some((_, s)) if self.parts.len() == 1 => {
                format!(": {} of the {}'s energy lost", percent(s), self.whole)
            }
            Some((i, s)) => format!(
                ": {} of {}'s energy lost (the worst of {})",
                percent(s),
                self.names()[i],
                self.parts.len(),
            ),
            None => String::new(),
        }
    }
}

/// `maps` (one file's) measured against `storage`; when they hold NaN or infinite values and
/// `keep_invalid` is off, a copy with those replaced by 0 to write instead.
pub fn measure_maps<'a>(
    maps: &'a [EnvMap],
    storage: Storage,
    keep_invalid: bool,
) -> (Cow<'a, [EnvMap]>, Report) {
    let range = storage.range();
    let mut report = Report::new(storage);
    report.parts = maps.iter().map(|m| range.measure_map(m)).collect();
    if report.sum().invalid == 0 || keep_invalid {
        return (Cow::Borrowed(maps), report);
    }
    let mut fixed = maps.to_vec();
    let report = measure_in_place(&mut fixed, storage, keep_invalid);
    (Cow::Owned(fixed), report)
}

/// [`measure_maps`] of maps the caller owns: NaN and infinities replaced in place.
pub fn measure_in_place(maps: &mut [EnvMap], storage: Storage, keep_invalid: bool) -> Report {
    let range = storage.range();
    let mut report = Report::new(storage);
    report.parts = maps.iter().map(|m| range.measure_map(m)).collect();
    if report.sum().invalid > 0 && !keep_invalid {
        report.replaced = maps.iter_mut().map(EnvMap::sanitize).sum();
        // What is left to report is what the writers will clip.
        report.parts = maps.iter().map(|m| range.measure_map(m)).collect();
    }
    report
}

/// A rendered picture measured against `storage`, every pixel weighing the same.
pub fn measure_picture(img: &Image, storage: Storage) -> Report {
    let mut report = Report::new(storage);
    report.parts = vec![storage.range().measure(img, Some(&|_, _| 1.0))];
    report.whole = "picture";
    report
}

/// `--exposure E`: the exposure that brings the largest value inside (`current − n` stops).
pub fn exposure_advice(flag: &str, current: f32, report: &Report) -> String {
    format!("{flag} {}", number(current - report.stops_to_fit() as f32))
}

/// `--precision float`, when `storage` is half (the ways of a command that has the flag).
pub fn precision_advice(storage: Storage) -> Option<String> {
    (storage == Storage::Texels(Encoding::Rgba16F)).then(|| "--precision float".to_string())
}

/// The channels' largest values: "65504", or "65024 (blue 64512)" where blue's differs.
fn largest_values(max: &[f32; 3]) -> String {
    if max[0] == max[1] && max[1] == max[2] {
        return number(max[0]);
    }
    let mut s = number(max[0]);
    for (k, name) in [(1, "green"), (2, "blue")] {
        if max[k] != max[0] {
            s += &format!(" ({name} {})", number(max[k]));
        }
    }
    s
}

/// A value for people: whole below 10⁷ (two decimals below 100, unless whole), else three
/// significant digits.
fn number(v: f32) -> String {
    if v == v.round() && v.abs() < 1e7 {
        format!("{v}")
    } else if v.abs() < 100.0 {
        format!("{v:.2}")
    } else if v.abs() < 1e7 {
        format!("{v:.0}")
    } else {
        format!("{v:.2e}")
    }
}

/// A share as a percentage with enough digits to be non-zero.
fn percent(s: f64) -> String {
    let p = 100.0 * s;
    if p >= 0.1 || p == 0.0 {
        format!("{p:.1}%")
    } else {
        format!("{p:.2e}%")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorball_core::ProjectionKind;

    #[test]
    fn the_line_counts_the_clipped_texels_and_gives_the_advice() {
        let cube = ProjectionKind::Cube.default_projection();
        let mut env = EnvMap::from_fn(cube, 4, 3, |_| [1.0, 1.0, 1.0, 1.0]);
        env.layers_mut()[0].set(1, 1, &[1e6, 2.0, 2.0]);
        let half = Storage::Texels(Encoding::Rgba16F);
        let (maps, r) = measure_maps(std::slice::from_ref(&env), half, false);
        assert!(matches!(maps, Cow::Borrowed(_)));
        let keep = [
            precision_advice(half).unwrap(),
            exposure_advice("--exposure", 0.0, &r),
        ];
        let line = r.line("x.exr", &keep).unwrap();
        assert!(
            line.starts_with("warning: x.exr: 1 texel past half's largest value 65504, written as it (the largest 1000000): "),
            "{line}"
        );
        assert!(line.contains("of the map's energy lost"), "{line}");
        assert!(
            line.ends_with("to keep it: --precision float, or --exposure -4"),
            "{line}"
        );
        // Display codes: no line. Float: none either.
        for s in [Storage::Display8, Storage::Texels(Encoding::Rgba32F)] {
            let (_, r) = measure_maps(std::slice::from_ref(&env), s, false);
            assert_eq!(r.line("x", &keep), None, "{s:?}");
        }
    }

    #[test]
    fn nan_made_by_the_work_is_replaced_unless_kept() {
        let cube = ProjectionKind::Cube.default_projection();
        let mut env = EnvMap::from_fn(cube, 4, 3, |_| [1.0, 1.0, 1.0, 1.0]);
        env.layers_mut()[3].set(0, 0, &[f32::NAN, f32::INFINITY, 1.0]);
        let float = Storage::Texels(Encoding::Rgba32F);
        let (maps, r) = measure_maps(std::slice::from_ref(&env), float, false);
        assert_eq!(r.replaced, 2);
        assert_eq!(maps[0].layers()[3].get(0, 0), &[0.0, 0.0, 1.0]);
        assert!(r
            .line("x", &[])
            .unwrap()
            .contains("2 NaN or infinite value(s)"));
        let (maps, r) = measure_maps(std::slice::from_ref(&env), float, true);
        assert!(matches!(maps, Cow::Borrowed(_)));
        assert_eq!(r.line("x", &[]), None);
    }
}
