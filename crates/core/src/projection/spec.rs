//! Projections as text: `NAME[:key=value[:key=value…]]`, the form the command line takes and
//! files record (`mirrorball:projection`).
//!
//! Keys: `look=DIR` (the direction a sphere map's camera, an angular map's or fisheye's
//! centre, or a paraboloid's front half looks along: `+x`, `-z`, or `x,y,z`), `up=DIR` (the
//! picture's up, when it is not the one [`Frame::looking_along`] picks), `fov=DEG` and
//! `lens=equidistant|equisolid|stereographic|orthographic` (fisheye), `max-lat=DEG`
//! (Mercator), `hfov=DEG` and `vfov=DEG` (the fields of view of the cylinders, the half
//! equirectangular and the views), `d=NUM` (Pannini's distance), `yaw=DEG`, `pitch=DEG` and
//! `roll=DEG` (where a view looks: yaw to the right, pitch up, as [`View::frame_of`] says).
//!
//! The dual fisheye (see [`DualFisheye`]) takes `fov`, `lens` and `look`/`up` (the front
//! lens's axis) for both lenses, `k=K1,K2,K3,K4` (OpenCV's fisheye coefficients, 1 to 4 of
//! them: the polynomial model for both lenses), `front=CX,CY,R[,ROLL]` and
//! `back=CX,CY,R[,ROLL]` (each image circle's centre and radius in units of the picture's
//! height, its roll in degrees counter-clockwise), and per lens `front-fov`, `front-lens`,
//! `front-k`, `back-fov`, `back-lens`, `back-k`, which override the shared keys:
//! `dual-fisheye:fov=200:lens=equisolid`,
//! `dfisheye:fov=204:k=0.02,-0.004:front=1.49,0.51,0.47,1.5:back=0.5,0.5,0.52`.
//!
//! [`Projection::spec`] gives every parameter of a built projection, and its text (the
//! `Display` of [`ProjectionSpec`] or [`Projection`]) is canonical: the name, then the keys
//! that apply in the order `fov`, `lens`, `max-lat`, `hfov`, `vfov`, `d`, `yaw`, `pitch`,
//! `roll`, the dual fisheye's (`k`, then per lens `fov`, `lens`, `k`, then `front`, `back`),
//! `look`, `up` (a view's zero angles left out), numbers rounded to 1e-9 (of a
//! degree, or of a unit vector's component). [`ProjectionSpec::parse`] reads it back to the
//! same projection, to that rounding.

use super::{
    AngularMap, Cylinder, CylinderRule, DualFisheye, DualParaboloid, Fisheye, FisheyeLens, Frame,
    Lens, LensModel, Mercator, Projection, ProjectionKind, Range, SphereMap, UnknownProjection,
    View,
};
use crate::{Choice, Error};
use glam::DVec3;
use std::fmt;

/// A projection named in text, with the parameters it was given: [`ProjectionSpec::build`]
/// fills in the rest with their defaults.
///
/// ```
/// use mirrorball_core::projection::ProjectionSpec;
/// use mirrorball_core::ProjectionKind;
/// let s = ProjectionSpec::parse("fisheye:fov=190:lens=equisolid:look=+y").unwrap();
/// assert_eq!(s.kind, ProjectionKind::Fisheye);
/// let p = s.build(None).unwrap();
/// assert_eq!(p.to_string(), "fisheye:fov=190:lens=equisolid:look=0,1,0");
/// assert_eq!(ProjectionSpec::parse(&p.to_string()).unwrap().build(None).unwrap(), p);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct ProjectionSpec {
    /// The kind.
    pub kind: ProjectionKind,
    look: Option<DVec3>,
    up: Option<DVec3>,
    fov: Option<f64>,
    lens: Option<Lens>,
    max_lat: Option<f64>,
    hfov: Option<f64>,
    vfov: Option<f64>,
    distance: Option<f64>,
    /// Yaw, pitch, roll.
    aim: [Option<f64>; 3],
    /// The dual fisheye's polynomial for both lenses.
    k: Option<[f64; 4]>,
    /// The dual fisheye's lenses (front, back).
    lenses: [LensSpec; 2],
}

/// One dual fisheye lens's keys: `front=`/`back=` and its own `fov`, `lens`, `k`.
#[derive(Clone, Debug, Default, PartialEq)]
struct LensSpec {
    /// Centre x, centre y, radius, roll.
    place: Option<[f64; 4]>,
    fov: Option<f64>,
    lens: Option<Lens>,
    k: Option<[f64; 4]>,
}

