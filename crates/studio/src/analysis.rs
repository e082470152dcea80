//! The analysis panel's payload (`GET /api/analysis`): the projection of the map the page
//! shows, measured and drawn by the analysis crate exactly as `mirrorball analyze` measures
//! and draws each projection (`analyze_projection`: texel statistics, Zimmons' profile, the
//! solid-angle, anisotropy and 1-D figures as SVG), and the share of that map's texels, and
//! of the sphere, that the page's camera frustum sees: what a background drawn through this
//! camera reads (Greene §9).

use mirrorball_analysis::frustum::{texel_sum, Frustum};
use mirrorball_analysis::geom::frustum_solid_angle;
use mirrorball_analysis::texels::{size_for_budget, texel_count};
use mirrorball_analysis::{analyze_projection, Config};
use mirrorball_core::glam::DVec3;
use mirrorball_core::Projection;
use serde_json::{json, Value};
use std::collections::HashMap;
use std::f64::consts::PI;

/// Texels measured when the page names no size: `mirrorball analyze`'s default budget.
pub const DEFAULT_BUDGET: u64 = 6 * 512 * 512;
/// The most texels one request measures (about 10 s for the slowest projections).
pub const MAX_TEXELS: u64 = 6 * 1024 * 1024;
/// The frustum's texels are counted at no more than this many (the report's brute force).
const FRUSTUM_TEXELS: u64 = 6 * 256 * 256;

/// The page's camera: its frame in the world and its frustum.
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    right: DVec3,
    up: DVec3,
    forward: DVec3,
    frustum: Frustum,
}

impl Camera {
    /// From `fov` (vertical, degrees; 45), `aspect` (width / height; 4/3), `forward`
    /// (0,0,-1) and `up` (0,1,0) of the query.
    /// A value the query cannot give is the request's fault.
    pub fn from_query(q: &HashMap<String, String>) -> Result<Camera, crate::Error> {
        Camera::from_query_text(q).map_err(crate::Error::request)
    }

    fn from_query_text(q: &HashMap<String, String>) -> Result<Camera, String> {
        let num = |k: &str, default: f64| -> Result<f64, String> {
            match q.get(k) {
                None => Ok(default),
                Some(s) => s
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| format!("{k}: '{s}' is not a number")),
            }
        };
        let vec = |k: &str, default: DVec3| -> Result<DVec3, String> {
            let Some(s) = q.get(k) else {
                return Ok(default);
            };
            let v: Vec<f64> = s
                .split(',')
                .map(|c| c.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| format!("{k}: '{s}' is not X,Y,Z"))?;
            match v[..] {
                [x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => {
                    Ok(DVec3::new(x, y, z))
                }
                _ => Err(format!("{k}: '{s}' is not X,Y,Z")),
            }
        };
        let fov = num("fov", 45.0)?;
        if !(fov > 0.0 && fov < 180.0) {
            return Err(format!("fov: {fov} is outside (0, 180) degrees"));
        }
        let aspect = num("aspect", 4.0 / 3.0)?;
        if !(aspect > 0.0 && aspect <= 100.0) {
            return Err(format!("aspect: {aspect} is outside (0, 100]"));
        }
        let forward = vec("forward", DVec3::NEG_Z)?
            .try_normalize()
            .ok_or("forward: the zero vector has no direction")?;
        let right = forward
            .cross(vec("up", DVec3::Y)?)
            .try_normalize()
            .ok_or("up: parallel to forward (or zero)")?;
        Ok(Camera {
            right,
            up: right.cross(forward),
            forward,
            frustum: Frustum {
                aspect,
                vertical_fov_deg: fov,
            },
        })
    }

    /// Whether world direction `d` is inside the frustum.
    fn sees(&self, d: DVec3) -> bool {
        let local = DVec3::new(d.dot(self.right), d.dot(self.up), -d.dot(self.forward));
        self.frustum.contains(local)
    }
}

/// The edge to measure `p` at: `size` when given (its texels at most [`MAX_TEXELS`]), else
/// the edge of [`DEFAULT_BUDGET`] texels. A size it cannot take is the request's fault.
pub fn size_of(p: &Projection, size: Option<&str>) -> Result<u32, crate::Error> {
    size_text(p, size).map_err(crate::Error::request)
}

