//! Environments made rather than photographed.
//!
//! **Phong highlights by sphere mapping** (Zimmons; the trick of fixed-function hardware):
//! the specular term of a light at `L` seen in the mirror direction `r` is
//! `k_s (r·L)ⁿ` (Phong's model written with the reflected eye vector), a function of `r`
//! alone. Storing it in a sphere map — attached to the eye, in eye coordinates as
//! `GL_SPHERE_MAP` indexes — turns per-pixel highlights into one texture lookup, with every
//! artifact of the indexing mode used (highlights that slide along chords at low
//! tessellation under mode 1).

use glam::DVec3;
use mirrorball_core::{EnvMap, Frame, Projection, SphereMap};

/// A sphere map (eye frame: looking along −Z, +Y up) of Phong intensities
/// `colour · max(0, r·L)ⁿ` for a light in eye-space direction `light` (towards the light),
/// `size × size` texels. Use it eye-attached, with a mirror material, and add the result to
/// a diffuse rendering.
pub fn phong_sphere_map(light: DVec3, exponent: f64, colour: [f32; 3], size: u32) -> EnvMap {
    let l = light.try_normalize().unwrap_or(DVec3::Z);
    EnvMap::from_fn(
        Projection::Sphere(SphereMap::new(Frame::default())),
        size,
        3,
        move |r| {
            let k = r.dot(l).max(0.0).powf(exponent) as f32;
            [colour[0] * k, colour[1] * k, colour[2] * k, 1.0]
        },
    )
}