/// `K1[,K2[,K3[,K4]]]`: OpenCV's fisheye coefficients, those left out zero.
fn parse_k(key: &str, v: &str) -> Result<[f64; 4], String> {
    let parts: Vec<Option<f64>> = v
        .split(',')
        .map(|p| p.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect();
    if parts.is_empty() || parts.len() > 4 || parts.iter().any(Option::is_none) {
        return Err(format!(
            "{key}={v}: give 1 to 4 numbers k1,k2,k3,k4 (OpenCV's fisheye coefficients)"
        ));
    }
    let mut k = [0.0; 4];
    for (o, p) in k.iter_mut().zip(parts) {
        *o = p.unwrap_or(0.0);
    }
    Ok(k)
}

/// `CX,CY,R[,ROLL]`: an image circle in units of the picture's height, its roll in degrees.
fn parse_place(key: &str, v: &str) -> Result<[f64; 4], String> {
    let parts: Vec<Option<f64>> = v
        .split(',')
        .map(|p| p.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect();
    if !(3..=4).contains(&parts.len()) || parts.iter().any(Option::is_none) {
        return Err(format!(
            "{key}={v}: give cx,cy,r[,roll] (the image circle's centre and radius in picture \
             heights, its roll in degrees)"
        ));
    }
    let mut out = [0.0; 4];
    for (o, p) in out.iter_mut().zip(parts) {
        *o = p.unwrap_or(0.0);
    }
    Ok(out)
}

fn parse_lens(v: &str) -> Result<Lens, String> {
    Lens::parse_name(v).map_err(|e| format!("unknown lens '{v}' (known: {})", e.list()))
}

/// Parses a direction: `+x`, `-y`, `z`, or three numbers `x,y,z`. Text that is none is
/// the request's fault.
pub fn parse_dir(s: &str) -> Result<DVec3, Error> {
    dir_text(s).map_err(Error::request)
}

fn dir_text(s: &str) -> Result<DVec3, String> {
    let t = s.trim().to_ascii_lowercase();
    let axis = match t.as_str() {
        "+x" | "x" => Some(DVec3::X),
        "-x" => Some(DVec3::NEG_X),
        "+y" | "y" | "up" => Some(DVec3::Y),
        "-y" | "down" => Some(DVec3::NEG_Y),
        "+z" | "z" | "back" => Some(DVec3::Z),
        "-z" | "forward" => Some(DVec3::NEG_Z),
        _ => None,
    };
    if let Some(a) = axis {
        return Ok(a);
    }
    let parts: Vec<f64> = t
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("'{s}' is not a direction (use +x, -z, or x,y,z)"))?;
    if parts.len() != 3 || parts.iter().any(|v| !v.is_finite()) {
        return Err(format!("'{s}' is not a direction (use +x, -z, or x,y,z)"));
    }
    let d = DVec3::new(parts[0], parts[1], parts[2]);
    if d.length() == 0.0 {
        return Err(format!("'{s}' is the zero vector, which points nowhere"));
    }
    Ok(d)
}

impl ProjectionSpec {
    /// Parses `NAME[:key=value…]`, checking that each key applies to the kind and that the
    /// values make a projection. Text that does not is the request's fault.
    pub fn parse(s: &str) -> Result<ProjectionSpec, Error> {
        ProjectionSpec::parse_text(s).map_err(Error::request)
    }

    fn parse_text(s: &str) -> Result<ProjectionSpec, String> {
        let mut parts = s.split(':');
        let name = parts.next().unwrap_or_default();
        let kind: ProjectionKind = name.parse().map_err(|e: UnknownProjection| e.to_string())?;
        let mut spec = ProjectionSpec::of(kind);
        for kv in parts {
            let (k, v) = kv
                .split_once('=')
                .ok_or_else(|| format!("'{kv}' in '{s}' is not key=value"))?;
            let num = |v: &str| {
                v.parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| format!("'{v}' is not a number (in '{s}')"))
            };
            match k.trim() {
                "look" | "dir" | "view" => spec.look = Some(dir_text(v)?),
                "up" => spec.up = Some(dir_text(v)?),
                "fov" => spec.fov = Some(num(v)?),
                "lens" => spec.lens = Some(parse_lens(v)?),
                "k" => spec.k = Some(parse_k("k", v)?),
                key @ ("front" | "back") => {
                    spec.lenses[(key == "back") as usize].place = Some(parse_place(key, v)?)
                }
                key @ ("front-fov" | "back-fov") => {
                    spec.lenses[key.starts_with("back") as usize].fov = Some(num(v)?)
                }
                key @ ("front-lens" | "back-lens") => {
                    spec.lenses[key.starts_with("back") as usize].lens = Some(parse_lens(v)?)
                }
                key @ ("front-k" | "back-k") => {
                    spec.lenses[key.starts_with("back") as usize].k = Some(parse_k(key, v)?)
                }
                "max-lat" | "maxlat" | "lat" => spec.max_lat = Some(num(v)?),
                "hfov" | "h-fov" | "h_fov" => spec.hfov = Some(num(v)?),
                "vfov" | "v-fov" | "v_fov" => spec.vfov = Some(num(v)?),
                "d" | "distance" => spec.distance = Some(num(v)?),
                "yaw" => spec.aim[0] = Some(num(v)?),
                "pitch" => spec.aim[1] = Some(num(v)?),
                "roll" => spec.aim[2] = Some(num(v)?),
                other => {
                    return Err(format!(
                        "unknown option '{other}' in '{s}' (known: look, up, fov, lens, \
                         max-lat, hfov, vfov, d, yaw, pitch, roll, k, front, back, front-fov, \
                         front-lens, front-k, back-fov, back-lens, back-k)"
                    ))
                }
            }
        }
        let applies = |ok: bool, key: &str| {
            if ok {
                Ok(())
            } else {
                Err(format!("'{key}' does not apply to {}", kind.name()))
            }
        };
        use ProjectionKind as K;
        if spec.look.is_some() || spec.up.is_some() {
            applies(
                matches!(
                    kind,
                    K::Sphere | K::Angular | K::Fisheye | K::Paraboloid | K::DualFisheye
                ),
                "look/up",
            )?;
        }
        if spec.fov.is_some() || spec.lens.is_some() {
            applies(matches!(kind, K::Fisheye | K::DualFisheye), "fov/lens")?;
        }
        if spec.k.is_some() || spec.lenses != <[LensSpec; 2]>::default() {
            applies(kind == K::DualFisheye, "k/front/back")?;
        }
        if spec.max_lat.is_some() {
            applies(kind == K::Mercator, "max-lat")?;
        }
        let view = matches!(kind, K::Perspective | K::Pannini);
        if spec.hfov.is_some() || spec.vfov.is_some() {
            applies(
                view || matches!(
                    kind,
                    K::Cylindrical | K::CylindricalEqualArea | K::HalfEquirect
                ),
                "hfov/vfov",
            )?;
        }
        if spec.distance.is_some() {
            applies(kind == K::Pannini, "d")?;
        }
        if spec.aim.iter().any(Option::is_some) {
            applies(view, "yaw/pitch/roll")?;
        }
        spec.build_text(None)?; // validate values now, before any work
        Ok(spec)
    }

    /// A spec of this kind with default parameters.
    pub fn of(kind: ProjectionKind) -> ProjectionSpec {
        ProjectionSpec {
            kind,
            look: None,
            up: None,
            fov: None,
            lens: None,
            max_lat: None,
            hfov: None,
            vfov: None,
            distance: None,
            aim: [None; 3],
            k: None,
            lenses: Default::default(),
        }
    }

    /// Every bounded number key of this spec's kind, with the value given (if any) and the
    /// interval it must lie in, which may depend on the other keys (a fisheye's lens,
    /// Pannini's `d`, a cylinder's rule, a dual fisheye lens's model). [`ProjectionSpec::build`]
    /// checks each given value against it before anything else, so every range message
    /// comes from here: `fisheye, equidistant lens: fov must be in (0°, 360°]; fov=-90 was
    /// given`.
    pub fn ranges(&self) -> Vec<Bounded> {
        let one = |scope: String, key: &'static str, given: Option<f64>, range: Range| Bounded {
            scope,
            key,
            given,
            range,
        };
        let name = self.kind.name().to_string();
        match self.kind {
            ProjectionKind::Fisheye => {
                let lens = self.lens.unwrap_or(Lens::Equidistant);
                let scope = format!("{name}, {} lens", lens.name());
                vec![one(scope, "fov", self.fov, lens.fov_range())]
            }
            ProjectionKind::Mercator => vec![one(name, "max-lat", self.max_lat, Mercator::MAX_LAT)],
            ProjectionKind::Cylindrical
            | ProjectionKind::CylindricalEqualArea
            | ProjectionKind::HalfEquirect => vec![
                one(name.clone(), "hfov", self.hfov, Cylinder::HFOV),
                one(
                    name,
                    "vfov",
                    self.vfov,
                    Cylinder::vfov_range(self.cylinder_rule()),
                ),
            ],
            ProjectionKind::Perspective => vec![
                one(name.clone(), "hfov", self.hfov, View::hfov_range(0.0)),
                one(name, "vfov", self.vfov, View::VFOV),
            ],
            ProjectionKind::Pannini => {
                let d = self.distance.unwrap_or(1.0);
                vec![
                    one(name.clone(), "d", self.distance, View::DISTANCE),
                    one(
                        format!("{name}, d={d}"),
                        "hfov",
                        self.hfov,
                        View::hfov_range(d),
                    ),
                    one(name, "vfov", self.vfov, View::VFOV),
                ]
            }
            ProjectionKind::DualFisheye => {
                let models = self.lens_models().unwrap_or([FisheyeLens::FRONT.model; 2]);
                (0..2)
                    .map(|i| {
                        let (lens, own) = (["front", "back"][i], self.lenses[i].fov);
                        let key = match (own, i) {
                            (None, _) => "fov",
                            (Some(_), 0) => "front-fov",
                            _ => "back-fov",
                        };
                        let scope = format!("{name}, {lens} lens ({})", models[i].name());
                        one(scope, key, own.or(self.fov), models[i].fov_range())
                    })
                    .collect()
            }
            _ => Vec::new(),
        }
    }

    /// The cylinder rule of a cylinder kind (half-equirect's is equidistant).
    fn cylinder_rule(&self) -> CylinderRule {
        match self.kind {
            ProjectionKind::Cylindrical => CylinderRule::Central,
            ProjectionKind::CylindricalEqualArea => CylinderRule::EqualArea,
            _ => CylinderRule::Equidistant,
        }
    }

    /// Each dual fisheye lens's model: its own `-k` or `-lens`, else the shared `k` or
    /// `lens`, else equidistant; refused when one lens is given both.
    fn lens_models(&self) -> Result<[LensModel; 2], String> {
        let mut models = [FisheyeLens::FRONT.model, FisheyeLens::BACK.model];
        for (i, (m, ls)) in models.iter_mut().zip(&self.lenses).enumerate() {
            let name = ["front", "back"][i];
            if ls.lens.is_some() && ls.k.is_some() {
                return Err(format!(
                    "dual-fisheye: {name}-lens and {name}-k both given: a lens has one model"
                ));
            }
            *m = match (ls.k, ls.lens, self.k, self.lens) {
                (Some(k), ..) => LensModel::Polynomial(k),
                (None, Some(lens), ..) => LensModel::Standard(lens),
                (None, None, Some(_), Some(_)) => {
                    return Err("dual-fisheye: lens and k both given: a lens has one \
                                model (per lens: front-lens, back-k, ...)"
                        .into())
                }
                (None, None, Some(k), None) => LensModel::Polynomial(k),
                (None, None, None, Some(lens)) => LensModel::Standard(lens),
                (None, None, None, None) => *m,
            };
        }
        Ok(models)
    }

    /// The frame `look` and `up` give (the default frame without them).
    fn frame(&self) -> Result<Frame, String> {
        const ALONG: &str = "the up direction must not be along the look direction";
        Ok(match (self.look, self.up) {
            (Some(d), Some(up)) => Frame::looking_along_up(d, up).ok_or(ALONG)?,
            (Some(d), None) => {
                Frame::looking_along(d).ok_or("the look direction must be non-zero")?
            }
            (None, Some(up)) => {
                Frame::looking_along_up(Frame::default().forward, up).ok_or(ALONG)?
            }
            (None, None) => Frame::default(),
        })
    }

    /// This spec with the output `w`×`h` texels (`--size WxH`, as `v360`'s `w` and `h`): a
    /// perspective view's vertical field of view set so that its height at width `w` is
    /// `h` with square pixels; any other projection kept, as long as `w` gives it `h`.
    /// Refused (a request fault) where a view's `vfov` is given too, or another
    /// projection's height at width `w` is not `h`.
    pub fn with_height(&self, w: u32, h: u32) -> Result<ProjectionSpec, Error> {
        let mut spec = self.clone();
        if self.kind == ProjectionKind::Perspective {
            if self.vfov.is_some() {
                return Err(Error::request(format!(
                    "--size {w}x{h}: the view's height follows its vfov; give a height or vfov, not both"
                )));
            }
            let hfov = self.hfov.unwrap_or(90.0).to_radians();
            let vfov = 2.0 * ((hfov / 2.0).tan() * h as f64 / w as f64).atan();
            spec.vfov = Some(vfov.to_degrees());
        }
        let (ew, eh) = super::WorldProjection::layer_extent(&spec.build(None)?, w);
        if (ew, eh) != (w, h) {
            return Err(Error::request(format!(
                "--size {w}x{h}: a {} of width {w} is {ew}x{eh} (a height is taken by flat views, which set their vfov from it; give --size {w} for others)",
                self.kind
            )));
        }
        Ok(spec)
    }

    /// The projection. For Mercator without `max-lat`, `extent` (an input picture's size)
    /// fixes the limit from the aspect ratio. Each number given is checked against its
    /// interval first ([`ProjectionSpec::ranges`]); a value outside is the request's fault.
    pub fn build(&self, extent: Option<(u32, u32)>) -> Result<Projection, Error> {
        self.build_text(extent).map_err(Error::request)
    }

    fn build_text(&self, extent: Option<(u32, u32)>) -> Result<Projection, String> {
        for b in self.ranges() {
            if let Some(v) = b.given {
                b.range
                    .check(b.key, v)
                    .map_err(|e| format!("{}: {e}", b.scope))?;
            }
        }
        let frame = self.frame()?;
        // Past the ranges, a constructor refuses nothing more: its check is the range's.
        let inside = || format!("{self}: parameters outside their ranges");
        Ok(match self.kind {
            ProjectionKind::Sphere => SphereMap::new(frame).into(),
            ProjectionKind::Angular => AngularMap::new(frame).into(),
            ProjectionKind::Paraboloid => DualParaboloid::new(frame).into(),
            ProjectionKind::Fisheye => {
                let lens = self.lens.unwrap_or(Lens::Equidistant);
                Fisheye::new(frame, lens, self.fov.unwrap_or(180.0))
                    .ok_or_else(inside)?
                    .into()
            }
            ProjectionKind::Mercator => match (self.max_lat, extent) {
                (Some(l), _) => Mercator::new(l).ok_or_else(inside)?.into(),
                (None, Some((w, h))) => Mercator::from_extent(w, h).ok_or("empty picture")?.into(),
                (None, None) => Mercator::default().into(),
            },
            ProjectionKind::Cylindrical
            | ProjectionKind::CylindricalEqualArea
            | ProjectionKind::HalfEquirect => {
                let rule = self.cylinder_rule();
                let (h, v) = match rule {
                    CylinderRule::Central => (360.0, 90.0),
                    CylinderRule::EqualArea => (360.0, 180.0),
                    CylinderRule::Equidistant => (180.0, 180.0),
                };
                let (h, v) = (self.hfov.unwrap_or(h), self.vfov.unwrap_or(v));
                Projection::Cylinder(Cylinder::new(rule, h, v).ok_or_else(inside)?)
            }
            ProjectionKind::Perspective | ProjectionKind::Pannini => {
                let pannini = self.kind == ProjectionKind::Pannini;
                let (h, v) = (
                    self.hfov.unwrap_or(if pannini { 120.0 } else { 90.0 }),
                    self.vfov.unwrap_or(90.0),
                );
                let [yaw, pitch, roll] = self.aim.map(|a| a.unwrap_or(0.0));
                let view = if pannini {
                    View::pannini(self.distance.unwrap_or(1.0), h, v, yaw, pitch, roll)
                } else {
                    View::perspective(h, v, yaw, pitch, roll)
                };
                Projection::View(view.ok_or_else(inside)?)
            }
            ProjectionKind::DualFisheye => {
                let models = self.lens_models()?;
                let mut lenses = [FisheyeLens::FRONT, FisheyeLens::BACK];
                for ((l, ls), model) in lenses.iter_mut().zip(&self.lenses).zip(models) {
                    if let Some([cx, cy, r, roll]) = ls.place {
                        (l.centre, l.radius, l.roll_deg) = (glam::DVec2::new(cx, cy), r, roll);
                    }
                    l.fov_deg = ls.fov.or(self.fov).unwrap_or(l.fov_deg);
                    l.model = model;
                }
                DualFisheye::new(frame, lenses[0], lenses[1])
                    .map_err(|e| format!("dual-fisheye: {e}"))?
                    .into()
            }
            k => k.default_projection(),
        })
    }
}

