//! Small, exact geometric helpers the measurements share.
//!
//! * [`angle_between`]: the angle between two directions as `atan2(|a × b|, a · b)`, which
//!   keeps full relative precision for tiny angles (the `acos` of a dot product loses half
//!   the digits there, and Zimmons' per-pixel angles are as small as 0.1°).
//! * [`spherical_polygon_area`]: the solid angle of a spherical polygon whose edges are
//!   great-circle arcs, summed over a fan of triangles with Van Oosterom & Strackee's
//!   formula (IEEE Trans. Biomed. Eng. 30(2), 1983):
//!   `tan(Ω/2) = a·(b×c) / (|a||b||c| + (a·b)|c| + (a·c)|b| + (b·c)|a|)`.
//! * [`frustum_solid_angle`]: the solid angle of a rectangular pyramid with half-angles `α`,
//!   `β` at its apex, `Ω = 4 asin(sin α sin β)` (the classic closed form; derived by
//!   splitting the pyramid's spherical rectangle into four right spherical triangles).
//! * [`reflect`]: mirror reflection `r = i − 2(i·n)n` of the incident direction `i` (from
//!   the eye towards the surface) about the unit normal `n`, the OpenGL convention.

use glam::DVec3;

/// The angle, in radians, between two non-zero vectors (need not be unit length).
#[inline]
pub fn angle_between(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

// The spherical-triangle and spherical-polygon areas are core's (Van Oosterom & Strackee).
pub use mirrorball_core::quadrature::{
    polygon_solid_angle as spherical_polygon_area, triangle_solid_angle,
};

/// Solid angle of a rectangular pyramid (a camera frustum) with half-angles `alpha` and
/// `beta` (radians) at its apex: `4 asin(sin α sin β)`.
pub fn frustum_solid_angle(alpha: f64, beta: f64) -> f64 {
    4.0 * (alpha.sin() * beta.sin()).asin()
}

/// Mirror reflection of the incident direction `i` about the unit normal `n`:
/// `i − 2(i·n)n` (OpenGL's `reflect`).
#[inline]
pub fn reflect(i: DVec3, n: DVec3) -> DVec3 {
    i - 2.0 * i.dot(n) * n
}

/// Rotates `v` about the unit `axis` by `angle` radians (Rodrigues).
pub fn rotate(v: DVec3, axis: DVec3, angle: f64) -> DVec3 {
    let (s, c) = angle.sin_cos();
    v * c + axis.cross(v) * s + axis * axis.dot(v) * (1.0 - c)
}

/// Two unit vectors perpendicular to unit `d` and to each other, `(right, up)`, with
/// `right = d × hint` and `up = right × d`, where the hint is +Y (+Z when `d` is vertical):
/// a camera looking along `d` with `up` as close to +Y as possible.
pub fn basis(d: DVec3) -> (DVec3, DVec3) {
    let hint = if d.y.abs() > 1.0 - 1e-9 {
        DVec3::Z
    } else {
        DVec3::Y
    };
    let right = d.cross(hint).normalize();
    let up = right.cross(d);
    (right, up)
}
