//! The camera files photogrammetry and Gaussian-splatting tools read: a COLMAP text model
//! (`sparse/0/`: `cameras.txt`, `images.txt`, `points3D.txt`, and the rig as COLMAP 3.12
//! writes it, `rigs.txt` and `frames.txt`), COLMAP's rig configuration (`rig_config.json`,
//! as `pycolmap.read_rig_config` and `apply_rig_config` take it) and nerfstudio's
//! `transforms.json`.
//!
//! Axes (ARCHITECTURE.md's conventions):
//! - COLMAP: a camera looks down +Z, x right, y down; pixel centres at half-integers (the
//!   picture's top-left corner is (0, 0)). Its world is mirrorball's `(x, −y, −z)`: y down,
//!   z along the yaw-0 pitch-0 view, so that view's `cam_from_world` is the identity.
//! - nerfstudio: a camera looks down −Z, x right, y up (OpenGL); `transform_matrix` is
//!   camera-to-world. Its world is mirrorball's `(x, −z, y)`: z up, as `ns-process-data`
//!   makes it from a COLMAP model (`applied_transform` records that step).
//!
//! All views of one panorama share its centre: translations are 0.

use mirrorball_core::glam::{DMat3, DQuat, DVec3};
use std::fmt::Write;

/// Mirrorball's world to COLMAP's (and a mirrorball view's axes to a COLMAP camera's):
/// `diag(1, −1, −1)`, its own inverse.
const TO_COLMAP: DMat3 = DMat3::from_cols(DVec3::X, DVec3::NEG_Y, DVec3::NEG_Z);

/// Mirrorball's world to nerfstudio's: `(x, y, z) → (x, −z, y)`.
const TO_NERFSTUDIO: DMat3 = DMat3::from_cols(DVec3::X, DVec3::Z, DVec3::NEG_Y);

/// COLMAP's world to nerfstudio's, the step `ns-process-data` applies (its
/// `applied_transform`): rows `(x, z, −y)`.
const COLMAP_TO_NERFSTUDIO: DMat3 = DMat3::from_cols(DVec3::X, DVec3::NEG_Z, DVec3::Y);

/// How a camera of the rig draws: a pinhole (COLMAP's and nerfstudio's `PINHOLE`), or an
/// equidistant fisheye (`OPENCV_FISHEYE` with `k1..k4 = 0`: a pixel's distance from the
/// centre over the focal length is its angle from the axis, as core's `Fisheye` with the
/// equidistant lens draws).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Model {
    Pinhole,
    Fisheye,
}

impl Model {
    /// The model's name in COLMAP and nerfstudio.
    pub fn name(self) -> &'static str {
        match self {
            Model::Pinhole => "PINHOLE",
            Model::Fisheye => "OPENCV_FISHEYE",
        }
    }
}

/// One camera of the rig: the picture's size and intrinsics in COLMAP's pixel convention,
/// and its orientation.
#[derive(Clone, Debug)]
pub struct Camera {
    /// The view's name (its folder).
    pub name: String,
    /// How it draws.
    pub model: Model,
    /// Picture width and height.
    pub size: (u32, u32),
    /// Focal lengths in pixels.
    pub focal: (f64, f64),
    /// The principal point, pixels from the top-left corner: the picture's centre.
    pub centre: (f64, f64),
    /// The view's axes in mirrorball's world (columns: right, up, backward:
    /// `View::frame_of`).
    pub frame: DMat3,
}

impl Camera {
    /// A camera `size` pixels with fields of view `hfov`, `vfov` (degrees) aimed by
    /// `frame`: the focal length at which the picture's edges are the fields' edges.
    pub fn new(name: &str, (w, h): (u32, u32), (hfov, vfov): (f64, f64), frame: DMat3) -> Camera {
        Camera {
            name: name.to_string(),
            model: Model::Pinhole,
            size: (w, h),
            focal: (
                w as f64 / (2.0 * (0.5 * hfov.to_radians()).tan()),
                h as f64 / (2.0 * (0.5 * vfov.to_radians()).tan()),
            ),
            centre: (0.5 * w as f64, 0.5 * h as f64),
            frame,
        }
    }

    /// An equidistant fisheye `size`² pixels whose disk, the picture's inscribed circle,
    /// spans `fov` degrees, aimed by `frame`: focal length `(size/2)/θ_max`.
    pub fn fisheye(name: &str, size: u32, fov: f64, frame: DMat3) -> Camera {
        let f = 0.5 * size as f64 / (0.5 * fov.to_radians());
        Camera {
            name: name.to_string(),
            model: Model::Fisheye,
            size: (size, size),
            focal: (f, f),
            centre: (0.5 * size as f64, 0.5 * size as f64),
            frame,
        }
    }