/// One bounded number key of a spec ([`ProjectionSpec::ranges`]): where it applies, its
/// name, the value given and the interval it must lie in.
#[derive(Clone, Debug, PartialEq)]
pub struct Bounded {
    /// What the interval belongs to, for messages: `fisheye, orthographic lens`.
    pub scope: String,
    /// The key: `fov`, `max-lat`, `hfov`, …
    pub key: &'static str,
    /// The value given, if any.
    pub given: Option<f64>,
    /// The interval.
    pub range: Range,
}

impl Projection {
    /// Every parameter of this projection as a spec: building it gives this projection back
    /// (to the rounding of its text form; see the module documentation).
    pub fn spec(&self) -> ProjectionSpec {
        let mut s = ProjectionSpec::of(self.kind());
        let frame = match self {
            Projection::Sphere(p) => Some(*p.eye()),
            Projection::Angular(p) => Some(*p.radial().frame()),
            Projection::Fisheye(p) => {
                s.fov = Some(2.0 * p.radial().theta_max().to_degrees());
                s.lens = Some(p.radial().lens());
                Some(*p.radial().frame())
            }
            Projection::Paraboloid(p) => Some(*p.frame()),
            Projection::DualFisheye(p) => {
                let [f, b] = *p.lenses();
                if f.fov_deg == b.fov_deg {
                    s.fov = Some(f.fov_deg);
                } else {
                    s.lenses[0].fov = Some(f.fov_deg);
                    s.lenses[1].fov = Some(b.fov_deg);
                }
                let set = |m: LensModel, lens: &mut Option<Lens>, k: &mut Option<[f64; 4]>| match m
                {
                    LensModel::Standard(l) => *lens = Some(l),
                    LensModel::Polynomial(c) => *k = Some(c),
                };
                if f.model == b.model {
                    set(f.model, &mut s.lens, &mut s.k);
                } else {
                    for (ls, l) in s.lenses.iter_mut().zip([f, b]) {
                        set(l.model, &mut ls.lens, &mut ls.k);
                    }
                }
                for (ls, l) in s.lenses.iter_mut().zip([f, b]) {
                    ls.place = Some([l.centre.x, l.centre.y, l.radius, l.roll_deg]);
                }
                Some(*p.rig())
            }
            Projection::Mercator(p) => {
                s.max_lat = Some(p.max_latitude_deg());
                None
            }
            Projection::Cylinder(c) => {
                s.hfov = Some(c.hfov_deg());
                s.vfov = Some(c.vfov_deg());
                None
            }
            Projection::View(v) => {
                let [h, vf, yaw, pitch, roll] = v.angles_deg();
                s.hfov = Some(h);
                s.vfov = Some(vf);
                if v.is_pannini() {
                    s.distance = Some(v.distance());
                }
                s.aim = [yaw, pitch, roll].map(|a| (a != 0.0).then_some(a));
                None
            }
            _ => None,
        };
        if let Some(f) = frame {
            s.look = Some(f.forward);
            let usual = Frame::looking_along(f.forward).map(|g| g.up);
            if usual.is_none_or(|u| (u - f.up).length() > 1e-9) {
                s.up = Some(f.up);
            }
        }
        s
    }
}

