//! The materials that read maps made from (or beside) the environment: Greene's
//! `dc·D + sc·S` and Zimmons' Phong highlights from a sphere map. What each material needs is
//! made once per render preparation ([`MaterialMaps::new`]); Greene's maps come from the
//! environment's [`crate::EnvCache`], so they are built once per environment.

use crate::lookup::GreeneMaps;
use crate::scene::{Environment, Material};
use glam::{DVec3, Mat3, Mat4, Vec3};
use mirrorball_core::{EnvMap, SphereMap};

/// Texels along the side of a Phong-intensity sphere map.
pub const PHONG_MAP_SIZE: u32 = 256;

/// What a material reads besides the environment itself.
// Made once a scene; its maps' projections (up to a dual fisheye's few hundred bytes) make
// the variants differ in size, which costs nothing here.
#[allow(clippy::large_enum_variant)]
pub(crate) enum MaterialMaps {
    /// Nothing.
    None,
    /// Greene's diffuse and specular maps.
    Greene(GreeneMaps),
    /// The eye-attached sphere map of Phong intensities.
    Phong(EnvMap),
}

impl MaterialMaps {
    /// Prepares `m`'s maps (Greene's from `env`'s cache).
    pub(crate) fn new(m: &Material, env: Option<&Environment>) -> MaterialMaps {
        match (m, env) {
            (Material::Greene { lobe, .. }, Some(e)) => {
                MaterialMaps::Greene(e.cache.greene(&e.map, *lobe))
            }
            (
                Material::PhongMap {
                    specular,
                    exponent,
                    light,
                    ..
                },
                _,
            ) => MaterialMaps::Phong(crate::maps::phong_sphere_map(
                Vec3::from_array(*light).as_dvec3(),
                *exponent as f64,
                *specular,
                PHONG_MAP_SIZE,
            )),
            _ => MaterialMaps::None,
        }
    }
}

/// Bilinear lookup of `map` in direction `d`, and the `(u, v, layer)` read.
#[inline]
fn read(map: &EnvMap, d: Vec3) -> ([f32; 3], [f32; 3]) {
    match crate::fast::dir_to_uv(map, d) {
        Some((l, u, v)) => (crate::fast::bilinear(map, l, u, v), [u, v, l as f32]),
        None => ([0.0; 3], [0.0, 0.0, -1.0]),
    }
}

/// Greene's reflected colour `dc·D(n) + sc·S(r)` (`k = [dc, sc]`; `n`, `r` attached unit
/// environment directions); `uv`: mode 1's interpolated texture coordinates of a
/// single-layer map, where `S` is read instead of at `r`. Returns the colour and the
/// `(u, v, layer)` of the specular read.
pub(crate) fn greene(
    maps: &GreeneMaps,
    k: [[f32; 3]; 2],
    n: Vec3,
    r: Vec3,
    uv: Option<Vec3>,
) -> ([f32; 3], [f32; 3]) {
    let (d, _) = read(&maps.diffuse, n);
    let (s, st) = match uv {
        Some(g) if g.x.is_finite() && g.y.is_finite() => (
            crate::fast::bilinear(&maps.specular, 0, g.x, g.y),
            [g.x, g.y, 0.0],
        ),
        Some(_) => ([0.0; 3], [0.0, 0.0, -1.0]),
        None => read(&maps.specular, r),
    };
    let [dc, sc] = k;
    ([0, 1, 2].map(|c| dc[c] * d[c] + sc[c] * s[c]), st)
}

/// The highlight read from the Phong-intensity sphere map: at mode 1's interpolated
/// `(s, 1 − t)` when given, else at the eye-space reflected vector `r_eye`. Returns the
/// colour and the `(u, v)` read.
pub(crate) fn phong_highlight(map: &EnvMap, r_eye: Vec3, st: Option<Vec3>) -> ([f32; 3], [f32; 2]) {
    let (u, v) = match st {
        Some(g) => (g.x, g.y),
        None => match crate::fast::dir_to_uv(map, r_eye) {
            Some((_, u, v)) => (u, v),
            None => return ([0.0; 3], [0.0; 2]),
        },
    };
    if !(u.is_finite() && v.is_finite()) {
        return ([0.0; 3], [0.0; 2]);
    }
    (crate::fast::bilinear(map, 0, u, v), [u, v])
}

/// Mode 1 for the Phong-intensity map: per world-space vertex `pos` with normal `nrm`, the
/// `GL_SPHERE_MAP` coordinates in eye space (`view`: world → eye), as `(s, 1 − t, 0)`.
pub(crate) fn eye_sphere_texgen(pos: &[Vec3], nrm: &[Vec3], view: &Mat4) -> Vec<Vec3> {
    let rot = Mat3::from_mat4(*view);
    pos.iter()
        .zip(nrm)
        .map(|(&q, &n)| {
            let u = view.transform_point3(q).normalize_or_zero();
            let ne = (rot * n).normalize_or_zero();
            let r = u - 2.0 * ne.dot(u) * ne;
            let st = SphereMap::gl_st(DVec3::new(r.x as f64, r.y as f64, r.z as f64));
            Vec3::new(st.x as f32, (1.0 - st.y) as f32, 0.0)
        })
        .collect()
}