    /// COLMAP's parameters of the camera: `fx fy cx cy`, and `k1..k4` (0) for a fisheye.
    pub fn params(&self) -> Vec<f64> {
        let mut p = vec![self.focal.0, self.focal.1, self.centre.0, self.centre.1];
        if self.model == Model::Fisheye {
            p.extend([0.0; 4]);
        }
        p
    }

    /// COLMAP's `cam_from_world` rotation (its world and camera axes).
    pub fn colmap_cam_from_world(&self) -> DMat3 {
        (TO_COLMAP * self.frame * TO_COLMAP).transpose()
    }

    /// nerfstudio's camera-to-world rotation (its world, OpenGL camera axes).
    pub fn nerfstudio_cam_to_world(&self) -> DMat3 {
        TO_NERFSTUDIO * self.frame
    }

    /// The world direction (mirrorball's axes) of the ray through pixel position `(px, py)`
    /// (COLMAP's convention: pixel `(x, y)`'s centre is `(x + ½, y + ½)`).
    pub fn ray(&self, px: f64, py: f64) -> DVec3 {
        let (x, y) = (
            (px - self.centre.0) / self.focal.0,
            (py - self.centre.1) / self.focal.1,
        );
        let cam = match self.model {
            Model::Pinhole => DVec3::new(x, y, 1.0),
            Model::Fisheye => {
                // Equidistant: the distance from the centre is the angle from the axis.
                let theta = x.hypot(y);
                let s = if theta > 0.0 {
                    theta.sin() / theta
                } else {
                    1.0
                };
                DVec3::new(x * s, y * s, theta.cos())
            }
        };
        (TO_COLMAP * self.colmap_cam_from_world().transpose() * cam).normalize()
    }
}

/// `[w, x, y, z]` of rotation `r`, `w ≥ 0`.
pub fn quaternion(r: DMat3) -> [f64; 4] {
    let q = DQuat::from_mat3(&r).normalize();
    let q = if q.w < 0.0 { -q } else { q };
    [q.w, q.x, q.y, q.z]
}

/// A number as text: the shortest that reads back to the same `f64`, `-0` as `0`.
fn num(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else {
        format!("{v}")
    }
}

/// One picture of one view: the camera (an index into the rig), its file and mask.
pub struct Shot<'a> {
    /// The camera's index in the rig.
    pub camera: usize,
    /// The picture, relative to the images folder (`front/pano.png`).
    pub name: &'a str,
    /// The mask, relative to the output folder, when one is written.
    pub mask: Option<&'a str>,
}

/// `cameras.txt`: one camera per view (PINHOLE or OPENCV_FISHEYE), ids from 1.
pub fn cameras_txt(rig: &[Camera]) -> String {
    let mut s = String::from(
        "# Camera list with one line of data per camera:\n\
         #   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n",
    );
    let _ = writeln!(s, "# Number of cameras: {}", rig.len());
    for (i, c) in rig.iter().enumerate() {
        let params: Vec<String> = c.params().into_iter().map(num).collect();
        let _ = writeln!(
            s,
            "{} {} {} {} {}",
            i + 1,
            c.model.name(),
            c.size.0,
            c.size.1,
            params.join(" ")
        );
    }
    s
}

/// `images.txt`: each shot's `cam_from_world` (translation 0), its camera and name, and an
/// empty line of 2D points; image ids from 1 in `shots`' order.
pub fn images_txt(rig: &[Camera], shots: &[Shot]) -> String {
    let mut s = String::from(
        "# Image list with two lines of data per image:\n\
         #   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n\
         #   POINTS2D[] as (X, Y, POINT3D_ID)\n",
    );
    let _ = writeln!(
        s,
        "# Number of images: {}, mean observations per image: 0",
        shots.len()
    );
    for (i, shot) in shots.iter().enumerate() {
        let q = quaternion(rig[shot.camera].colmap_cam_from_world());
        let _ = writeln!(
            s,
            "{} {} {} {} {} 0 0 0 {} {}\n",
            i + 1,
            num(q[0]),
            num(q[1]),
            num(q[2]),
            num(q[3]),
            shot.camera + 1,
            shot.name
        );
    }
    s
}

/// `points3D.txt`: no points.
pub fn points3d_txt() -> String {
    "# 3D point list with one line of data per point:\n\
     #   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n\
     # Number of points: 0, mean track length: 0\n"
        .into()
}