/// A number for the text form: rounded to 1e-9, without a sign on zero.
struct Num(f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let r = (self.0 * 1e9).round() / 1e9;
        write!(f, "{}", if r == 0.0 { 0.0 } else { r })
    }
}

/// A direction for the text form: `x,y,z`.
struct Dir(DVec3);

impl fmt::Display for Dir {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{},{}", Num(self.0.x), Num(self.0.y), Num(self.0.z))
    }
}

impl fmt::Display for ProjectionSpec {
    /// The canonical text: the name, then the parameters given, in the order `fov`, `lens`,
    /// `max-lat`, `hfov`, `vfov`, `d`, `yaw`, `pitch`, `roll`, `look`, `up`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.kind.name())?;
        if let Some(v) = self.fov {
            write!(f, ":fov={}", Num(v))?;
        }
        if let Some(l) = self.lens {
            write!(f, ":lens={}", l.name())?;
        }
        if let Some(v) = self.max_lat {
            write!(f, ":max-lat={}", Num(v))?;
        }
        if let Some(v) = self.hfov {
            write!(f, ":hfov={}", Num(v))?;
        }
        if let Some(v) = self.vfov {
            write!(f, ":vfov={}", Num(v))?;
        }
        if let Some(v) = self.distance {
            write!(f, ":d={}", Num(v))?;
        }
        for (key, a) in ["yaw", "pitch", "roll"].iter().zip(self.aim) {
            if let Some(v) = a {
                write!(f, ":{key}={}", Num(v))?;
            }
        }
        let list = |v: &[f64]| {
            v.iter()
                .map(|x| Num(*x).to_string())
                .collect::<Vec<_>>()
                .join(",")
        };
        if let Some(k) = self.k {
            write!(f, ":k={}", list(&k))?;
        }
        for (name, ls) in ["front", "back"].iter().zip(&self.lenses) {
            if let Some(v) = ls.fov {
                write!(f, ":{name}-fov={}", Num(v))?;
            }
            if let Some(l) = ls.lens {
                write!(f, ":{name}-lens={}", l.name())?;
            }
            if let Some(k) = ls.k {
                write!(f, ":{name}-k={}", list(&k))?;
            }
        }
        for (name, ls) in ["front", "back"].iter().zip(&self.lenses) {
            if let Some(p) = ls.place {
                write!(f, ":{name}={}", list(&p))?;
            }
        }
        if let Some(d) = self.look {
            write!(f, ":look={}", Dir(d))?;
        }
        if let Some(d) = self.up {
            write!(f, ":up={}", Dir(d))?;
        }
        Ok(())
    }
}

