//! A rig: the pinhole views cut from each panorama. Named presets in one table
//! ([`PRESETS`]: `--rig`'s help and its checks read it), or a JSON file of views.
//!
//! Angles are degrees and aim a view as `convert --to perspective` does
//! (`mirrorball_core::View::frame_of`): yaw to the right, pitch up, roll about the view axis.

use super::cameras::Model;
use crate::error::Error;
use serde::Deserialize;
use std::collections::HashSet;
use std::path::Path;

/// One view of a rig: where it looks, how wide, and (optionally) its picture's size.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewSpec {
    /// The view's name: its images' folder (`images/NAME/`) and its camera's prefix.
    pub name: String,
    /// Degrees to the right.
    pub yaw: f64,
    /// Degrees up.
    pub pitch: f64,
    /// Degrees about the view axis.
    pub roll: f64,
    /// How it draws: a pinhole, or an equidistant fisheye (square, its disk the picture's
    /// inscribed circle, `fov` across).
    pub model: Model,
    /// The horizontal field of view, degrees, in `(0, 180)` (a fisheye's disk's).
    pub fov: f64,
    /// The vertical field of view, degrees; `None`: from the picture's shape (square
    /// pixels), a square picture when its height is not given either.
    pub vfov: Option<f64>,
    /// The picture's width; `None`: `--size`'s, else from the panorama's resolution.
    pub width: Option<i64>,
    /// The picture's height; `None`: from the fields of view (square pixels).
    pub height: Option<i64>,
}

impl ViewSpec {
    fn aimed(name: impl Into<String>, yaw: f64, pitch: f64, fov: f64) -> ViewSpec {
        ViewSpec {
            name: name.into(),
            yaw,
            pitch,
            roll: 0.0,
            model: Model::Pinhole,
            fov,
            vfov: None,
            width: None,
            height: None,
        }
    }
}

/// A named rig: `name` as `--rig` takes it (`N` stands for a count in [`Preset::counts`]).
pub struct Preset {
    /// The name; a trailing `N` takes a count (`ring8`).
    pub name: &'static str,
    /// One line for `--rig`'s help.
    pub about: &'static str,
    /// The counts `N` may take (none for a plain name).
    pub counts: Option<(u32, u32)>,
    views: fn(u32) -> Vec<ViewSpec>,
}

/// Every named rig.
pub const PRESETS: &[Preset] = &[
    Preset {
        name: "cube",
        about: "six 90° faces: front right back left up down (no overlap)",
        counts: None,
        views: |_| cube(90.0),
    },
    Preset {
        name: "cube-96",
        about: "the cube's six faces 96° wide, 3° of overlap past each edge",
        counts: None,
        views: |_| cube(96.0),
    },
    Preset {
        name: "ringN",
        about: "N views (3 to 36) around the horizon at pitch 0, yaw 0, 360/N, …, each \
                1.25·360/N° wide (at least 30°) and 100° high, plus up and down (100°)",
        counts: Some((3, 36)),
        views: ring,
    },
];

/// The six faces of a cube, `fov` wide.
fn cube(fov: f64) -> Vec<ViewSpec> {
    vec![
        ViewSpec::aimed("front", 0.0, 0.0, fov),
        ViewSpec::aimed("right", 90.0, 0.0, fov),
        ViewSpec::aimed("back", 180.0, 0.0, fov),
        ViewSpec::aimed("left", 270.0, 0.0, fov),
        ViewSpec::aimed("up", 0.0, 90.0, fov),
        ViewSpec::aimed("down", 0.0, -90.0, fov),
    ]
}

/// `n` views round the horizon (named by their yaw, `yaw045`), then up and down.
fn ring(n: u32) -> Vec<ViewSpec> {
    let step = 360.0 / n as f64;
    let fov = (1.25 * step).clamp(30.0, 170.0);
    let mut views: Vec<ViewSpec> = (0..n)
        .map(|i| {
            let yaw = step * i as f64;
            let mut v = ViewSpec::aimed(format!("yaw{:03}", yaw.round() as u32), yaw, 0.0, fov);
            v.vfov = Some(100.0);
            v
        })
        .collect();
    views.push(ViewSpec::aimed("up", 0.0, 90.0, 100.0));
    views.push(ViewSpec::aimed("down", 0.0, -90.0, 100.0));
    views
}

/// `--rig`'s help: each preset on a line.
pub fn help() -> String {
    let s = String::from(
        "The rig: a name below, or a JSON file of views \
         ({\"views\": [{\"name\", \"yaw\", \"pitch\", \"roll\", \"fov\", \"vfov\", \"width\", \"height\", \
         \"model\"}]}; name and fov required, angles in degrees; model pinhole, or fisheye: \
         equidistant, square, OPENCV_FISHEYE for COLMAP and nerfstudio).\nNames:\n",
    );
    let lines: Vec<String> = PRESETS
        .iter()
        .map(|p| format!("  {:<8} {}", p.name, p.about))
        .collect();
    s + &lines.join("\n")
}

