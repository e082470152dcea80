//! FFmpeg `v360`'s option string (`libavfilter/vf_v360.c`, FFmpeg 5.1) as a conversion
//! request: [`parse`] reads `IN:OUT[:key=value…]` exactly as the filter does (its options
//! in its order may be given without their keys, up to the first `key=value`), and
//! [`ConvertRequest::with_v360`] puts what it says into a request, refusing the flags that
//! would say it again.
//!
//! What each option means here:
//! - projections: one table, [`PROJECTIONS`]; a v360 projection mirrorball has no exact
//!   counterpart of is refused by name;
//! - `yaw`, `pitch`, `roll`, `rorder`, `h_flip`, `v_flip`, `d_flip`: v360 turns each
//!   output direction by the quaternion `I·m[o₀]·m[o₁]·m[o₂]` (`calculate_rotation`: `m`
//!   about its y for yaw, x for pitch, z for roll, in `rorder`'s order) and then mirrors
//!   its components (`mirror`). v360's `(x, y, z)` is mirrorball's `(x, −y, −z)`, so in
//!   mirrorball's axes the source direction of output direction `d` is
//!   `M·A₀·A₁·A₂·d` with `A_yaw = R_y(−yaw)`, `A_pitch = R_x(pitch)`, `A_roll = R_z(−roll)`
//!   and `M` the mirrors (a [`Rotation`] given whole to the request);
//! - `w`, `h`: the output picture (one eye's), which must be the picture mirrorball makes
//!   of the projection at that size (square texels for views; `3n×2n` for `c3x2`, …);
//!   without them the size is mirrorball's (`--size`, or about the source's resolution),
//!   not v360's;
//! - `h_fov`/`v_fov` (`ih_fov`/`iv_fov`): the projections' own fields of view, as
//!   [`Proj::spec`] says per projection; `d_fov` only for a flat output with `w` and `h`;
//! - `in_forder`, `out_forder`, `in_frot`, `out_frot`: the cube cells' order and turns
//!   (core's `CubeCells`); `in_pad`/`out_pad`/`fin_pad`/`fout_pad`: 0 only;
//! - `in_stereo`, `out_stereo`: core's `Stereo`, v360's rule;
//! - `interp`: every method accepted, with a note: mirrorball integrates each output texel
//!   over its footprint (antialiased) whichever v360 names;
//! - refused unless left at their defaults: `ih_flip`, `iv_flip`, `in_trans`, `out_trans`,
//!   `h_offset`, `v_offset`, `alpha_mask`.

use crate::convert::ConvertRequest;
use crate::error::Error;
use crate::spec::ProjSpec;
use mirrorball_core::glam::{DMat3, DVec3};
use mirrorball_core::{CubeCells, Layout, ProjectionKind, Rotation, Stereo, WorldProjection};
use std::fmt;

/// Why a v360 option string cannot be taken: each names the key (or the projection) at
/// fault.
#[derive(Clone, Debug, PartialEq)]
pub enum V360Error {
    /// A key v360 does not have.
    UnknownKey(String),
    /// A value v360 would refuse: unreadable, or out of its range.
    BadValue {
        /// The key.
        key: String,
        /// The value given.
        value: String,
        /// What the key takes.
        takes: String,
    },
    /// A value without a key after a `key=value`, or more values than v360 has options.
    Positional(String),
    /// A key given twice.
    Repeated(String),
    /// What v360 means by a key or projection, mirrorball cannot make exactly.
    Unsupported {
        /// The key (for a projection, `input` or `output`).
        key: String,
        /// The value given.
        value: String,
        /// Why, and what to give instead.
        why: String,
    },
}

impl V360Error {
    /// The key at fault.
    pub fn key(&self) -> &str {
        match self {
            V360Error::UnknownKey(k) | V360Error::Positional(k) | V360Error::Repeated(k) => k,
            V360Error::BadValue { key, .. } | V360Error::Unsupported { key, .. } => key,
        }
    }
}

impl fmt::Display for V360Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            V360Error::UnknownKey(k) => write!(f, "unknown key '{k}' (v360 has no such option)"),
            V360Error::BadValue { key, value, takes } => {
                write!(f, "{key}={value}: {key} takes {takes}")
            }
            V360Error::Positional(v) => write!(
                f,
                "'{v}': a value without a key (only v360's options in its order, before any \
                 key=value, may leave their keys out)"
            ),
            V360Error::Repeated(k) => write!(f, "{k} is given twice"),
            V360Error::Unsupported { key, value, why } => write!(f, "{key}={value}: {why}"),
        }
    }
}

impl std::error::Error for V360Error {}

impl From<V360Error> for Error {
    fn from(e: V360Error) -> Error {
        Error::request(format!("--v360: {e}"))
    }
}