impl fmt::Display for Projection {
    /// The canonical text of [`Projection::spec`]: `sphere:look=0,0,-1`,
    /// `fisheye:fov=190:lens=equisolid:look=0,1,0`, `mercator:max-lat=85.051128780`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.spec().fmt(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::WorldProjection;
    use glam::DVec2;

    #[test]
    fn parses_names_and_options() {
        let s = ProjectionSpec::parse("fisheye:fov=220:lens=equisolid:look=+y").unwrap();
        assert_eq!(s.kind, ProjectionKind::Fisheye);
        assert!(ProjectionSpec::parse("equirect").is_ok());
        assert!(ProjectionSpec::parse("fisheye:fov=400:lens=stereographic").is_err());
        assert!(ProjectionSpec::parse("cube:fov=90")
            .unwrap_err()
            .message
            .contains("does not apply"));
        assert!(ProjectionSpec::parse("sphere:look=0,0,0").is_err());
        assert!(ProjectionSpec::parse("sphere:look=+y:up=0,2,0").is_err());
        assert!(ProjectionSpec::parse("mercator:max-lat=95").is_err());
        assert!(ProjectionSpec::parse("perspective:hfov=180").is_err());
        assert!(ProjectionSpec::parse("pannini:d=-1").is_err());
        assert!(ProjectionSpec::parse("pannini:d=1:hfov=360").is_err());
        assert!(ProjectionSpec::parse("cylindrical:vfov=180").is_err());
        assert!(ProjectionSpec::parse("cea:vfov=180").is_ok());
        assert!(ProjectionSpec::parse("hammer:hfov=90")
            .unwrap_err()
            .message
            .contains("does not apply"));
        assert!(ProjectionSpec::parse("cylindrical:yaw=10")
            .unwrap_err()
            .message
            .contains("does not apply"));
        assert!(ProjectionSpec::parse("perspective:d=1")
            .unwrap_err()
            .message
            .contains("does not apply"));
        assert!(ProjectionSpec::parse("nope")
            .unwrap_err()
            .message
            .contains("known"));
    }