/// `cam_from_rig` of camera `i`: the rig's frame is camera 0's.
fn cam_from_rig(rig: &[Camera], i: usize) -> DMat3 {
    rig[i].colmap_cam_from_world() * rig[0].colmap_cam_from_world().transpose()
}

/// `rigs.txt`: one rig, camera 1 its reference sensor, each other camera's
/// `sensor_from_rig` (translation 0).
pub fn rigs_txt(rig: &[Camera]) -> String {
    let mut s = String::from(
        "# Rig calib list with one line of data per calib:\n\
         #   RIG_ID, NUM_SENSORS, REF_SENSOR_TYPE, REF_SENSOR_ID, SENSORS[] as (SENSOR_TYPE, SENSOR_ID, HAS_POSE, [QW, QX, QY, QZ, TX, TY, TZ])\n\
         # Number of rigs: 1\n",
    );
    let _ = write!(s, "1 {} CAMERA 1", rig.len());
    for i in 1..rig.len() {
        let q = quaternion(cam_from_rig(rig, i));
        let _ = write!(
            s,
            " CAMERA {} 1 {} {} {} {} 0 0 0",
            i + 1,
            num(q[0]),
            num(q[1]),
            num(q[2]),
            num(q[3])
        );
    }
    s.push('\n');
    s
}

/// `frames.txt`: one frame per panorama (`shots` in runs of the rig's length), its
/// `rig_from_world` the reference camera's `cam_from_world`, holding its images.
pub fn frames_txt(rig: &[Camera], shots: &[Shot]) -> String {
    let frames = shots.len() / rig.len().max(1);
    let mut s = String::from(
        "# Frame list with one line of data per frame:\n\
         #   FRAME_ID, RIG_ID, RIG_FROM_WORLD[QW, QX, QY, QZ, TX, TY, TZ], NUM_DATA_IDS, DATA_IDS[] as (SENSOR_TYPE, SENSOR_ID, DATA_ID)\n",
    );
    let _ = writeln!(s, "# Number of frames: {frames}");
    let q = quaternion(rig[0].colmap_cam_from_world());
    for f in 0..frames {
        let _ = write!(
            s,
            "{} 1 {} {} {} {} 0 0 0 {}",
            f + 1,
            num(q[0]),
            num(q[1]),
            num(q[2]),
            num(q[3]),
            rig.len()
        );
        for (k, shot) in shots[f * rig.len()..(f + 1) * rig.len()].iter().enumerate() {
            let _ = write!(s, " CAMERA {} {}", shot.camera + 1, f * rig.len() + k + 1);
        }
        s.push('\n');
    }
    s
}

/// `rig_config.json`: one rig, each camera's image prefix (`NAME/`), camera 0 the
/// reference sensor, the others' `cam_from_rig` rotation `[w, x, y, z]` and translation
/// 0, and each camera's model and parameters.
pub fn rig_config_json(rig: &[Camera]) -> String {
    let cameras: Vec<serde_json::Value> = rig
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let mut cam = serde_json::json!({
                "image_prefix": format!("{}/", c.name),
                "camera_model_name": c.model.name(),
                "camera_params": c.params(),
            });
            if i == 0 {
                cam["ref_sensor"] = true.into();
            } else {
                cam["ref_sensor"] = false.into();
                cam["cam_from_rig_rotation"] = quaternion(cam_from_rig(rig, i)).to_vec().into();
                cam["cam_from_rig_translation"] = vec![0.0; 3].into();
            }
            cam
        })
        .collect();
    let mut s = serde_json::to_string_pretty(&serde_json::json!([{ "cameras": cameras }]))
        .expect("plain values");
    s.push('\n');
    s
}

