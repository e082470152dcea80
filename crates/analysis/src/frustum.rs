//! How much of the sphere a camera frustum sees (Greene 1986, §9: "a viewing pyramid with a
//! 3:4 aspect ratio and a 45 degree vertical view angle subtends only about six percent of
//! the world").
//!
//! A frustum with half-angles `α` (horizontal) and `β` (vertical) cuts the unit sphere in a
//! spherical rectangle of area `Ω = 4 asin(sin α sin β)`. We compute it three ways: that
//! closed form; the spherical polygon through the four corner directions (Van Oosterom &
//! Strackee); and by brute force on a projection, summing the exact solid angles of the
//! texels whose centres lie inside the frustum (which converges as the texel size shrinks,
//! so it checks the projection's texel solid angles too).

use crate::geom::{frustum_solid_angle, spherical_polygon_area};
use glam::{DVec2, DVec3};
use mirrorball_core::{Projection, WorldProjection};
use rayon::prelude::*;
use serde::Serialize;
use std::f64::consts::PI;

/// A camera frustum looking along −Z with +Y up.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Frustum {
    /// Picture width : height, as `width / height` (Greene's 3:4 picture is 4/3 wide).
    pub aspect: f64,
    /// Vertical field of view, degrees.
    pub vertical_fov_deg: f64,
}

impl Frustum {
    /// Greene's example: 3:4 (height:width), 45° vertical.
    pub const GREENE: Frustum = Frustum {
        aspect: 4.0 / 3.0,
        vertical_fov_deg: 45.0,
    };

    /// Half-angles `(α, β)`, radians: `tan α = aspect · tan β`.
    pub fn half_angles(&self) -> (f64, f64) {
        let beta = 0.5 * self.vertical_fov_deg.to_radians();
        ((self.aspect * beta.tan()).atan(), beta)
    }

    /// Whether unit direction `d` is inside.
    pub fn contains(&self, d: DVec3) -> bool {
        let (a, b) = self.half_angles();
        let z = -d.z;
        z > 0.0 && d.x.abs() <= a.tan() * z && d.y.abs() <= b.tan() * z
    }

    /// The four corner directions, counter-clockwise seen from the camera.
    pub fn corners(&self) -> [DVec3; 4] {
        let (a, b) = self.half_angles();
        let (ta, tb) = (a.tan(), b.tan());
        [
            DVec3::new(ta, tb, -1.0),
            DVec3::new(-ta, tb, -1.0),
            DVec3::new(-ta, -tb, -1.0),
            DVec3::new(ta, -tb, -1.0),
        ]
    }
}

/// The frustum's share measured on one projection.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BruteForce {
    /// Projection name.
    pub projection: String,
    /// Edge size.
    pub size: u32,
    /// Texels whose centre is inside.
    pub texels: u64,
    /// Their summed solid angle, sr.
    pub solid_angle: f64,
    /// Relative difference from the closed form.
    pub relative_error: f64,
}

/// The frustum's solid angle, three ways.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FrustumShare {
    /// The frustum.
    pub frustum: Frustum,
    /// Horizontal field of view, degrees.
    pub horizontal_fov_deg: f64,
    /// `4 asin(sin α sin β)`, sr.
    pub closed_form: f64,
    /// The spherical polygon through the corners, sr.
    pub polygon: f64,
    /// `closed_form / 4π`.
    pub share: f64,
    /// Brute-force sums on projections.
    pub brute_force: Vec<BruteForce>,
}

/// Sums the solid angles of the texels of `p` (edge `size`) whose centre `inside` accepts.
pub fn texel_sum<F>(p: &Projection, size: u32, inside: F) -> (u64, f64)
where
    F: Fn(DVec3) -> bool + Sync,
{
    let (w, h) = p.layer_extent(size);
    let rows: Vec<(usize, u32)> = (0..p.layer_count())
        .flat_map(|l| (0..h).map(move |y| (l, y)))
        .collect();
    let per_row = rows.par_iter().map(|&(l, y)| {
        let v = (y as f64 + 0.5) / h as f64;
        let mut n = 0;
        let mut s = 0.0;
        for x in 0..w {
            let uv = DVec2::new((x as f64 + 0.5) / w as f64, v);
            if p.uv_to_dir(l, uv).is_some_and(&inside) {
                n += 1;
                s += p.texel_solid_angle(l, x, y, w, h);
            }
        }
        (n, s)
    });
    mirrorball_core::par::fold_in_order(per_row, (0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1))
}

/// Measures `frustum` in closed form, as a polygon, and on each of `on` (projection, size).
///
/// ```
/// use mirrorball_analysis::frustum::{frustum_share, Frustum};
/// use mirrorball_core::ProjectionKind;
/// // A square 90° frustum is one cube face: a sixth of the sphere, and on a cube map
/// // exactly the texels of the −Z face.
/// let face = Frustum { aspect: 1.0, vertical_fov_deg: 90.0 };
/// let m = frustum_share(face, &[(ProjectionKind::Cube.default_projection(), 64)]);
/// assert!((m.share - 1.0 / 6.0).abs() < 1e-12);
/// assert_eq!(m.brute_force[0].texels, 64 * 64);
/// assert!(m.brute_force[0].relative_error < 1e-12);
/// ```
pub fn frustum_share(frustum: Frustum, on: &[(Projection, u32)]) -> FrustumShare {
    let (a, b) = frustum.half_angles();
    let closed_form = frustum_solid_angle(a, b);
    let polygon = spherical_polygon_area(&frustum.corners());
    let brute_force = on
        .iter()
        .map(|(p, size)| {
            let (texels, solid_angle) = texel_sum(p, *size, |d| frustum.contains(d));
            BruteForce {
                projection: p.name().to_string(),
                size: *size,
                texels,
                solid_angle,
                relative_error: solid_angle / closed_form - 1.0,
            }
        })
        .collect();
    FrustumShare {
        frustum,
        horizontal_fov_deg: 2.0 * a.to_degrees(),
        closed_form,
        polygon,
        share: closed_form / (4.0 * PI),
        brute_force,
    }
}