    /// The largest difference in direction between two projections over a grid of texture
    /// coordinates of every layer: zero when they are the same mapping.
    fn max_dir_diff(a: &Projection, b: &Projection) -> f64 {
        let mut worst = 0.0f64;
        for layer in 0..a.layer_count() {
            for i in 0..17 {
                for j in 0..17 {
                    let uv = DVec2::new((i as f64 + 0.5) / 17.0, (j as f64 + 0.5) / 17.0);
                    match (a.uv_to_dir(layer, uv), b.uv_to_dir(layer, uv)) {
                        (Some(x), Some(y)) => worst = worst.max((x - y).length()),
                        (None, None) => {}
                        _ => return f64::INFINITY,
                    }
                }
            }
        }
        worst
    }

    #[test]
    fn text_form_round_trips_every_projection() {
        let frame_up = Frame::looking_along_up(DVec3::new(1.0, 0.2, -0.3), DVec3::Z).unwrap();
        let mut cases: Vec<Projection> = ProjectionKind::ALL
            .iter()
            .map(|k| k.default_projection())
            .collect();
        cases.extend::<[Projection; 11]>([
            Cylinder::new(CylinderRule::Central, 123.4, 56.7)
                .unwrap()
                .into(),
            Cylinder::new(CylinderRule::EqualArea, 200.0, 100.0)
                .unwrap()
                .into(),
            View::perspective(100.0, 60.0, 30.0, -20.0, 12.5)
                .unwrap()
                .into(),
            View::pannini(0.7, 150.0, 80.0, 0.0, 45.0, 0.0)
                .unwrap()
                .into(),
            Fisheye::new(
                Frame::looking_along(DVec3::Y).unwrap(),
                Lens::Equisolid,
                190.0,
            )
            .unwrap()
            .into(),
            Fisheye::new(frame_up, Lens::Stereographic, 123.456)
                .unwrap()
                .into(),
            SphereMap::new(Frame::looking_along(DVec3::new(1.0, 1.0, 0.0)).unwrap()).into(),
            AngularMap::new(frame_up).into(),
            DualParaboloid::new(Frame::looking_along(DVec3::X).unwrap()).into(),
            Mercator::new(70.0).unwrap().into(),
            Mercator::from_extent(300, 200).unwrap().into(),
        ]);
        for p in cases {
            let text = p.to_string();
            let back = ProjectionSpec::parse(&text)
                .unwrap_or_else(|e| panic!("{text}: {e}"))
                .build(None)
                .unwrap();
            assert_eq!(back.kind(), p.kind(), "{text}");
            let d = max_dir_diff(&p, &back);
            assert!(d < 1e-8, "{text}: directions differ by {d}");
            // Canonical: the text of what was read is the text that was written (with an
            // `up`, made perpendicular again after rounding, the last digit may move).
            if !text.contains(":up=") {
                assert_eq!(back.to_string(), text);
            }
        }
        assert_eq!(
            Projection::from(
                Fisheye::new(
                    Frame::looking_along(DVec3::Y).unwrap(),
                    Lens::Equisolid,
                    190.0
                )
                .unwrap()
            )
            .to_string(),
            "fisheye:fov=190:lens=equisolid:look=0,1,0"
        );
        assert_eq!(
            Projection::from(SphereMap::default()).to_string(),
            "sphere:look=0,0,-1"
        );
        assert_eq!(
            Projection::from(frame_up_angular())
                .to_string()
                .matches(":up=")
                .count(),
            1
        );
    }