fn size_text(p: &Projection, size: Option<&str>) -> Result<u32, String> {
    let Some(s) = size else {
        return Ok(size_for_budget(p, DEFAULT_BUDGET));
    };
    let n = s
        .parse::<u32>()
        .ok()
        .filter(|n| (1..=65536).contains(n))
        .ok_or_else(|| format!("size: '{s}' is not an edge of 1..=65536 texels"))?;
    let t = texel_count(p, n);
    if t > MAX_TEXELS {
        return Err(format!(
            "size {n}: {t} texels of {}, over the {MAX_TEXELS} one request measures",
            p.name()
        ));
    }
    Ok(n)
}

/// The panel's JSON: `projection`, `size`, `entry` (the report's entry of the projection:
/// `stats`, `profile`, `cone`), `figures` (`id`, `title`, `caption`, `svg` each) and
/// `frustum` (the camera's: its fields of view, the texels whose centre it sees at `size`,
/// of how many, their solid angle, and its closed-form share of the sphere).
pub fn encode(p: &Projection, size: u32, camera: &Camera) -> Value {
    let (entry, figures) = analyze_projection(p, size, Config::default().drawing_budget);
    let fs = size_for_budget(p, texel_count(p, size).min(FRUSTUM_TEXELS));
    let (seen, solid_angle) = texel_sum(p, fs, |d| camera.sees(d));
    let of = texel_count(p, fs);
    let (alpha, beta) = camera.frustum.half_angles();
    json!({
        "projection": p.name(),
        "size": size,
        "entry": entry,
        "figures": figures
            .iter()
            .map(|f| json!({ "id": f.id, "title": f.title, "caption": f.caption, "svg": f.svg }))
            .collect::<Vec<_>>(),
        "frustum": {
            "vertical_fov_deg": camera.frustum.vertical_fov_deg,
            "horizontal_fov_deg": (2.0 * alpha).to_degrees(),
            "aspect": camera.frustum.aspect,
            "size": fs,
            "texels": seen,
            "of": of,
            "texel_share": seen as f64 / of as f64,
            "solid_angle": solid_angle,
            "sphere_share": frustum_solid_angle(alpha, beta) / (4.0 * PI),
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorball_core::ProjectionKind;

    fn query(pairs: &[(&str, &str)]) -> HashMap<String, String> {
        pairs
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect()
    }

    #[test]
    fn the_frustum_is_the_cameras_and_bad_numbers_are_refused() {
        let cube = ProjectionKind::Cube.default_projection();
        // A 90°×90° camera looking down +X sees exactly the +X face: a sixth of the texels
        // and of the sphere.
        let cam = Camera::from_query(&query(&[
            ("fov", "90"),
            ("aspect", "1"),
            ("forward", "1,0,0"),
        ]))
        .unwrap();
        let j = encode(&cube, 16, &cam);
        let f = &j["frustum"];
        assert_eq!(f["texels"], 16 * 16);
        assert_eq!(f["of"], 6 * 16 * 16);
        assert!((f["solid_angle"].as_f64().unwrap() - 4.0 * PI / 6.0).abs() < 1e-9);
        assert!((f["sphere_share"].as_f64().unwrap() - 1.0 / 6.0).abs() < 1e-12);
        assert_eq!(j["entry"]["stats"]["size"], 16);
        let ids: Vec<&str> = j["figures"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f["id"].as_str().unwrap())
            .collect();
        assert_eq!(
            ids,
            [
                "analysis-solid-angle-heatmaps",
                "analysis-anisotropy-heatmaps",
                "analysis-zimmons-1d"
            ]
        );
        for (k, v, why) in [
            ("fov", "180", "outside"),
            ("fov", "nan", "not a number"),
            ("aspect", "0", "outside"),
            ("forward", "0,0,0", "zero"),
            ("forward", "1,2", "X,Y,Z"),
            ("up", "0,0,-2", "parallel"),
        ] {
            let e = Camera::from_query(&query(&[(k, v)])).unwrap_err();
            assert!(
                e.message.contains(why) && e.fault == mirrorball_core::Fault::Request,
                "{k}={v}: {e}"
            );
        }
        assert_eq!(size_of(&cube, None).unwrap(), 512);
        assert!(size_of(&cube, Some("2048"))
            .unwrap_err()
            .message
            .contains("over"));
        assert!(size_of(&cube, Some("0")).is_err());
    }
}
