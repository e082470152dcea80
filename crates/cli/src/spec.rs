//! Projection specifications on the command line: `NAME[:key=value[:key=value…]]`.
//!
//! Keys: `look=DIR` (the direction a sphere map's camera, an angular map's or fisheye's
//! centre, or a paraboloid's front half looks along: `+x`, `-z`, or `x,y,z`), `fov=DEG` and
//! `lens=equidistant|equisolid|stereographic|orthographic` (fisheye), `max-lat=DEG`
//! (Mercator).

use crate::error::CliError;
use mirrorball_core::glam::DVec3;
use mirrorball_core::{
    AngularMap, DualParaboloid, Fisheye, Frame, Lens, Mercator, Projection, ProjectionKind,
    SphereMap,
};

/// A parsed `--to`/`--from` value.
#[derive(Clone, Debug, PartialEq)]
pub struct ProjSpec {
    /// The kind.
    pub kind: ProjectionKind,
    look: Option<DVec3>,
    fov: Option<f64>,
    lens: Option<Lens>,
    max_lat: Option<f64>,
}

/// Parses a direction: `+x`, `-y`, `z`, or three numbers `x,y,z`.
pub fn parse_dir(s: &str) -> Result<DVec3, String> {
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

impl ProjSpec {
    /// Parses `NAME[:key=value…]`.
    pub fn parse(s: &str) -> Result<ProjSpec, String> {
        let mut parts = s.split(':');
        let name = parts.next().unwrap_or_default();
        let kind: ProjectionKind = name
            .parse()
            .map_err(|e: mirrorball_core::UnknownProjection| e.to_string())?;
        let mut spec = ProjSpec {
            kind,
            look: None,
            fov: None,
            lens: None,
            max_lat: None,
        };
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
                "look" | "dir" | "view" => spec.look = Some(parse_dir(v)?),
                "fov" => spec.fov = Some(num(v)?),
                "lens" => {
                    spec.lens = Some(Lens::from_name(v).ok_or_else(|| {
                        format!("unknown lens '{v}' (known: equidistant, equisolid, stereographic, orthographic)")
                    })?)
                }
                "max-lat" | "maxlat" | "lat" => spec.max_lat = Some(num(v)?),
                other => return Err(format!("unknown option '{other}' in '{s}' (known: look, fov, lens, max-lat)")),
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
        if spec.look.is_some() {
            applies(
                matches!(kind, K::Sphere | K::Angular | K::Fisheye | K::Paraboloid),
                "look",
            )?;
        }
        if spec.fov.is_some() || spec.lens.is_some() {
            applies(kind == K::Fisheye, "fov/lens")?;
        }
        if spec.max_lat.is_some() {
            applies(kind == K::Mercator, "max-lat")?;
        }
        spec.build(None)?; // validate values now, before any work
        Ok(spec)
    }

    /// A spec of this kind with default parameters.
    pub fn of(kind: ProjectionKind) -> ProjSpec {
        ProjSpec {
            kind,
            look: None,
            fov: None,
            lens: None,
            max_lat: None,
        }
    }

    /// The projection. For Mercator without `max-lat`, `extent` (an input picture's size)
    /// fixes the limit from the aspect ratio.
    pub fn build(&self, extent: Option<(u32, u32)>) -> Result<Projection, String> {
        let frame = match self.look {
            Some(d) => Frame::looking_along(d).ok_or("the look direction must be non-zero")?,
            None => Frame::default(),
        };
        Ok(match self.kind {
            ProjectionKind::Sphere => SphereMap::new(frame).into(),
            ProjectionKind::Angular => AngularMap::new(frame).into(),
            ProjectionKind::Paraboloid => DualParaboloid::new(frame).into(),
            ProjectionKind::Fisheye => {
                let lens = self.lens.unwrap_or(Lens::Equidistant);
                let fov = self.fov.unwrap_or(180.0);
                Fisheye::new(frame, lens, fov)
                    .ok_or_else(|| {
                        format!(
                            "a {lens:?} fisheye covers at most {:.0}° (fov={fov} asked)",
                            2.0 * lens.max_half_fov().to_degrees()
                        )
                    })?
                    .into()
            }
            ProjectionKind::Mercator => match (self.max_lat, extent) {
                (Some(l), _) => Mercator::new(l)
                    .ok_or_else(|| format!("max-lat must be between 0 and 90 degrees, not {l}"))?
                    .into(),
                (None, Some((w, h))) => Mercator::from_extent(w, h).ok_or("empty picture")?.into(),
                (None, None) => Mercator::default().into(),
            },
            k => k.default_projection(),
        })
    }
}

/// Turns a CLI string error into a request error naming the option.
pub fn bad(option: &str, e: String) -> CliError {
    CliError::request(format!("{option}: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_names_and_options() {
        let s = ProjSpec::parse("fisheye:fov=220:lens=equisolid:look=+y").unwrap();
        assert_eq!(s.kind, ProjectionKind::Fisheye);
        assert!(ProjSpec::parse("equirect").is_ok());
        assert!(ProjSpec::parse("fisheye:fov=400:lens=stereographic").is_err());
        assert!(ProjSpec::parse("cube:fov=90")
            .unwrap_err()
            .contains("does not apply"));
        assert!(ProjSpec::parse("sphere:look=0,0,0").is_err());
        assert!(ProjSpec::parse("mercator:max-lat=95").is_err());
        assert!(ProjSpec::parse("nope").unwrap_err().contains("known"));
    }
}