    #[test]
    fn dual_fisheye_text() {
        let p = ProjectionSpec::parse("dfisheye:fov=200:lens=equisolid")
            .unwrap()
            .build(None)
            .unwrap();
        let Projection::DualFisheye(d) = p else {
            panic!("{p:?}")
        };
        assert_eq!(d.lenses()[1].fov_deg, 200.0);
        assert_eq!(d.lenses()[0].model, LensModel::Standard(Lens::Equisolid));
        let text = "dual-fisheye:fov=204:k=0.02,-0.004:back-fov=198:back-k=0.01:\
                    front=1.49,0.51,0.47,1.5:back=0.5,0.5,0.52:look=0.2,-0.1,-1";
        let p = ProjectionSpec::parse(text).unwrap().build(None).unwrap();
        let Projection::DualFisheye(d) = p else {
            panic!("{p:?}")
        };
        let [f, b] = *d.lenses();
        assert_eq!(f.model, LensModel::Polynomial([0.02, -0.004, 0.0, 0.0]));
        assert_eq!(b.model, LensModel::Polynomial([0.01, 0.0, 0.0, 0.0]));
        assert_eq!((f.fov_deg, b.fov_deg), (204.0, 198.0));
        assert_eq!((f.roll_deg, b.radius), (1.5, 0.52));
        let back = ProjectionSpec::parse(&p.to_string())
            .unwrap()
            .build(None)
            .unwrap();
        assert!(max_dir_diff(&p, &back) < 1e-8, "{p}");
        assert_eq!(back.to_string(), p.to_string());
        // Bad input: the key and the problem.
        for (bad, says) in [
            (
                "dfisheye:fov=400",
                "front lens (equidistant): fov must be in (0°, 360°]; fov=400 was given",
            ),
            (
                "dfisheye:front-fov=-5",
                "front lens (equidistant): front-fov must be in (0°, 360°]; front-fov=-5",
            ),
            ("dfisheye:fov=nan", "'nan' is not a number"),
            ("dfisheye:front=1.5,0.5,0", "radius 0 must be over 0"),
            ("dfisheye:back=5,0.5,0.5", "outside the 2×1 picture"),
            ("dfisheye:back=1.2,0.5,0.5", "overlap in the picture"),
            ("dfisheye:fov=200:k=0,-0.2", "stops increasing"),
            ("dfisheye:k=1,2,3,4,5", "1 to 4 numbers"),
            ("dfisheye:front=1,2", "cx,cy,r[,roll]"),
            ("dfisheye:lens=equisolid:k=0.1", "lens and k both given"),
            (
                "dfisheye:fov=200:lens=orthographic",
                "front lens (orthographic): fov must be in (0°, 180°]",
            ),
            ("fisheye:k=0.1", "does not apply"),
        ] {
            let e = ProjectionSpec::parse(bad).unwrap_err().message;
            assert!(e.contains(says), "{bad}: {e}");
        }
    }

