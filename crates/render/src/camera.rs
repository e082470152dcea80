//! Cameras: perspective and orthographic, in OpenGL's conventions.
//!
//! Eye space is OpenGL's: the camera sits at the origin looking along −Z with +Y up and +X to
//! the right. The view matrix is `gluLookAt(eye, target, up)`; the projection is
//! `gluPerspective(fovy, aspect, near, far)` or `glOrtho(−h·aspect, h·aspect, −h, h, near,
//! far)`, so clip and normalised device coordinates, depth included, are exactly what a
//! fixed-function pipeline computes (which the Mesa comparison relies on).
//!
//! Pixel `(x, y)` of a `w×h` image (row 0 at the top) covers NDC
//! `x_ndc ∈ [2x/w − 1, 2(x+1)/w − 1]`, `y_ndc ∈ [1 − 2(y+1)/h, 1 − 2y/h]`; its centre is at
//! half-integers, as in OpenGL's rasterisation rules.

use glam::{Mat4, Vec3, Vec4, Vec4Swizzles};

/// How the camera projects: the two projections of OpenGL's fixed-function pipeline. (A
/// fisheye picture is not a camera lens here but a captured cube resampled into the core's
/// fisheye projection, whose radial mapping is `mirrorball_core::Lens`: see
/// [`crate::render_fisheye`].)
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CameraLens {
    /// `gluPerspective` with this vertical field of view, in degrees.
    Perspective {
        /// Vertical field of view in degrees (0 < fov < 180).
        fov_y_deg: f32,
    },
    /// `glOrtho` with this half height of the view volume (the half width follows from the
    /// aspect ratio).
    Orthographic {
        /// Half the height of the view, in world units.
        half_height: f32,
    },
}

