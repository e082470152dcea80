//! The spherical-harmonic side files mirrorball writes beside a map: the SH JSON of
//! `prefilter` and `bake --for ktx2` (`radiance`, `irradiance_over_pi`: nine RGB
//! coefficients each, band 0 to 2) and Filament's `sh.txt` (nine lines `( r, g, b); //
//! L00 …` as cmgen writes it, its pre-scaled irradiance; or plain `r g b` lines). Read back for `info`: what such a
//! file holds is a function on the whole sphere in the SH basis, not a picture.

use crate::Error;
use serde_json::{json, Value};
use std::path::Path;

/// What an SH side file holds.
#[derive(Clone, Debug, PartialEq)]
pub struct ShFile {
    /// The container, for people.
    pub description: String,
    /// What the coefficients are of (`radiance`, `irradiance / π`, …), with them: nine
    /// `[r, g, b]` each, band 0 first.
    pub sets: Vec<(String, Vec<[f64; 3]>)>,
    /// The projection of the map the file was made beside, when it records one.
    pub beside: Option<String>,
}

/// The name `info` gives the "projection" of an SH file: the basis itself.
pub const SH_PROJECTION: &str = "sh9";

/// Nine `[r, g, b]` from a JSON array, or why not.
fn nine(v: &Value) -> Option<Vec<[f64; 3]>> {
    let a = v.as_array().filter(|a| a.len() == 9)?;
    a.iter()
        .map(|c| {
            let c = c.as_array().filter(|c| c.len() == 3)?;
            let x: Option<Vec<f64>> = c.iter().map(Value::as_f64).collect();
            x.map(|x| [x[0], x[1], x[2]])
        })
        .collect()
}

/// Reads `path` as an SH side file when its name says it is one (`.json`, `.txt`): `None`
/// for other names; an error when such a file does not hold nine RGB coefficients.
pub fn read_sh(path: &Path) -> Result<Option<ShFile>, Error> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let json = match ext.as_deref() {
        Some("json") => true,
        Some("txt") => false,
        _ => return Ok(None),
    };
    Error::check_input(path)?;
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let bad = |p: String| Error::input(path, p);
    if json {
        let doc: Value = serde_json::from_str(&text).map_err(|e| bad(format!("JSON: {e}")))?;
        let mut sets = Vec::new();
        for (key, what) in [
            ("radiance", "radiance"),
            ("irradiance_over_pi", "irradiance / pi"),
        ] {
            if let Some(c) = nine(&doc[key]) {
                sets.push((what.to_string(), c));
            }
        }
        if sets.is_empty() {
            return Err(bad(
                "no 'radiance' or 'irradiance_over_pi' of nine RGB coefficients: not \
                 mirrorball's SH JSON"
                    .into(),
            ));
        }
        return Ok(Some(ShFile {
            description: "spherical-harmonic coefficients (mirrorball's SH JSON)".into(),
            sets,
            beside: doc["projection"].as_str().map(str::to_string),
        }));
    }
    // cmgen's lines: `( r,  g,  b); // L00, irradiance, pre-scaled base`.
    let rows: Option<Vec<[f64; 3]>> = text
        .lines()
        .map(|l| l.split("//").next().unwrap_or_default())
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let x: Option<Vec<f64>> = l
                .split(|c: char| c.is_whitespace() || "(),;".contains(c))
                .filter(|w| !w.is_empty())
                .map(|w| w.parse().ok())
                .collect();
            x.filter(|x| x.len() == 3).map(|x| [x[0], x[1], x[2]])
        })
        .collect();
    match rows.filter(|r| r.len() == 9) {
        Some(c) => Ok(Some(ShFile {
            description: "spherical-harmonic coefficients (Filament's sh.txt, cmgen's \
                          pre-scaled irradiance)"
                .into(),
            sets: vec![("pre-scaled irradiance".into(), c)],
            beside: None,
        })),
        None => Err(bad(
            "not nine lines of three numbers: not an SH text file (Filament's sh.txt)".into(),
        )),
    }
}

impl ShFile {
    /// `info`'s lines for the file `file`.
    pub fn info_text(&self, file: &str) -> String {
        let mut s = format!(
            "file:        {file}\ncontainer:   {}\nprojection:  {SH_PROJECTION} (spherical harmonics, bands 0 to 2, of the whole sphere{})\n",
            self.description,
            self.beside
                .as_deref()
                .map_or(String::new(), |p| format!("; made beside a {p} map"))
        );
        for (what, c) in &self.sets {
            s += &format!(
                "{what:<12} DC {:.6e} {:.6e} {:.6e}\n",
                c[0][0], c[0][1], c[0][2]
            );
        }
        s
    }

    /// `info --json`'s document for the file `file`.
    pub fn info_json(&self, file: &str) -> Value {
        let sets: serde_json::Map<String, Value> = self
            .sets
            .iter()
            .map(|(k, c)| (k.clone(), json!(c)))
            .collect();
        json!({
            "file": file,
            "container": self.description,
            "projection": SH_PROJECTION,
            "beside": self.beside,
            "coefficients": sets,
        })
    }
}