    /// Every bounded key of every kind, given a value outside its interval, is refused
    /// with the interval and the value (the message [`ProjectionSpec::ranges`] makes), and
    /// a value inside is taken.
    #[test]
    fn every_range_message_names_the_interval_and_the_value() {
        let mut checked = 0;
        for kind in ProjectionKind::ALL {
            let ranges = ProjectionSpec::of(kind).ranges();
            // A key shared by both dual fisheye lenses is checked for the front one first.
            for (i, b) in ranges.iter().enumerate() {
                if ranges[..i].iter().any(|a| a.key == b.key) {
                    continue;
                }
                let tries = [-1e9, -90.0, 0.0, b.range.hi(), b.range.hi() + 1.0, 1e9];
                for v in tries.into_iter().filter(|v| v.is_finite()) {
                    let text = format!("{}:{}={v}", kind.name(), b.key);
                    let got = ProjectionSpec::parse(&text);
                    if b.range.contains(v) {
                        assert!(got.is_ok(), "{text}: {got:?}");
                        continue;
                    }
                    let e = got.unwrap_err().message;
                    let want = format!(
                        "{}: {} must be in {}; {}={v} was given",
                        b.scope, b.key, b.range, b.key
                    );
                    assert_eq!(e, want, "{text}");
                    checked += 1;
                }
            }
        }
        assert!(checked >= 30, "{checked} refusals checked");
        // The issue's cases, word for word.
        assert_eq!(
            ProjectionSpec::parse("fisheye:fov=-90")
                .unwrap_err()
                .message,
            "fisheye, equidistant lens: fov must be in (0°, 360°]; fov=-90 was given"
        );
        assert_eq!(
            ProjectionSpec::parse("fisheye:lens=orthographic:fov=200")
                .unwrap_err()
                .message,
            "fisheye, orthographic lens: fov must be in (0°, 180°]; fov=200 was given"
        );
        assert_eq!(
            ProjectionSpec::parse("pannini:d=2:hfov=250")
                .unwrap_err()
                .message,
            "pannini, d=2: hfov must be in (0°, 240°); hfov=250 was given"
        );
    }

    fn frame_up_angular() -> AngularMap {
        AngularMap::new(Frame::looking_along_up(DVec3::NEG_Z, DVec3::X).unwrap())
    }
}