/// The views of the preset `name` (`ring8`), or `None` when no preset has that name.
pub fn preset(name: &str) -> Result<Option<Vec<ViewSpec>>, Error> {
    let lower = name.to_ascii_lowercase();
    for p in PRESETS {
        match p.counts {
            None if p.name == lower => return Ok(Some((p.views)(0))),
            None => {}
            Some((lo, hi)) => {
                let stem = p.name.trim_end_matches('N');
                let Some(n) = lower.strip_prefix(stem) else {
                    continue;
                };
                if n.is_empty() || !n.bytes().all(|b| b.is_ascii_digit()) {
                    continue;
                }
                return match n.parse::<u32>() {
                    Ok(n) if (lo..=hi).contains(&n) => Ok(Some((p.views)(n))),
                    _ => Err(Error::request(format!(
                        "--rig {name}: {stem}N takes N from {lo} to {hi}"
                    ))),
                };
            }
        }
    }
    Ok(None)
}

/// The names `--rig` takes, for messages.
fn names() -> String {
    PRESETS
        .iter()
        .map(|p| p.name)
        .collect::<Vec<_>>()
        .join(", ")
}

/// A rig file's contents.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RigFile {
    views: Vec<ViewEntry>,
}

/// One view of a rig file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ViewEntry {
    name: String,
    #[serde(default)]
    yaw: f64,
    #[serde(default)]
    pitch: f64,
    #[serde(default)]
    roll: f64,
    #[serde(default)]
    model: ModelName,
    fov: f64,
    vfov: Option<f64>,
    width: Option<i64>,
    height: Option<i64>,
}

/// A rig file's camera model.
#[derive(Deserialize, Default, Clone, Copy)]
#[serde(rename_all = "lowercase")]
enum ModelName {
    #[default]
    Pinhole,
    Fisheye,
}

/// The rig `--rig` names: a preset, else a JSON file (`.json`).
pub fn resolve(rig: &str) -> Result<Vec<ViewSpec>, Error> {
    if let Some(views) = preset(rig)? {
        return Ok(views);
    }
    let path = Path::new(rig);
    let is_json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    if !is_json {
        return Err(Error::request(format!(
            "--rig {rig}: not a rig's name ({}) nor a .json file of views",
            names()
        )));
    }
    let text = std::fs::read_to_string(path).map_err(|e| {
        let fault = match e.kind() {
            std::io::ErrorKind::NotFound => mirrorball_core::Fault::Request,
            _ => mirrorball_core::Fault::System,
        };
        Error::new(fault, format!("--rig {rig}: {e}"))
    })?;
    let file: RigFile =
        serde_json::from_str(&text).map_err(|e| Error::input(format!("--rig {rig}: {e}")))?;
    let views: Vec<ViewSpec> = file
        .views
        .into_iter()
        .map(|v| ViewSpec {
            name: v.name,
            yaw: v.yaw,
            pitch: v.pitch,
            roll: v.roll,
            model: match v.model {
                ModelName::Pinhole => Model::Pinhole,
                ModelName::Fisheye => Model::Fisheye,
            },
            fov: v.fov,
            vfov: v.vfov,
            width: v.width,
            height: v.height,
        })
        .collect();
    check_names(&views).map_err(|e| Error::input(format!("--rig {rig}: {}", e.message)))?;
    Ok(views)
}

/// Refuses a rig without views, a name that is no plain folder name, or a name twice.
pub fn check_names(views: &[ViewSpec]) -> Result<(), Error> {
    if views.is_empty() {
        return Err(Error::request("the rig has no views"));
    }
    let mut seen = HashSet::new();
    for v in views {
        let plain = !v.name.is_empty()
            && v.name.len() <= 64
            && v.name != "."
            && v.name != ".."
            && v.name
                .bytes()
                .all(|b| b.is_ascii_alphanumeric() || matches!(b, b'-' | b'_' | b'.'));
        if !plain {
            return Err(Error::request(format!(
                "view name '{}': a view's name is its images' folder: 1 to 64 of A-Z a-z 0-9 - _ .",
                v.name
            )));
        }
        if !seen.insert(v.name.to_ascii_lowercase()) {
            return Err(Error::request(format!(
                "view name '{}' is given twice (names are folders, compared ignoring case)",
                v.name
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_resolve_by_the_table() {
        assert_eq!(resolve("cube").unwrap().len(), 6);
        assert_eq!(resolve("CUBE-96").unwrap()[0].fov, 96.0);
        let r = resolve("ring8").unwrap();
        assert_eq!(r.len(), 10);
        assert_eq!(r[1].name, "yaw045");
        assert!((r[1].yaw - 45.0).abs() < 1e-12);
        assert!(resolve("ring2").unwrap_err().message.contains("3 to 36"));
        assert!(resolve("ring99").is_err());
        assert!(resolve("sphere")
            .unwrap_err()
            .message
            .contains("cube, cube-96, ringN"));
        for p in PRESETS {
            assert!(help().contains(p.name));
            let name = p
                .name
                .replace('N', &p.counts.map_or(0, |c| c.0).to_string());
            check_names(&resolve(&name).unwrap()).unwrap();
        }
    }

    #[test]
    fn names_are_folders_and_unique() {
        let v = |n: &str| ViewSpec::aimed(n, 0.0, 0.0, 90.0);
        assert!(check_names(&[v("a"), v("A")]).is_err());
        assert!(check_names(&[v("a/b")]).is_err());
        assert!(check_names(&[v("..")]).is_err());
        assert!(check_names(&[]).is_err());
        check_names(&[v("front"), v("yaw-045_x")]).unwrap();
    }
}