/// v360's options in its order (`v360_options`), the order values without keys take.
const KEYS: &[&str] = &[
    "input",
    "output",
    "interp",
    "w",
    "h",
    "in_stereo",
    "out_stereo",
    "in_forder",
    "out_forder",
    "in_frot",
    "out_frot",
    "in_pad",
    "out_pad",
    "fin_pad",
    "fout_pad",
    "yaw",
    "pitch",
    "roll",
    "rorder",
    "h_fov",
    "v_fov",
    "d_fov",
    "h_flip",
    "v_flip",
    "d_flip",
    "ih_flip",
    "iv_flip",
    "in_trans",
    "out_trans",
    "ih_fov",
    "iv_fov",
    "id_fov",
    "h_offset",
    "v_offset",
    "alpha_mask",
    "reset_rot",
];

/// v360's interpolation names (`interp`).
const INTERP: &[&str] = &[
    "near",
    "nearest",
    "line",
    "linear",
    "lagrange9",
    "cube",
    "cubic",
    "lanc",
    "lanczos",
    "sp16",
    "spline16",
    "gauss",
    "gaussian",
    "mitchell",
];

/// A v360 projection.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Proj {
    /// `e`: mirrorball's `latlong`.
    Equirect,
    /// `c3x2`, `c6x1`, `c1x6`: a `cube` in v360's cells.
    Cells(&'static str),
    /// `eac`: `eac` in v360's padded layout.
    Eac,
    /// `flat`: `perspective` with `hfov`, `vfov`.
    Flat,
    /// `dfisheye`: `dfisheye:fov=F` (equal `h_fov` and `v_fov`).
    DualFisheye,
    /// `fisheye`, `sg`, `equisolid`, `og`: `fisheye:fov=F` with that lens.
    Fisheye(&'static str),
    /// `hequirect`: `half-equirect`.
    HalfEquirect,
    /// `cylindrical`: `cylindrical:hfov:vfov`.
    Cylindrical,
    /// `cylindricalea`: `cylindrical-equal-area`, whose `v_fov` is `180·sin(vfov/2)`.
    CylindricalEa,
    /// `hammer`.
    Hammer,
    /// `sinusoidal`.
    Sinusoidal,
    /// `pannini`: `pannini:d=D` where `h_fov` is D, drawn over `X, Y ∈ [−1, 1]`.
    Pannini,
    /// `tetrahedron`.
    Tetrahedron,
    /// A v360 projection mirrorball does not make: why.
    Refused(&'static str),
}

/// Every v360 projection name (FFmpeg 5.1's `input`/`output` constants) and what it is
/// here: the one table of them.
pub const PROJECTIONS: &[(&[&str], Proj)] = &[
    (&["e", "equirect"], Proj::Equirect),
    (&["c3x2"], Proj::Cells("c3x2")),
    (&["c6x1"], Proj::Cells("c6x1")),
    (&["c1x6"], Proj::Cells("c1x6")),
    (&["eac"], Proj::Eac),
    (&["flat", "rectilinear", "gnomonic"], Proj::Flat),
    (&["dfisheye"], Proj::DualFisheye),
    (&["fisheye"], Proj::Fisheye("equidistant")),
    (&["sg"], Proj::Fisheye("stereographic")),
    (&["equisolid"], Proj::Fisheye("equisolid")),
    (&["og"], Proj::Fisheye("orthographic")),
    (&["hequirect", "he"], Proj::HalfEquirect),
    (&["cylindrical"], Proj::Cylindrical),
    (&["cylindricalea"], Proj::CylindricalEa),
    (&["hammer"], Proj::Hammer),
    (&["sinusoidal"], Proj::Sinusoidal),
    (&["pannini"], Proj::Pannini),
    (
        &["barrel", "fb", "barrelsplit"],
        Proj::Refused("Facebook's barrel layouts are not among mirrorball's projections"),
    ),
    (&["tetrahedron"], Proj::Tetrahedron),
    (
        &["tsp"],
        Proj::Refused("the truncated square pyramid is not among mirrorball's projections"),
    ),
    (
        &["ball"],
        Proj::Refused(
            "v360's ball is not compared with mirrorball's sphere map yet; give --from/--to sphere",
        ),
    ),
    (
        &["mercator"],
        Proj::Refused(
            "v360's mercator is not compared with mirrorball's yet; give --from/--to mercator",
        ),
    ),
    (
        &["octahedron"],
        Proj::Refused(
            "v360's octahedron is centred on the view, mirrorball's octahedral on +Y: not the same picture",
        ),
    ),
    (
        &["perspective"],
        Proj::Refused("v360's perspective (an output only) is not mirrorball's; flat is"),
    ),
];

/// The projection v360 calls `name`.
fn projection(key: &str, name: &str) -> Result<Proj, V360Error> {
    PROJECTIONS
        .iter()
        .find(|(names, _)| names.contains(&name))
        .map(|&(_, p)| p)
        .ok_or_else(|| V360Error::BadValue {
            key: key.to_string(),
            value: name.to_string(),
            takes: format!(
                "a v360 projection ({})",
                PROJECTIONS
                    .iter()
                    .flat_map(|(n, _)| n.iter().copied())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        })
}

/// One side's fields of view as given (`h_fov`, `v_fov`, `d_fov` or the input's).
#[derive(Clone, Copy, Debug, Default)]
struct Fov {
    h: Option<f64>,
    v: Option<f64>,
    d: Option<f64>,
}

/// The key names of one side's fields of view: output or input.
struct FovKeys {
    h: &'static str,
    v: &'static str,
    d: &'static str,
}

const OUT_FOV: FovKeys = FovKeys {
    h: "h_fov",
    v: "v_fov",
    d: "d_fov",
};
const IN_FOV: FovKeys = FovKeys {
    h: "ih_fov",
    v: "iv_fov",
    d: "id_fov",
};

impl Proj {
    /// The mirrorball projection and layout of this v360 projection with fields of view
    /// `fov` (keys `keys`), named by `key` (`input`/`output`) as `name`.
    fn spec(
        self,
        key: &str,
        name: &str,
        fov: Fov,
        keys: &FovKeys,
    ) -> Result<(String, Option<Layout>), V360Error> {
        let unsupported = |k: &str, v: String, why: String| V360Error::Unsupported {
            key: k.to_string(),
            value: v,
            why,
        };
        if let Some(d) = fov.d {
            return Err(unsupported(
                keys.d,
                num(d),
                format!(
                    "a diagonal field of view is taken for a flat output with w and h only; give \
                     {} and {}",
                    keys.h, keys.v
                ),
            ));
        }
        // Both fields of view, which v360's defaults would otherwise fill (they differ
        // between its versions).
        let both = || match (fov.h, fov.v) {
            (Some(h), Some(v)) => Ok((h, v)),
            _ => Err(unsupported(
                key,
                name.to_string(),
                format!(
                    "give {} and {} (v360's defaults differ between its versions)",
                    keys.h, keys.v
                ),
            )),
        };
        // One field of view for both axes: mirrorball's lenses are circles.
        let circle = || {
            let (h, v) = both()?;
            if h != v {
                return Err(unsupported(
                    keys.v,
                    num(v),
                    format!(
                        "{name}'s circle is as wide as it is high here: give {}={} too",
                        keys.v,
                        num(h)
                    ),
                ));
            }
            Ok(h)
        };
        let plain = |s: &str| Ok((s.to_string(), None));
        match self {
            Proj::Equirect => plain("latlong"),
            Proj::HalfEquirect => plain("half-equirect"),
            Proj::Hammer => plain("hammer"),
            Proj::Sinusoidal => plain("sinusoidal"),
            Proj::Tetrahedron => plain("tetrahedron"),
            Proj::Cells(grid) => Ok(("cube".into(), Some(grid.parse().expect("a grid")))),
            Proj::Eac => Ok(("eac".into(), Some(Layout::eac()))),
            Proj::Flat => {
                let (h, v) = both()?;
                Ok((format!("perspective:hfov={}:vfov={}", num(h), num(v)), None))
            }
            Proj::Cylindrical => {
                let (h, v) = both()?;
                Ok((format!("cylindrical:hfov={}:vfov={}", num(h), num(v)), None))
            }
            Proj::CylindricalEa => {
                let (h, v) = both()?;
                if v > 180.0 {
                    return Err(unsupported(
                        keys.v,
                        num(v),
                        "cylindricalea's v_fov is 180·sin(vfov/2): at most 180".into(),
                    ));
                }
                let vfov = 2.0 * (v / 180.0).asin().to_degrees();
                Ok((
                    format!("cylindrical-equal-area:hfov={}:vfov={}", num(h), num(vfov)),
                    None,
                ))
            }
            Proj::DualFisheye => Ok((format!("dfisheye:fov={}", num(circle()?)), None)),
            Proj::Fisheye(lens) => {
                Ok((format!("fisheye:fov={}:lens={lens}", num(circle()?)), None))
            }
            Proj::Pannini => {
                // v360 takes d from h_fov and draws X, Y ∈ [−1, 1]: X = 1 where
                // (d + 1) sin λ = d + cos λ, i.e. λ = asin(d/R) + atan2(1, d + 1) with
                // R = √((d + 1)² + 1); Y = tan θ on the centre column: 90° high.
                let d = fov.h.unwrap_or(0.0);
                let r = ((d + 1.0) * (d + 1.0) + 1.0).sqrt();
                let lambda = (d / r).asin() + 1.0f64.atan2(d + 1.0);
                Ok((
                    format!(
                        "pannini:d={}:hfov={}:vfov=90",
                        num(d),
                        num(2.0 * lambda.to_degrees())
                    ),
                    None,
                ))
            }
            Proj::Refused(why) => Err(unsupported(key, name.to_string(), why.to_string())),
        }
    }
}

/// A number as projection text takes it.
fn num(v: f64) -> String {
    format!("{v}")
}

/// What a v360 option string asks, as mirrorball's settings: [`parse`] makes it,
/// [`ConvertRequest::with_v360`] applies it.
#[derive(Clone, Debug)]
pub struct V360 {
    /// The input's projection.
    pub from: ProjSpec,
    /// The input's layout (v360's cells), if it has layers.
    pub in_layout: Option<Layout>,
    /// The output's projection.
    pub to: ProjSpec,
    /// The output's layout (v360's cells), if it has layers.
    pub layout: Option<Layout>,
    /// The output's size as `--size` takes it (a face's edge, a width), from `w` and `h`.
    pub size: Option<i64>,
    /// `in_stereo`.
    pub in_stereo: Stereo,
    /// `out_stereo`.
    pub out_stereo: Stereo,
    /// The turn and mirrors, as the source direction of each output direction.
    pub rotation: Rotation,
    /// What people should know: options accepted that change nothing here.
    pub notes: Vec<String>,
}

/// `v`, the value of `key`, as a number within `lo..=hi`.
fn number(key: &str, v: &str, lo: f64, hi: f64) -> Result<f64, V360Error> {
    v.trim()
        .parse::<f64>()
        .ok()
        .filter(|x| x.is_finite() && (lo..=hi).contains(x))
        .ok_or_else(|| V360Error::BadValue {
            key: key.into(),
            value: v.into(),
            takes: format!("a number from {lo} to {hi}"),
        })
}

/// `v`, the value of `key`, as v360's booleans (`av_opt`'s words or a number).
fn boolean(key: &str, v: &str) -> Result<bool, V360Error> {
    match v.trim().to_ascii_lowercase().as_str() {
        "1" | "true" | "y" | "yes" | "on" | "enable" => Ok(true),
        "0" | "false" | "n" | "no" | "off" | "disable" => Ok(false),
        _ => Err(V360Error::BadValue {
            key: key.into(),
            value: v.into(),
            takes: "a boolean (0 or 1, true or false)".into(),
        }),
    }
}

/// Reads a v360 option string: `IN:OUT[:key=value…]` (a leading `v360=` is allowed), the
/// options v360 has (FFmpeg 5.1) meaning what they mean there; see the module's
/// documentation for each, and [`V360Error`] for what is refused.
pub fn parse(text: &str) -> Result<V360, V360Error> {
    let text = text.trim();
    let text = text.strip_prefix("v360=").unwrap_or(text);
    let mut given: Vec<(&'static str, String)> = Vec::new();
    let mut named = false;
    for (i, part) in text.split(':').enumerate() {
        let (key, value) = match part.split_once('=') {
            Some((k, v)) => {
                named = true;
                let k = k.trim();
                let key = KEYS
                    .iter()
                    .find(|&&known| known == k)
                    .ok_or_else(|| V360Error::UnknownKey(k.to_string()))?;
                (*key, v.to_string())
            }
            None if named || i >= KEYS.len() => {
                return Err(V360Error::Positional(part.to_string()))
            }
            None => (KEYS[i], part.to_string()),
        };
        if given.iter().any(|(k, _)| *k == key) {
            return Err(V360Error::Repeated(key.into()));
        }
        given.push((key, value));
    }
    let get = |k: &str| given.iter().find(|(g, _)| *g == k).map(|(_, v)| v.as_str());
    let num_of = |k: &str, lo, hi| get(k).map(|v| number(k, v, lo, hi)).transpose();
    let flag = |k: &str| {
        get(k)
            .map(|v| boolean(k, v))
            .transpose()
            .map(|b| b == Some(true))
    };
    let unsupported = |k: &str, why: &str| V360Error::Unsupported {
        key: k.into(),
        value: get(k).unwrap_or_default().into(),
        why: why.into(),
    };

    let mut notes = Vec::new();
    if let Some(i) = get("interp") {
        if !INTERP.contains(&i.trim()) {
            return Err(V360Error::BadValue {
                key: "interp".into(),
                value: i.into(),
                takes: format!("one of {}", INTERP.join(", ")),
            });
        }
        notes.push(format!(
            "--v360 interp={i}: mirrorball integrates each output texel over its footprint \
             (antialiased) whichever interpolation v360 names"
        ));
    }
    if flag("reset_rot")? {
        notes.push(
            "--v360 reset_rot=1: changes nothing in one conversion (v360 resets its rotation \
             between commands)"
                .into(),
        );
    }
    for (k, why) in [
        (
            "ih_flip",
            "mirrorball does not flip the input picture; h_flip mirrors the directions",
        ),
        (
            "iv_flip",
            "mirrorball does not flip the input picture; v_flip mirrors the directions",
        ),
        ("in_trans", "mirrorball does not transpose the input picture"),
        ("out_trans", "mirrorball does not transpose the output picture"),
        (
            "alpha_mask",
            "mirrorball writes no mask of this kind; --outside black leaves zero alpha where the output holds alpha",
        ),
    ] {
        if flag(k)? {
            return Err(unsupported(k, why));
        }
    }
    for k in ["h_offset", "v_offset"] {
        if num_of(k, -1.0, 1.0)?.is_some_and(|v| v != 0.0) {
            return Err(unsupported(
                k,
                "mirrorball's views are not shifted off their axis",
            ));
        }
    }
    for (k, hi) in [
        ("in_pad", 0.1),
        ("out_pad", 0.1),
        ("fin_pad", 100.0),
        ("fout_pad", 100.0),
    ] {
        if num_of(k, 0.0, hi)?.is_some_and(|v| v != 0.0) {
            return Err(unsupported(
                k,
                "mirrorball's cube cells have no padding (eac's own two texels aside)",
            ));
        }
    }

    // Projections and their fields of view (0, v360's default, is none given).
    let fov = |keys: &FovKeys| -> Result<Fov, V360Error> {
        let given = |k| Ok::<_, V360Error>(num_of(k, 0.0, 360.0)?.filter(|&v| v > 0.0));
        Ok(Fov {
            h: given(keys.h)?,
            v: given(keys.v)?,
            d: given(keys.d)?,
        })
    };
    let (in_name, out_name) = (
        get("input").unwrap_or("e").trim(),
        get("output").unwrap_or("c3x2").trim(),
    );
    let (pin, pout) = (
        projection("input", in_name)?,
        projection("output", out_name)?,
    );
    let (w, h) = (num_of("w", 0.0, 32767.0)?, num_of("h", 0.0, 32767.0)?);
    for (k, v) in [("w", w), ("h", h)] {
        if v.is_some_and(|v| v.fract() != 0.0) {
            return Err(V360Error::BadValue {
                key: k.into(),
                value: get(k).unwrap_or_default().into(),
                takes: "a whole number from 0 to 32767".into(),
            });
        }
    }
    // v360 takes 0 as "not given".
    let extent = match (w.filter(|&w| w > 0.0), h.filter(|&h| h > 0.0)) {
        (Some(w), Some(h)) => Some((w as u32, h as u32)),
        (None, None) => None,
        (w, _) => {
            let k = if w.is_some() { "h" } else { "w" };
            return Err(V360Error::BadValue {
                key: k.into(),
                value: get(k).unwrap_or("0").into(),
                takes: "a size with the other (v360 wants both w and h)".into(),
            });
        }
    };
    let mut out_fov = fov(&OUT_FOV)?;
    if let (Some(d), Proj::Flat, Some((w, h))) = (out_fov.d, pout, extent) {
        // v360's fov_from_dfov for flat views.
        let (w, h) = (w as f64, h as f64);
        let da = (0.5 * d.min(359.0)).to_radians().tan();
        let diag = w.hypot(h);
        out_fov = Fov {
            h: Some(2.0 * (da * w).atan2(diag).to_degrees()),
            v: Some(2.0 * (da * h).atan2(diag).to_degrees()),
            d: None,
        };
    }
    let (from, in_layout) = pin.spec("input", in_name, fov(&IN_FOV)?, &IN_FOV)?;
    let (to, layout) = pout.spec("output", out_name, out_fov, &OUT_FOV)?;

    let in_layout = cell_order(&get, "in", pin).map(|l| l.or(in_layout))?;
    let layout = cell_order(&get, "out", pout).map(|l| l.or(layout))?;
    finish(
        given_rest(&get, notes)?,
        (from, in_layout),
        (to, layout),
        extent,
    )
}

/// The cells' layout `{side}_forder` and `{side}_frot` give for `proj` (`None` when neither
/// is given); refused for projections without cells.
fn cell_order<'a>(
    get: &impl Fn(&str) -> Option<&'a str>,
    side: &str,
    proj: Proj,
) -> Result<Option<Layout>, V360Error> {
    let (fo, fr) = (format!("{side}_forder"), format!("{side}_frot"));
    let (order, turns) = (get(&fo), get(&fr));
    let key = match (order, turns) {
        (None, None) => return Ok(None),
        (Some(_), _) => fo,
        (None, Some(_)) => fr,
    };
    let value = get(&key).unwrap_or_default().to_string();
    let Proj::Cells(grid) = proj else {
        return Err(V360Error::Unsupported {
            key,
            value,
            why: "face orders and turns are for c3x2, c6x1 and c1x6 (v360 ignores them for \
                  other projections, eac included)"
                .into(),
        });
    };
    let text = format!(
        "{grid}:forder={}:frot={}",
        order.unwrap_or("rludfb"),
        turns.unwrap_or("000000")
    );
    text.parse().map(Some).map_err(|e| V360Error::BadValue {
        key,
        value,
        takes: format!("six face letters (forder) or quarter turns (frot): {e}"),
    })
}

/// The options that do not depend on the projections: stereo modes and the rotation.
struct Rest {
    in_stereo: Stereo,
    out_stereo: Stereo,
    rotation: Rotation,
    notes: Vec<String>,
}

fn given_rest<'a>(
    get: &impl Fn(&str) -> Option<&'a str>,
    notes: Vec<String>,
) -> Result<Rest, V360Error> {
    let stereo = |k: &str| -> Result<Stereo, V360Error> {
        match get(k).map(str::trim) {
            None | Some("2d") => Ok(Stereo::Mono),
            Some("sbs") => Ok(Stereo::SideBySide),
            Some("tb") => Ok(Stereo::TopBottom),
            Some(v) => Err(V360Error::BadValue {
                key: k.into(),
                value: v.into(),
                takes: "2d, sbs or tb".into(),
            }),
        }
    };
    let angle = |k: &str| -> Result<f64, V360Error> {
        Ok(get(k)
            .map(|v| number(k, v, -180.0, 180.0))
            .transpose()?
            .unwrap_or(0.0))
    };
    let (yaw, pitch, roll) = (angle("yaw")?, angle("pitch")?, angle("roll")?);
    let order = get("rorder").unwrap_or("ypr");
    let bad_order = || V360Error::BadValue {
        key: "rorder".into(),
        value: order.into(),
        takes: "three of y, p, r (yaw, pitch, roll), in the order they turn: ypr, rpy, …".into(),
    };
    if order.chars().count() != 3 {
        return Err(bad_order());
    }
    // In mirrorball's axes: yaw about −Y, pitch about +X, roll about −Z (v360's y and z
    // are ours negated), each turning the output's direction to the source's.
    let mut m = DMat3::IDENTITY;
    for c in order.chars() {
        m *= match c.to_ascii_lowercase() {
            'y' => DMat3::from_rotation_y(-yaw.to_radians()),
            'p' => DMat3::from_rotation_x(pitch.to_radians()),
            'r' => DMat3::from_rotation_z(-roll.to_radians()),
            _ => return Err(bad_order()),
        };
    }
    let mut mirror = DVec3::ONE;
    for (i, k) in ["h_flip", "v_flip", "d_flip"].into_iter().enumerate() {
        if get(k).map(|v| boolean(k, v)).transpose()? == Some(true) {
            mirror[i] = -1.0;
        }
    }
    // Rotation::from_matrix takes the turn of the environment: the transpose of the
    // source-of map M·m.
    let to_source = DMat3::from_diagonal(mirror) * m;
    let rotation = Rotation::from_matrix(to_source.transpose()).expect("orthogonal");
    Ok(Rest {
        in_stereo: stereo("in_stereo")?,
        out_stereo: stereo("out_stereo")?,
        rotation,
        notes,
    })
}

/// The parsed string from its parts; `extent` (`w`, `h`) checked against the picture
/// mirrorball makes of the output.
fn finish(
    rest: Rest,
    (from, in_layout): (String, Option<Layout>),
    (to, layout): (String, Option<Layout>),
    extent: Option<(u32, u32)>,
) -> Result<V360, V360Error> {
    let spec = |key: &str, text: &str| {
        ProjSpec::parse(text).map_err(|e| V360Error::Unsupported {
            key: key.into(),
            value: text.into(),
            why: e.to_string(),
        })
    };
    let (from, to) = (spec("input", &from)?, spec("output", &to)?);
    let (size, layout) = match extent {
        None => (None, layout),
        Some((w, h)) => {
            let (size, layout) = output_size(&to, layout, w, h)?;
            (Some(size as i64), layout)
        }
    };
    Ok(V360 {
        from,
        in_layout,
        to,
        layout,
        size,
        in_stereo: rest.in_stereo,
        out_stereo: rest.out_stereo,
        rotation: rest.rotation,
        notes: rest.notes,
    })
}

/// The `--size` that makes a `w`×`h` picture of `to` in `layout`, and the layout (v360's
/// `eac` at any size: [`CubeCells::eac_frame`]); refused (naming `h`) when none does.
fn output_size(
    to: &ProjSpec,
    layout: Option<Layout>,
    w: u32,
    h: u32,
) -> Result<(u32, Option<Layout>), V360Error> {
    let refuse = |why: String| V360Error::Unsupported {
        key: "h".into(),
        value: h.to_string(),
        why,
    };
    let p = to.build(None).map_err(|e| refuse(e.to_string()))?;
    match layout {
        Some(Layout::Cells(cells)) if cells.eac_pad => CubeCells::eac_frame(w, h)
            .map(|(cells, n)| (n, Some(Layout::Cells(cells))))
            .ok_or_else(|| refuse(format!("w={w}:h={h}: too small for an eac picture"))),
        Some(Layout::Cells(cells)) => cells.face_size(w, h).map(|n| (n, layout)).ok_or_else(|| {
            let (a, b) = cells.extent(1);
            refuse(format!(
                "w={w}:h={h}: mirrorball's {} picture is {a}n x {b}n for faces of n texels",
                Layout::Cells(cells)
            ))
        }),
        _ => {
            let (ew, eh) = p.layer_extent(w);
            if (ew, eh) != (w, h) {
                let why = if p.kind() == ProjectionKind::Perspective {
                    "its texels are square here, its height follows h_fov and v_fov"
                } else {
                    "v360 would stretch its texels; mirrorball keeps the projection's shape"
                };
                return Err(refuse(format!(
                    "a {} of width {w} is {ew}x{eh} ({why}): give h={eh}",
                    p.kind()
                )));
            }
            Ok((w, layout))
        }
    }
}

impl ConvertRequest {
    /// This request doing what the v360 options `v` say: the input's and output's
    /// projections and layouts, the size, the stereo modes and the rotation. Refused (the
    /// request's fault) when the request already says any of them (`--to`, `--from`,
    /// `--in-layout`, `--layout`, `--size` with v360's `w`/`h`, `--in-stereo`, `--stereo`,
    /// `--yaw`, `--pitch`, `--roll`, `--flip`).
    pub fn with_v360(mut self, v: &V360) -> Result<ConvertRequest, Error> {
        let given = [
            ("--to", self.to.is_some()),
            ("--from", self.input_plan.from.is_some()),
            ("--in-layout", self.input_plan.layout.is_some()),
            ("--layout", self.layout.is_some()),
            ("--size", self.size.is_some() && v.size.is_some()),
            ("--in-stereo", self.in_stereo.is_some()),
            ("--stereo", self.stereo.is_some()),
            ("--yaw", self.yaw != 0.0),
            ("--pitch", self.pitch != 0.0),
            ("--roll", self.roll != 0.0),
            ("--flip", !self.flip.is_empty()),
            ("a rotation", self.rotation.is_some()),
        ];
        if let Some((flag, _)) = given.iter().find(|(_, g)| *g) {
            return Err(Error::request(format!(
                "{flag} and --v360 both say it: give it in the v360 options only (or leave \
                 --v360 out)"
            )));
        }
        self.input_plan.from = Some(v.from.clone());
        self.input_plan.layout = v.in_layout;
        self.to = Some(v.to.clone());
        self.layout = v.layout;
        if v.size.is_some() {
            self.size = v.size;
            self.height = None;
        }
        self.in_stereo = Some(v.in_stereo);
        self.stereo = Some(v.out_stereo);
        self.rotation = Some(v.rotation);
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(s: &str) -> V360Error {
        parse(s).expect_err(s)
    }

    #[test]
    fn projections_and_keys() {
        let v = parse("e:eac").unwrap();
        assert_eq!(v.from.kind, ProjectionKind::LatLong);
        assert_eq!(v.to.kind, ProjectionKind::Eac);
        assert_eq!(v.layout, Some(Layout::eac()));
        assert_eq!(v.size, None);
        let v = parse("input=dfisheye:output=e:ih_fov=190:iv_fov=190").unwrap();
        assert_eq!(v.from.to_string(), "dual-fisheye:fov=190");
        let v = parse("v360=e:c3x2:out_forder=fbudlr:out_frot=123012:w=120:h=80").unwrap();
        assert_eq!(
            v.layout.unwrap().to_string(),
            "c3x2:forder=fbudlr:frot=123012"
        );
        assert_eq!(v.size, Some(40));
        let v = parse("e:flat:h_fov=90:v_fov=58.71551708:w=160:h=90").unwrap();
        assert_eq!(v.size, Some(160));
        // Positional values in v360's order: interp, w, h.
        let v = parse("e:eac:near:148:104").unwrap();
        assert_eq!(v.size, Some(48));
        assert_eq!(v.notes.len(), 1, "{:?}", v.notes);
        assert_eq!(
            parse("e:e:in_stereo=sbs").unwrap().in_stereo,
            Stereo::SideBySide
        );
        // v360's eac at any size: YouTube's 3840x2160, faces 1278⅔ by 1076 texels, made
        // from faces of 1280 (the finer spacing, rounded up to even).
        let v = parse("e:eac:w=3840:h=2160").unwrap();
        assert_eq!(v.size, Some(1280));
        let layout = v.layout.unwrap();
        assert_eq!(layout.to_string(), "eac");
        assert_eq!(layout.extent(6, 1280, 1280), (3840, 2160));
        // Every name of the table reads; those refused say why, naming the key.
        for (names, p) in PROJECTIONS {
            for n in *names {
                let r = parse(&format!("e:{n}:h_fov=100:v_fov=100"));
                match p {
                    Proj::Refused(_) => assert_eq!(r.unwrap_err().key(), "output", "{n}"),
                    _ => assert!(r.is_ok(), "{n}: {:?}", r.err()),
                }
            }
        }
    }

    #[test]
    fn rotation_is_v360s() {
        // v360's (x, y, z) is ours (x, −y, −z); the source direction of output direction
        // d is q·d·q* with q = m[o₀]·m[o₁]·m[o₂], each m a turn about v360's y, x or z.
        let v360 = |yaw: f64, pitch: f64, roll: f64, order: &str, d: DVec3| {
            let turn = |c: char| match c {
                'y' => DMat3::from_rotation_y(yaw.to_radians()),
                'p' => DMat3::from_rotation_x(pitch.to_radians()),
                _ => DMat3::from_rotation_z(roll.to_radians()),
            };
            let m = order.chars().fold(DMat3::IDENTITY, |m, c| m * turn(c));
            let s = DVec3::new(1.0, -1.0, -1.0);
            m * (d * s) * s
        };
        let d = DVec3::new(0.3, -0.5, -0.8).normalize();
        for order in ["ypr", "yrp", "pyr", "pry", "ryp", "rpy"] {
            let v = parse(&format!("e:e:yaw=30:pitch=-20:roll=10:rorder={order}")).unwrap();
            let want = v360(30.0, -20.0, 10.0, order, d);
            assert!(v.rotation.source_of(d).abs_diff_eq(want, 1e-12), "{order}");
        }
        // mirrorball's --yaw 30 --pitch 20 is v360's yaw=30:pitch=-20:rorder=pyr.
        let v = parse("e:e:yaw=30:pitch=-20:rorder=pyr").unwrap();
        let ours = Rotation::from_euler_deg(30.0, 20.0, 0.0);
        assert!(v
            .rotation
            .source_of(d)
            .abs_diff_eq(ours.source_of(d), 1e-12));
        // Mirrors after the turn: h_flip negates x of the source direction.
        let v = parse("e:e:yaw=90:h_flip=1").unwrap();
        let turned = parse("e:e:yaw=90").unwrap().rotation.source_of(d);
        assert!(v
            .rotation
            .source_of(d)
            .abs_diff_eq(turned * DVec3::new(-1.0, 1.0, 1.0), 1e-12));
    }

    #[test]
    fn refusals_name_the_key() {
        for (s, key) in [
            ("e:eac:bogus=1", "bogus"),
            ("e:eac:yaw=200", "yaw"),
            ("e:eac:yaw=x", "yaw"),
            ("e:eac:rorder=ypx", "rorder"),
            ("e:eac:rorder=yp", "rorder"),
            ("e:cube", "output"),
            ("e:tsp", "output"),
            ("barrel:e", "input"),
            ("e:c3x2:out_forder=rludfx", "out_forder"),
            ("e:eac:out_forder=rludfb", "out_forder"),
            ("e:c3x2:in_forder=rludfb", "in_forder"),
            ("e:c3x2:out_pad=0.05", "out_pad"),
            ("e:e:ih_flip=1", "ih_flip"),
            ("e:e:alpha_mask=1", "alpha_mask"),
            ("e:e:h_offset=0.5", "h_offset"),
            ("e:e:w=100", "h"),
            ("e:e:w=100:h=100", "h"),
            ("e:c3x2:w=100:h=60", "h"),
            ("e:flat", "output"),
            ("e:fisheye:h_fov=180:v_fov=170", "v_fov"),
            ("e:flat:d_fov=100", "d_fov"),
            ("e:eac:interp=bogus", "interp"),
            ("e:eac:in_stereo=lr", "in_stereo"),
            ("e:eac:h_flip=maybe", "h_flip"),
            ("e:eac:yaw=10:yaw=20", "yaw"),
            ("e:eac:yaw=10:line", "line"),
        ] {
            let e = err(s);
            assert_eq!(e.key(), key, "{s}: {e}");
            assert!(Error::from(e.clone()).message.contains(key), "{s}: {e}");
        }
    }

    #[test]
    fn flags_that_say_it_again_are_refused() {
        let v = parse("e:eac:yaw=10").unwrap();
        let base = ConvertRequest::default();
        let r = base.clone().with_v360(&v).unwrap();
        assert_eq!(r.to.unwrap().kind, ProjectionKind::Eac);
        assert_eq!(r.rotation, Some(v.rotation));
        let twice = ConvertRequest {
            pitch: 5.0,
            ..base.clone()
        };
        let e = twice.with_v360(&v).unwrap_err();
        assert!(e.message.contains("--pitch"), "{}", e.message);
        let to = ConvertRequest {
            to: Some(ProjSpec::parse("cube").unwrap()),
            ..base
        };
        assert!(to.with_v360(&v).unwrap_err().message.contains("--to"));
    }
}