/// `transforms.json` for nerfstudio: per frame its camera's intrinsics (the rig's one
/// model, `PINHOLE` or `OPENCV_FISHEYE` with `k1..k4` 0), the
/// picture (`images/NAME`), its mask when written, and the camera-to-world matrix;
/// `extra` (EXIF and the like) added at the top level.
pub fn transforms_json(rig: &[Camera], shots: &[Shot], extra: Option<serde_json::Value>) -> String {
    let frames: Vec<serde_json::Value> = shots
        .iter()
        .map(|shot| {
            let c = &rig[shot.camera];
            let r = c.nerfstudio_cam_to_world();
            let row = |i: usize| {
                let v = r.row(i);
                vec![v.x, v.y, v.z, 0.0]
            };
            let mut f = serde_json::json!({
                "file_path": format!("images/{}", shot.name),
                "fl_x": c.focal.0,
                "fl_y": c.focal.1,
                "cx": c.centre.0,
                "cy": c.centre.1,
                "w": c.size.0,
                "h": c.size.1,
                "camera_model": c.model.name(),
                "transform_matrix": [row(0), row(1), row(2), [0.0, 0.0, 0.0, 1.0]],
            });
            if c.model == Model::Fisheye {
                for k in ["k1", "k2", "k3", "k4"] {
                    f[k] = 0.0.into();
                }
            }
            if let Some(m) = shot.mask {
                f["mask_path"] = m.into();
            }
            f
        })
        .collect();
    let a = COLMAP_TO_NERFSTUDIO;
    let row = |i: usize| {
        let v = a.row(i);
        vec![v.x, v.y, v.z, 0.0]
    };
    let model = rig.first().map_or(Model::Pinhole, |c| c.model);
    let mut doc = serde_json::json!({
        "camera_model": model.name(),
        "frames": frames,
        "applied_transform": [row(0), row(1), row(2)],
    });
    if let Some(extra) = extra {
        doc["mirrorball"] = extra;
    }
    let mut s = serde_json::to_string_pretty(&doc).expect("plain values");
    s.push('\n');
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorball_core::{View, WorldProjection};

    #[test]
    fn the_front_view_is_colmaps_world() {
        let c = Camera::new(
            "front",
            (64, 64),
            (90.0, 90.0),
            View::frame_of(0.0, 0.0, 0.0),
        );
        assert!(c
            .colmap_cam_from_world()
            .abs_diff_eq(DMat3::IDENTITY, 1e-15));
        assert_eq!(quaternion(c.colmap_cam_from_world()), [1.0, 0.0, 0.0, 0.0]);
        // nerfstudio's world is COLMAP's through ns-process-data's step.
        assert!(
            (COLMAP_TO_NERFSTUDIO * TO_COLMAP).abs_diff_eq(TO_NERFSTUDIO, 1e-15),
            "{}",
            COLMAP_TO_NERFSTUDIO * TO_COLMAP
        );
    }

    #[test]
    fn fisheye_rays_are_cores_equidistant_fisheye() {
        use mirrorball_core::{Fisheye, Frame, Lens};
        let m = View::frame_of(30.0, -10.0, 5.0);
        let lens = Fisheye::new(Frame::turned(m), Lens::Equidistant, 150.0).unwrap();
        let c = Camera::fisheye("f", 64, 150.0, m);
        assert_eq!(c.params().len(), 8);
        for (x, y) in [(0, 31), (31, 31), (32, 5), (50, 40), (63, 32)] {
            let uv =
                mirrorball_core::glam::DVec2::new((x as f64 + 0.5) / 64.0, (y as f64 + 0.5) / 64.0);
            let Some(d) = lens.uv_to_dir(0, uv) else {
                continue;
            };
            let r = c.ray(x as f64 + 0.5, y as f64 + 0.5);
            assert!((d - r).length() < 1e-12, "({x}, {y}): {d} {r}");
        }
    }

    #[test]
    fn rays_are_the_views_directions() {
        for (yaw, pitch, roll) in [(0.0, 0.0, 0.0), (37.0, -20.0, 15.0), (200.0, 89.0, -70.0)] {
            let (w, h) = (40u32, 30u32);
            let hfov = 100.0f64;
            let vfov = 2.0 * ((0.5 * hfov.to_radians()).tan() * h as f64 / w as f64).atan();
            let v = View::perspective(hfov, vfov.to_degrees(), yaw, pitch, roll).unwrap();
            let c = Camera::new(
                "v",
                (w, h),
                (hfov, vfov.to_degrees()),
                View::frame_of(yaw, pitch, roll),
            );
            for (x, y) in [(0, 0), (39, 29), (20, 15), (7, 22)] {
                let uv = mirrorball_core::glam::DVec2::new(
                    (x as f64 + 0.5) / w as f64,
                    (y as f64 + 0.5) / h as f64,
                );
                let d = v.uv_to_dir(0, uv).unwrap();
                let r = c.ray(x as f64 + 0.5, y as f64 + 0.5);
                assert!((d - r).length() < 1e-12, "{d} {r}");
                // nerfstudio: the OpenGL camera ray (x, −y, −1) turned to its world.
                let cam = DVec3::new(
                    (x as f64 + 0.5 - c.centre.0) / c.focal.0,
                    -(y as f64 + 0.5 - c.centre.1) / c.focal.1,
                    -1.0,
                );
                let ns = (c.nerfstudio_cam_to_world() * cam).normalize();
                assert!((ns - TO_NERFSTUDIO * d).length() < 1e-12);
            }
        }
    }
}