/// A camera: placement, lens, clipping planes and image size.
///
/// ```
/// use glam::Vec3;
/// use mirrorball_render::Camera;
/// let cam = Camera::perspective(Vec3::new(0.0, 1.0, 5.0), Vec3::ZERO, 60.0, 320, 240);
/// assert_eq!(cam.aspect(), 320.0 / 240.0);
/// // The ray through the picture's centre leaves the eye towards the target…
/// let (origin, centre) = cam.ray_ndc(0.0, 0.0);
/// assert_eq!(origin, cam.eye);
/// assert!((centre - (cam.target - cam.eye).normalize()).length() < 1e-6);
/// // …and the one through the middle of its top edge, half the vertical field of view above.
/// let (_, top) = cam.ray_ndc(0.0, 1.0);
/// assert!((top.angle_between(centre).to_degrees() - 30.0).abs() < 1e-3);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Where the camera is.
    pub eye: Vec3,
    /// The point it looks at.
    pub target: Vec3,
    /// Which way is up (need not be orthogonal to the view direction).
    pub up: Vec3,
    /// Perspective or orthographic.
    pub lens: CameraLens,
    /// Near clipping distance (> 0 for perspective).
    pub near: f32,
    /// Far clipping distance.
    pub far: f32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl Camera {
    /// A perspective camera at `eye` looking at `target`, +Y up, near 0.05, far 1000.
    pub fn perspective(eye: Vec3, target: Vec3, fov_y_deg: f32, width: u32, height: u32) -> Camera {
        Camera {
            eye,
            target,
            up: Vec3::Y,
            lens: CameraLens::Perspective { fov_y_deg },
            near: 0.05,
            far: 1000.0,
            width,
            height,
        }
    }

    /// An orthographic camera at `eye` looking at `target`, +Y up, showing `2·half_height`
    /// world units vertically.
    pub fn orthographic(
        eye: Vec3,
        target: Vec3,
        half_height: f32,
        width: u32,
        height: u32,
    ) -> Camera {
        Camera {
            eye,
            target,
            up: Vec3::Y,
            lens: CameraLens::Orthographic { half_height },
            near: 0.05,
            far: 1000.0,
            width,
            height,
        }
    }

    /// Checks that the camera can form an image; one that cannot is the request's fault.
    pub fn validate(&self) -> Result<(), crate::RenderError> {
        self.problem().map_err(crate::RenderError::request)
    }

    fn problem(&self) -> Result<(), String> {
        if self.width == 0 || self.height == 0 {
            return Err("the image must be at least 1x1".into());
        }
        let fwd = self.target - self.eye;
        if !fwd.is_finite() || fwd.length_squared() < 1e-20 {
            return Err("eye and target must differ".into());
        }
        if fwd.cross(self.up).length_squared() < 1e-12 * fwd.length_squared() {
            return Err("up must not be parallel to the view direction".into());
        }
        match self.lens {
            CameraLens::Perspective { fov_y_deg } => {
                if !(fov_y_deg.is_finite() && 0.0 < fov_y_deg && fov_y_deg < 180.0) {
                    return Err(format!("field of view {fov_y_deg}° is outside (0°, 180°)"));
                }
                if self.near.is_nan() || self.near <= 0.0 {
                    return Err("a perspective camera needs near > 0".into());
                }
            }
            CameraLens::Orthographic { half_height } => {
                if half_height.is_nan() || half_height <= 0.0 {
                    return Err("an orthographic camera needs a positive height".into());
                }
            }
        }
        if self.far.is_nan() || self.far <= self.near {
            return Err("far must be beyond near".into());
        }
        Ok(())
    }

    /// Width over height.
    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height as f32
    }

    /// World to eye space (`gluLookAt`).
    pub fn view(&self) -> Mat4 {
        let f = (self.target - self.eye).normalize();
        let s = f.cross(self.up).normalize();
        let u = s.cross(f);
        Mat4::from_cols(
            Vec4::new(s.x, u.x, -f.x, 0.0),
            Vec4::new(s.y, u.y, -f.y, 0.0),
            Vec4::new(s.z, u.z, -f.z, 0.0),
            Vec4::new(-s.dot(self.eye), -u.dot(self.eye), f.dot(self.eye), 1.0),
        )
    }

    /// Eye to clip space (`gluPerspective` / `glOrtho`).
    pub fn projection(&self) -> Mat4 {
        match self.lens {
            CameraLens::Perspective { fov_y_deg } => {
                let f = 1.0 / (fov_y_deg.to_radians() * 0.5).tan();
                let (n, fa) = (self.near, self.far);
                Mat4::from_cols(
                    Vec4::new(f / self.aspect(), 0.0, 0.0, 0.0),
                    Vec4::new(0.0, f, 0.0, 0.0),
                    Vec4::new(0.0, 0.0, (fa + n) / (n - fa), -1.0),
                    Vec4::new(0.0, 0.0, 2.0 * fa * n / (n - fa), 0.0),
                )
            }
            CameraLens::Orthographic { half_height } => {
                let (t, r) = (half_height, half_height * self.aspect());
                let (n, fa) = (self.near, self.far);
                Mat4::from_cols(
                    Vec4::new(1.0 / r, 0.0, 0.0, 0.0),
                    Vec4::new(0.0, 1.0 / t, 0.0, 0.0),
                    Vec4::new(0.0, 0.0, -2.0 / (fa - n), 0.0),
                    Vec4::new(0.0, 0.0, -(fa + n) / (fa - n), 1.0),
                )
            }
        }
    }

    /// `true` for a perspective camera.
    pub fn is_perspective(&self) -> bool {
        matches!(self.lens, CameraLens::Perspective { .. })
    }

    /// The primary ray through normalised device coordinates `(x, y)`: origin and unit
    /// direction, in world space.
    pub fn ray_ndc(&self, x: f32, y: f32) -> (Vec3, Vec3) {
        self.rays().ray(x, y)
    }

    /// A primary-ray generator with the per-frame work done once.
    pub fn rays(&self) -> Rays {
        let (right, up, forward) = self.basis();
        let (sx, sy) = match self.lens {
            CameraLens::Perspective { fov_y_deg } => {
                let t = (fov_y_deg.to_radians() * 0.5).tan();
                (t * self.aspect(), t)
            }
            CameraLens::Orthographic { half_height } => (half_height * self.aspect(), half_height),
        };
        Rays {
            eye: self.eye,
            right: right * sx,
            up: up * sy,
            forward,
            perspective: self.is_perspective(),
        }
    }

    /// The camera's world-space right, up and forward unit vectors (rows of the view
    /// rotation).
    pub fn basis(&self) -> (Vec3, Vec3, Vec3) {
        let v = self.view();
        let r = v.row(0).xyz();
        let u = v.row(1).xyz();
        let b = v.row(2).xyz();
        (r, u, -b)
    }

    /// The same camera panned in place by `angle` radians about its up vector (positive:
    /// to the left), as a camera rotating between two frames (Greene §9).
    pub fn panned(&self, angle: f32) -> Camera {
        let (_, up, _) = self.basis();
        let rot = glam::Quat::from_axis_angle(up, angle);
        Camera {
            target: self.eye + rot * (self.target - self.eye),
            ..*self
        }
    }

    /// The same camera turned about `target` by `angle` radians around +Y (a turntable
    /// frame: the camera orbits, the world stays).
    pub fn orbited(&self, angle: f32) -> Camera {
        let rot = Mat4::from_rotation_y(angle);
        let eye = self.target + rot.transform_vector3(self.eye - self.target);
        Camera { eye, ..*self }
    }
}

/// Primary rays of a [`Camera`], from [`Camera::rays`].
#[derive(Clone, Copy, Debug)]
pub struct Rays {
    eye: Vec3,
    /// Camera right scaled to the half width of the view at unit distance (or of the
    /// orthographic volume).
    right: Vec3,
    /// Likewise up.
    up: Vec3,
    forward: Vec3,
    perspective: bool,
}

impl Rays {
    /// Origin and unit direction of the ray through NDC `(x, y)`.
    #[inline]
    pub fn ray(&self, x: f32, y: f32) -> (Vec3, Vec3) {
        if self.perspective {
            let d = self.forward + self.right * x + self.up * y;
            (self.eye, d.normalize())
        } else {
            (self.eye + self.right * x + self.up * y, self.forward)
        }
    }

    /// For a perspective camera, the `(forward, right, up)` that [`Rays::ray`] combines
    /// into `forward + right·x + up·y` before normalising (for callers that batch rays).
    #[inline]
    pub fn perspective_parts(&self) -> Option<(Vec3, Vec3, Vec3)> {
        self.perspective
            .then_some((self.forward, self.right, self.up))
    }
}
