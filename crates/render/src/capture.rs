//! Scenes into world projections (Greene 1986, §4): a scene rendered from a point as six
//! 90° views makes a cube map, which `mirrorball_core::resample` turns into any other
//! projection. Dynamic reflection follows: capture the scene at an object's centre, without
//! that object, then render the object reflecting the capture.
//!
//! The limit, which the docs show: a capture is an environment *at infinity* seen from one
//! point. The object cannot reflect itself (it is left out of its own capture: from inside
//! it, it would hide everything), and nearby objects are reflected without parallax, as if
//! they were seen from the object's centre whatever the point of the surface.
//!
//! Faces are not assumed to match a camera's picture (OpenGL's cube faces are mirrored
//! relative to one, see ARCHITECTURE.md): each face texel's direction comes from
//! `CubeMap::uv_to_dir` and is projected into the 90° view that was rendered, so the result
//! follows the core's conventions by construction.

use crate::camera::{Camera, CameraLens};
use crate::render::{render, RenderError};
use crate::scene::{Scene, Settings};
use glam::{DVec2, Vec3, Vec4};
use mirrorball_core::{CubeFace, CubeMap, EnvMap, Image, Projection, WorldProjection};

/// Renders `scene` from `centre` into a cube map with `face`-texel faces, leaving out the
/// object with index `exclude`. `settings` gives the indexing mode and supersampling used for
/// the views (diagnostic channels are not made).
///
/// ```
/// use glam::{DVec3, Vec3};
/// use mirrorball_core::{EnvMap, ProjectionKind};
/// use mirrorball_render::{capture_cube, Environment, Scene, Settings};
/// // With no objects, the captured cube is the environment resampled into a cube.
/// let latlong = ProjectionKind::LatLong.default_projection();
/// let env = EnvMap::from_fn(latlong, 64, 3, |d| {
///     [0.5 + 0.5 * d.x as f32, 0.5 + 0.5 * d.y as f32, 0.5 + 0.5 * d.z as f32, 1.0]
/// });
/// let scene = Scene { objects: vec![], environment: Some(Environment::new(env.clone())), background: true };
/// let cube = capture_cube(&scene, Vec3::ZERO, 16, None, &Settings::default()).unwrap();
/// assert_eq!(cube.layers().len(), 6);
/// for d in [DVec3::X, DVec3::NEG_Y, DVec3::new(1.0, 1.0, -1.0).normalize()] {
///     let (a, b) = (cube.sample(d), env.sample(d));
///     assert!((0..3).all(|i| (a[i] - b[i]).abs() < 0.02), "{d}: {a:?} {b:?}");
/// }
/// ```
pub fn capture_cube(
    scene: &Scene,
    centre: Vec3,
    face: u32,
    exclude: Option<usize>,
    settings: &Settings,
) -> Result<EnvMap, RenderError> {
    if face == 0 {
        return Err(RenderError::request(
            "the cube's faces need at least one texel",
        ));
    }
    let mut s = scene.clone();
    if let Some(k) = exclude {
        if k >= s.objects.len() {
            return Err(RenderError::request(format!("no object {k} to leave out")));
        }
        s.objects.remove(k);
    }
    let settings = Settings {
        aovs: false,
        ..*settings
    };
    // Render a little more than 90° so that every texel centre projects inside the view.
    let n = face + 2;
    let fov = 2.0 * ((n as f32 / face as f32).atan()).to_degrees();
    let mut layers = Vec::with_capacity(6);
    for f in CubeFace::ALL {
        let fwd = f.point(0.0, 0.0).as_vec3();
        let up = if fwd.y.abs() > 0.5 { Vec3::Z } else { Vec3::Y };
        let cam = Camera {
            eye: centre,
            target: centre + fwd,
            up,
            lens: CameraLens::Perspective { fov_y_deg: fov },
            near: 1e-3,
            far: 1e4,
            width: n,
            height: n,
        };
        let view = render(&s, &cam, &settings)?;
        let vp = cam.projection() * cam.view();
        let mut img = Image::new(face, face, 3);
        for y in 0..face {
            for x in 0..face {
                let uv = DVec2::new(
                    (x as f64 + 0.5) / face as f64,
                    (y as f64 + 0.5) / face as f64,
                );
                let d = CubeMap
                    .uv_to_dir(f as usize, uv)
                    .expect("inside a face")
                    .as_vec3();
                let c: Vec4 = vp * (centre + d).extend(1.0);
                let px = ((c.x / c.w + 1.0) * 0.5 * n as f32 - 0.5).round();
                let py = ((1.0 - c.y / c.w) * 0.5 * n as f32 - 0.5).round();
                let (px, py) = (
                    (px as i64).clamp(0, n as i64 - 1) as u32,
                    (py as i64).clamp(0, n as i64 - 1) as u32,
                );
                let t = view.color.get(px, py);
                img.set(x, y, &t[..3]);
            }
        }
        layers.push(img);
    }
    EnvMap::new(Projection::Cube(CubeMap), layers).map_err(|e| RenderError::system(e.to_string()))
}

/// Greene's Omnimax frames (§10): the scene is captured as a cube map at the eye and the
/// cube resampled (antialiased, by `mirrorball_core::resample`) into a fisheye picture of
/// `size × size` looking from `eye` towards `target` with `up` as the picture's up, through
/// `lens` with a full field of view of `fov_deg` (up to 360° for the equidistant and
/// equisolid lenses). `face` is the cube's face size; about `size / 2` keeps detail.
#[allow(clippy::too_many_arguments)]
pub fn render_fisheye(
    scene: &Scene,
    eye: Vec3,
    target: Vec3,
    up: Vec3,
    lens: mirrorball_core::Lens,
    fov_deg: f64,
    size: u32,
    face: u32,
    settings: &Settings,
) -> Result<Image, RenderError> {
    let f = (target - eye).as_dvec3();
    let fwd = f
        .try_normalize()
        .ok_or_else(|| RenderError::request("eye and target must differ"))?;
    let right = fwd
        .cross(up.as_dvec3())
        .try_normalize()
        .ok_or_else(|| RenderError::request("up must not be parallel to the view direction"))?;
    let frame = mirrorball_core::Frame {
        right,
        up: right.cross(fwd),
        forward: fwd,
    };
    lens.fov_range()
        .check("the fisheye's fov", fov_deg)
        .map_err(|e| RenderError::request(format!("{e} (the {} lens)", lens.name())))?;
    let fish = mirrorball_core::Fisheye::new(frame, lens, fov_deg).ok_or_else(|| {
        RenderError::request(format!("fov={fov_deg}: no {} fisheye", lens.name()))
    })?;
    let cube = capture_cube(scene, eye, face, None, settings)?;
    let out = mirrorball_core::resample(
        &cube,
        Projection::Fisheye(fish),
        size,
        &mirrorball_core::ResampleOptions::default(),
    );
    // Black outside the image circle (the projection fills it from the rim for filtering).
    let mut img = out.into_layers().remove(0);
    let (w, h) = (img.width(), img.height());
    let c = img.channels();
    for y in 0..h {
        for x in 0..w {
            let a = 2.0 * (x as f64 + 0.5) / w as f64 - 1.0;
            let b = 1.0 - 2.0 * (y as f64 + 0.5) / h as f64;
            if a * a + b * b > 1.0 {
                img.set(x, y, &[0.0; 4][..c]);
            }
        }
    }
    Ok(img)
}
