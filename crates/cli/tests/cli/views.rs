//! `mirrorball views`: a panorama cut into a rig of pinhole views with COLMAP's and
//! nerfstudio's camera files. The cameras are read back as COLMAP's text model says and
//! checked against mirrorball's own projection code and against the pixels themselves (a
//! panorama whose texels hold their own direction); masks against coverage worked out here.

use crate::util::{files, ok, run, stderr};
use mirrorball_core::glam::{DMat3, DQuat, DVec2, DVec3};
use mirrorball_core::{EnvMap, ProjectionKind, View, WorldProjection};
use std::collections::HashMap;
use std::path::Path;

/// A lat-long EXR of `size`² texels per layer whose texels hold `(d + 1)/2` of their own
/// direction `d`, and its path.
fn direction_panorama(dir: &Path, size: u32) -> String {
    let ll = ProjectionKind::LatLong.default_projection();
    let env = EnvMap::from_fn(ll, size, 3, |d| {
        [
            0.5 * (d.x as f32 + 1.0),
            0.5 * (d.y as f32 + 1.0),
            0.5 * (d.z as f32 + 1.0),
            1.0,
        ]
    });
    let path = dir.join("pano.exr");
    let opts = mirrorball_io::WriteOptions {
        precision: Some(mirrorball_io::Precision::Float),
        ..Default::default()
    };
    mirrorball_io::write_image(&path, &env.layers()[0], &opts).unwrap();
    path.to_str().unwrap().to_string()
}

/// A camera of `cameras.txt`: width, height, fx, fy, cx, cy.
pub(crate) type Camera = (u32, u32, f64, f64, f64, f64);

/// An image of `images.txt`: name, camera id, `cam_from_world` rotation and translation.
pub(crate) type Posed = (String, u32, DMat3, DVec3);

/// `cameras.txt` and `images.txt` of `sparse`, read as COLMAP's text format says: cameras
/// by id, and per image name its camera id and `cam_from_world` rotation.
pub(crate) fn read_model(sparse: &Path) -> (HashMap<u32, Camera>, Vec<Posed>) {
    let text = std::fs::read_to_string(sparse.join("cameras.txt")).unwrap();
    let mut cams = HashMap::new();
    for line in text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
    {
        let f: Vec<&str> = line.split_whitespace().collect();
        assert!(["PINHOLE", "OPENCV_FISHEYE"].contains(&f[1]), "{line}");
        let n = |i: usize| f[i].parse::<f64>().unwrap();
        cams.insert(
            f[0].parse().unwrap(),
            (
                f[2].parse().unwrap(),
                f[3].parse().unwrap(),
                n(4),
                n(5),
                n(6),
                n(7),
            ),
        );
    }
    let text = std::fs::read_to_string(sparse.join("images.txt")).unwrap();
    let lines: Vec<&str> = text.lines().filter(|l| !l.starts_with('#')).collect();
    let mut images = Vec::new();
    // Two lines an image: the pose, then its 2D points (none).
    for pair in lines.chunks(2) {
        let f: Vec<&str> = pair[0].split_whitespace().collect();
        assert_eq!(f.len(), 10, "{}", pair[0]);
        let n = |i: usize| f[i].parse::<f64>().unwrap();
        let q = DQuat::from_xyzw(n(2), n(3), n(4), n(1));
        assert!((q.length() - 1.0).abs() < 1e-9);
        images.push((
            f[9].to_string(),
            f[8].parse().unwrap(),
            DMat3::from_quat(q),
            DVec3::new(n(5), n(6), n(7)),
        ));
        assert!(pair.get(1).is_none_or(|l| l.trim().is_empty()));
    }
    (cams, images)
}

/// The mirrorball world direction of COLMAP's ray through pixel position `(px, py)` of a
/// camera `cam` posed `cam_from_world`: `R^T K^-1 (px, py, 1)`, COLMAP's world being
/// mirrorball's `(x, −y, −z)`.
pub(crate) fn colmap_ray(cam: &Camera, cam_from_world: DMat3, px: f64, py: f64) -> DVec3 {
    let k_inv = DVec3::new((px - cam.4) / cam.2, (py - cam.5) / cam.3, 1.0);
    let w = cam_from_world.transpose() * k_inv;
    DVec3::new(w.x, -w.y, -w.z).normalize()
}

#[test]
fn views_cut_a_panorama_into_a_rig_with_camera_files() {
    let dir = tempfile::tempdir().unwrap();
    let pano = direction_panorama(dir.path(), 256);
    // A rig file: turned, rolled, not square, wider than high by its vfov.
    let rig = dir.path().join("rig.json");
    std::fs::write(
        &rig,
        r#"{"views": [
            {"name": "a", "yaw": 0, "pitch": 0, "fov": 90},
            {"name": "b", "yaw": 37, "pitch": -20, "roll": 15, "fov": 100, "width": 48, "height": 30},
            {"name": "c", "yaw": 200, "pitch": 80, "roll": -70, "fov": 60, "vfov": 80}
        ]}"#,
    )
    .unwrap();
    let out = dir.path().join("out");
    let out_s = out.to_str().unwrap();
    ok(&[
        "views",
        &pano,
        out_s,
        "--rig",
        rig.to_str().unwrap(),
        "--size",
        "40",
        "--format",
        "exr",
        "-q",
    ]);
    let listed = files(&out);
    for f in [
        "images/a/pano.exr",
        "images/b/pano.exr",
        "images/c/pano.exr",
        "sparse/0/cameras.txt",
        "sparse/0/images.txt",
        "sparse/0/points3D.txt",
        "sparse/0/rigs.txt",
        "sparse/0/frames.txt",
        "rig_config.json",
        "transforms.json",
    ] {
        assert!(listed.contains(&f.to_string()), "{f} missing: {listed:?}");
    }
    // A lat-long covers everything: no masks unless asked.
    assert!(!listed.iter().any(|f| f.starts_with("masks")), "{listed:?}");
    assert!(!listed.iter().any(|f| f.ends_with(".tmp")), "{listed:?}");

    let (cams, images) = read_model(&out.join("sparse/0"));
    assert_eq!(images.len(), 3);
    let text = std::fs::read_to_string(out.join("sparse/0/cameras.txt")).unwrap();
    assert_eq!(text.matches(" PINHOLE ").count(), 3, "{text}");
    // The views as the rig file gives them, through mirrorball's own projection code.
    let specs = [
        ("a", 90.0, None, 0.0, 0.0, 0.0),
        ("b", 100.0, None, 37.0, -20.0, 15.0),
        ("c", 60.0, Some(80.0), 200.0, 80.0, -70.0),
    ];
    let mut worst = 0f64;
    let mut worst_px = 0f64;
    for (name, fov, vfov, yaw, pitch, roll) in specs {
        let (image, cam_id, r, t) = images
            .iter()
            .find(|i| i.0 == format!("{name}/pano.exr"))
            .unwrap();
        assert_eq!(*t, DVec3::ZERO, "one centre");
        let cam = cams[cam_id];
        let (w, h) = (cam.0, cam.1);
        match name {
            "a" => assert_eq!((w, h), (40, 40)),
            "b" => assert_eq!((w, h), (48, 30)),
            _ => assert_eq!(w, 40),
        }
        let hfov_t = (0.5 * f64::to_radians(fov)).tan();
        let vfov: f64 =
            vfov.unwrap_or_else(|| 2.0 * (hfov_t * h as f64 / w as f64).atan().to_degrees());
        let view = View::perspective(fov, vfov, yaw, pitch, roll).unwrap();
        let picture = mirrorball_io::read(&out.join("images").join(image), &Default::default())
            .unwrap()
            .layers
            .remove(0);
        assert_eq!((picture.width(), picture.height()), (w, h));
        for y in 0..h {
            for x in 0..w {
                // COLMAP's pixel (x, y) is centred at (x + ½, y + ½).
                let ray = colmap_ray(&cam, *r, x as f64 + 0.5, y as f64 + 0.5);
                let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                let d = view.uv_to_dir(0, uv).unwrap();
                worst = worst.max(ray.angle_between(d));
                // The pixel holds its direction (as the panorama's texels, filtered).
                let p = picture.get(x, y);
                let seen = DVec3::new(
                    2.0 * p[0] as f64 - 1.0,
                    2.0 * p[1] as f64 - 1.0,
                    2.0 * p[2] as f64 - 1.0,
                );
                worst_px = worst_px.max(seen.normalize().angle_between(ray));
            }
        }
    }
    assert!(
        worst < 1e-4,
        "COLMAP's rays are {worst} rad from mirrorball's"
    );
    // A 256×128 lat-long: a texel is 0.025 rad; half of one at the poles, and far less
    // elsewhere, is what the filter and half-float pixels leave (7.4e-4 rad measured).
    assert!(
        worst_px < 3e-3,
        "the pixels hold directions {worst_px} rad from COLMAP's rays"
    );
    eprintln!("views: COLMAP rays within {worst:.2e} rad, pixels within {worst_px:.2e} rad");

    // transforms.json: nerfstudio's OpenGL cameras in its world, mirrorball's (x, −z, y).
    let t: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("transforms.json")).unwrap())
            .unwrap();
    assert_eq!(t["camera_model"], "PINHOLE");
    let frames = t["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 3);
    for f in frames {
        let path = f["file_path"].as_str().unwrap();
        let (_, cam_id, r, _) = images
            .iter()
            .find(|i| format!("images/{}", i.0) == path)
            .unwrap();
        let cam = cams[cam_id];
        let n = |k: &str| f[k].as_f64().unwrap();
        assert_eq!((n("w") as u32, n("h") as u32), (cam.0, cam.1));
        let m = &f["transform_matrix"];
        let c2w = DMat3::from_cols_array_2d(
            &[0, 1, 2].map(|c| [0, 1, 2].map(|r| m[r][c].as_f64().unwrap())),
        );
        for (px, py) in [
            (0.5, 0.5),
            (3.25, 17.5),
            (cam.0 as f64 - 0.5, cam.1 as f64 - 0.5),
        ] {
            let gl = DVec3::new(
                (px - n("cx")) / n("fl_x"),
                -(py - n("cy")) / n("fl_y"),
                -1.0,
            );
            let ns = (c2w * gl).normalize();
            let mb = DVec3::new(ns.x, ns.z, -ns.y);
            assert!(mb.angle_between(colmap_ray(&cam, *r, px, py)) < 1e-9);
        }
    }
    // rig_config.json: camera 0 the reference, the others' cam_from_rig the poses' ratio.
    let rc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("rig_config.json")).unwrap())
            .unwrap();
    let rc_cams = rc[0]["cameras"].as_array().unwrap();
    assert_eq!(rc_cams.len(), 3);
    assert_eq!(rc_cams[0]["ref_sensor"], true);
    assert_eq!(rc_cams[0]["image_prefix"], "a/");
    let ref_pose = images[0].2;
    for (i, c) in rc_cams.iter().enumerate().skip(1) {
        let q: Vec<f64> = c["cam_from_rig_rotation"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let q = DMat3::from_quat(DQuat::from_xyzw(q[1], q[2], q[3], q[0]));
        assert!((q * ref_pose).abs_diff_eq(images[i].2, 1e-9));
    }
}

#[test]
fn views_masks_are_what_a_fisheye_covers() {
    let dir = tempfile::tempdir().unwrap();
    let pano = direction_panorama(dir.path(), 64);
    let fish = dir.path().join("fish.exr");
    let fish_s = fish.to_str().unwrap();
    // The default fisheye: equidistant, 180°, looking along −Z.
    ok(&[
        "convert", &pano, fish_s, "--to", "fisheye", "--size", "128", "-q",
    ]);
    let out = dir.path().join("out");
    ok(&["views", fish_s, out.to_str().unwrap(), "--size", "32", "-q"]);
    let t: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("transforms.json")).unwrap())
            .unwrap();
    let mut seen = [0usize; 2];
    for (name, yaw, pitch) in [
        ("front", 0.0, 0.0),
        ("right", 90.0, 0.0),
        ("back", 180.0, 0.0),
        ("left", 270.0, 0.0),
        ("up", 0.0, 90.0),
        ("down", 0.0, -90.0),
    ] {
        let mask = out.join(format!("masks/{name}/fish.png.png"));
        let frame = t["frames"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["file_path"] == format!("images/{name}/fish.png"))
            .unwrap();
        assert_eq!(frame["mask_path"], format!("masks/{name}/fish.png.png"));
        // One channel, 8-bit, as nerfstudio and COLMAP read masks.
        let bytes = std::fs::read(&mask).unwrap();
        assert_eq!(&bytes[12..16], b"IHDR");
        assert_eq!((bytes[24], bytes[25]), (8, 0), "8-bit grey");
        let m = mirrorball_io::read(&mask, &Default::default())
            .unwrap()
            .layers
            .remove(0);
        let view = View::perspective(90.0, 90.0, yaw, pitch, 0.0).unwrap();
        for y in 0..32 {
            for x in 0..32 {
                let uv = DVec2::new((x as f64 + 0.5) / 32.0, (y as f64 + 0.5) / 32.0);
                let d = view.uv_to_dir(0, uv).unwrap();
                // The 180° fisheye covers the hemisphere in front: z ≤ 0.
                if d.z.abs() < 1e-6 {
                    continue;
                }
                let valid = m.get(x, y)[0] > 0.5;
                assert_eq!(valid, d.z < 0.0, "{name} ({x}, {y}): {d}");
                seen[valid as usize] += 1;
            }
        }
    }
    assert!(seen[0] > 1000 && seen[1] > 1000, "{seen:?}");
}

#[test]
fn views_user_mask_is_resampled_and_refused_at_the_wrong_size() {
    let dir = tempfile::tempdir().unwrap();
    let pano = direction_panorama(dir.path(), 64);
    // Black (invalid) below the horizon.
    let ll = ProjectionKind::LatLong.default_projection();
    let below = EnvMap::from_fn(ll, 64, 3, |d| {
        let v = if d.y < 0.0 { 0.0 } else { 1.0 };
        [v, v, v, 1.0]
    });
    let mask = dir.path().join("mask.png");
    mirrorball_io::write_image(&mask, &below.layers()[0], &Default::default()).unwrap();
    let out = dir.path().join("out");
    ok(&[
        "views",
        &pano,
        out.to_str().unwrap(),
        "--mask",
        mask.to_str().unwrap(),
        "--rig",
        "ring4",
        "--size",
        "24",
        "-q",
    ]);
    let m = mirrorball_io::read(&out.join("masks/up/pano.png.png"), &Default::default()).unwrap();
    assert!(m.layers[0].data().iter().all(|&v| v == 1.0));
    let m = mirrorball_io::read(&out.join("masks/down/pano.png.png"), &Default::default()).unwrap();
    assert!(m.layers[0].data().iter().all(|&v| v == 0.0));
    let m = mirrorball_io::read(&out.join("masks/yaw090/pano.png.png"), &Default::default())
        .unwrap()
        .layers
        .remove(0);
    assert_eq!(m.get(5, 2)[0], 1.0);
    assert_eq!(m.get(5, m.height() - 3)[0], 0.0);

    // The wrong size: refused, nothing written.
    let small = EnvMap::from_fn(ll, 32, 3, |_| [1.0; 4]);
    let wrong = dir.path().join("small.png");
    mirrorball_io::write_image(&wrong, &small.layers()[0], &Default::default()).unwrap();
    let out2 = dir.path().join("out2");
    let o = run(&[
        "views",
        &pano,
        out2.to_str().unwrap(),
        "--mask",
        wrong.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("the same size"), "{}", stderr(&o));
    assert!(!out2.exists());
}

#[test]
fn views_bad_requests_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let pano = direction_panorama(dir.path(), 32);
    let out = dir.path().join("out");
    let out_s = out.to_str().unwrap();
    let rig = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let wide = rig("wide.json", r#"{"views": [{"name": "a", "fov": 180}]}"#);
    let unknown = rig(
        "unknown.json",
        r#"{"views": [{"name": "a", "fov": 90, "zoom": 2}]}"#,
    );
    let twice = rig(
        "twice.json",
        r#"{"views": [{"name": "a", "fov": 90}, {"name": "a", "yaw": 90, "fov": 90}]}"#,
    );
    let huge = rig(
        "huge.json",
        r#"{"views": [{"name": "a", "fov": 90, "width": 99999999}]}"#,
    );
    let cases: [(&[&str], &str, i32); 8] = [
        (&["--rig", &wide], "(0°, 180°)", 2),
        (&["--rig", &unknown], "unknown field `zoom`", 1),
        (&["--rig", &twice], "given twice", 1),
        (&["--rig", &huge], "outside 1..=", 2),
        (&["--size", "0"], "--size 0: outside 1..=", 2),
        (&["--size", "64x9999999"], "outside 1..=", 2),
        (&["--rig", "ring99"], "3 to 36", 2),
        (&["--rig", "sphere"], "cube, cube-96, ringN", 2),
    ];
    for (args, message, code) in cases {
        let mut a = vec!["views", pano.as_str(), out_s];
        a.extend_from_slice(args);
        let o = run(&a);
        assert_eq!(o.status.code(), Some(code), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(message), "{args:?}: {}", stderr(&o));
        assert!(!out.exists(), "{args:?} wrote {out:?}");
    }
    // OUT-DIR a file.
    let file = dir.path().join("a-file");
    std::fs::write(&file, "x").unwrap();
    let o = run(&["views", &pano, file.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("OUT-DIR is a file"), "{}", stderr(&o));
    assert_eq!(std::fs::read(&file).unwrap(), b"x");
    // A rig preset's help comes from the table.
    let help = crate::util::stdout(&run(&["views", "--help"]));
    for p in mirrorball::views::PRESETS {
        assert!(
            help.contains(p.name) && help.contains(&p.about[..20]),
            "{help}"
        );
    }
}

#[test]
fn views_of_a_sequence_share_one_rig() {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("seq");
    std::fs::create_dir(&seq).unwrap();
    let ll = ProjectionKind::LatLong.default_projection();
    for (n, size) in [(1, 32), (2, 32), (3, 16)] {
        let env = EnvMap::from_fn(ll, size, 3, |d| {
            [d.x.abs() as f32 * n as f32, 0.5, 0.5, 1.0]
        });
        let path = seq.join(format!("frame_{n:04}.exr"));
        mirrorball_io::write_image(&path, &env.layers()[0], &Default::default()).unwrap();
    }
    // The third frame is smaller: refused when reached, nothing written.
    let pattern = seq.join("frame_%04d.exr");
    let out = dir.path().join("out");
    let o = run(&[
        "views",
        pattern.to_str().unwrap(),
        out.to_str().unwrap(),
        "--size",
        "8",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("frame_0003.exr"), "{}", stderr(&o));
    assert!(!out.exists(), "{:?}", files(&out));
    std::fs::remove_file(seq.join("frame_0003.exr")).unwrap();
    ok(&[
        "views",
        pattern.to_str().unwrap(),
        out.to_str().unwrap(),
        "--size",
        "8",
        "-q",
    ]);
    let listed = files(&out);
    for view in ["front", "right", "back", "left", "up", "down"] {
        for n in [1, 2] {
            let f = format!("images/{view}/frame_{n:04}.png");
            assert!(listed.contains(&f), "{f}: {listed:?}");
        }
    }
    let (cams, images) = read_model(&out.join("sparse/0"));
    assert_eq!((cams.len(), images.len()), (6, 12));
    // Frame 2's images: the same cameras and poses as frame 1's.
    for i in 0..6 {
        assert_eq!(images[i].1, images[i + 6].1);
        assert_eq!(images[i].2, images[i + 6].2);
        assert!(images[i + 6].0.ends_with("frame_0002.png"));
    }
    let frames = std::fs::read_to_string(out.join("sparse/0/frames.txt")).unwrap();
    let lines: Vec<&str> = frames.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(lines.len(), 2);
    assert!(lines[1].ends_with("CAMERA 6 12"), "{}", lines[1]);
}

#[test]
fn views_fisheye_rigs_are_opencv_fisheye_cameras() {
    let dir = tempfile::tempdir().unwrap();
    let pano = direction_panorama(dir.path(), 256);
    let rig = dir.path().join("rig.json");
    std::fs::write(
        &rig,
        r#"{"views": [
            {"name": "f", "model": "fisheye", "fov": 170},
            {"name": "b", "model": "fisheye", "yaw": 180, "pitch": 10, "roll": 20, "fov": 120, "width": 48}
        ]}"#,
    )
    .unwrap();
    let out = dir.path().join("out");
    ok(&[
        "views",
        &pano,
        out.to_str().unwrap(),
        "--rig",
        rig.to_str().unwrap(),
        "--size",
        "64",
        "--format",
        "exr",
        "-q",
    ]);
    let cameras = std::fs::read_to_string(out.join("sparse/0/cameras.txt")).unwrap();
    let lines: Vec<&str> = cameras.lines().filter(|l| !l.starts_with('#')).collect();
    let (_, images) = read_model(&out.join("sparse/0"));
    let mut worst = 0f64;
    for (line, (name, _, r, _)) in lines.iter().zip(&images) {
        let f: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(&f[1..4], ["OPENCV_FISHEYE", f[2], f[2]], "square: {line}");
        assert_eq!(&f[8..], ["0", "0", "0", "0"]);
        let n = |i: usize| f[i].parse::<f64>().unwrap();
        let (w, fx, fy, cx, cy) = (n(2) as u32, n(4), n(5), n(6), n(7));
        let picture = mirrorball_io::read(&out.join("images").join(name), &Default::default())
            .unwrap()
            .layers
            .remove(0);
        for y in 0..w {
            for x in 0..w {
                // OpenCV's fisheye with k = 0: the distance from the centre is θ.
                let (a, b) = ((x as f64 + 0.5 - cx) / fx, (y as f64 + 0.5 - cy) / fy);
                let theta = a.hypot(b);
                // Outside the disk (masked), or within a pixel of its rim, where the
                // picture's filter reaches outside.
                let rim = (x as f64 + 0.5 - cx).hypot(y as f64 + 0.5 - cy);
                if rim > 0.5 * w as f64 - 1.0 {
                    continue;
                }
                let s = if theta > 0.0 {
                    theta.sin() / theta
                } else {
                    1.0
                };
                let cam = DVec3::new(a * s, b * s, theta.cos());
                let wc = r.transpose() * cam;
                let ray = DVec3::new(wc.x, -wc.y, -wc.z);
                let p = picture.get(x, y);
                let seen = DVec3::new(
                    2.0 * p[0] as f64 - 1.0,
                    2.0 * p[1] as f64 - 1.0,
                    2.0 * p[2] as f64 - 1.0,
                );
                worst = worst.max(seen.normalize().angle_between(ray));
            }
        }
    }
    assert!(
        worst < 3e-3,
        "fisheye pixels are {worst} rad from OpenCV's fisheye rays"
    );
    eprintln!("views: fisheye pixels within {worst:.2e} rad of OpenCV's fisheye rays");
    // The disk's outside is masked in every view.
    let m = mirrorball_io::read(&out.join("masks/f/pano.exr.png"), &Default::default()).unwrap();
    let m = &m.layers[0];
    assert_eq!((m.get(0, 0)[0], m.get(32, 32)[0]), (0.0, 1.0));
    let t: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("transforms.json")).unwrap())
            .unwrap();
    assert_eq!(t["camera_model"], "OPENCV_FISHEYE");
    assert_eq!(t["frames"][0]["k4"], 0.0);
    // Mixed models, or a fisheye given a height: refused.
    let mixed = dir.path().join("mixed.json");
    std::fs::write(
        &mixed,
        r#"{"views": [{"name": "a", "fov": 90}, {"name": "b", "model": "fisheye", "fov": 170}]}"#,
    )
    .unwrap();
    let o = run(&[
        "views",
        &pano,
        dir.path().join("o2").to_str().unwrap(),
        "--rig",
        mixed.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("all pinhole or all fisheye"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn views_rerun_replaces_only_what_mirrorball_wrote() {
    let dir = tempfile::tempdir().unwrap();
    let pano = direction_panorama(dir.path(), 64);
    let out = dir.path().join("out");
    let o = out.to_str().unwrap();
    ok(&["views", &pano, o, "--size", "8", "-q"]);
    let first = files(&out);
    assert!(
        first.contains(&"images/up/pano.png".to_string()),
        "{first:?}"
    );
    assert!(
        first.contains(&mirrorball_io::RECORD.to_string()),
        "{first:?}"
    );
    // The user's own files, beside and among the views.
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    std::fs::write(out.join("images/up/mine.png"), "mine too").unwrap();
    // A rig of four views: the up and down views the first run wrote are removed (and the
    // down view's folder, left empty), the user's files stay.
    let rig = dir.path().join("ring.json");
    std::fs::write(
        &rig,
        r#"{"views": [{"name": "front", "fov": 90}, {"name": "right", "yaw": 90, "fov": 90},
                       {"name": "back", "yaw": 180, "fov": 90}, {"name": "left", "yaw": 270, "fov": 90}]}"#,
    )
    .unwrap();
    let said = run(&[
        "views",
        &pano,
        o,
        "--size",
        "8",
        "--rig",
        rig.to_str().unwrap(),
    ]);
    assert!(said.status.success(), "{}", stderr(&said));
    assert!(
        stderr(&said).contains("removed 2 files an earlier run wrote"),
        "{}",
        stderr(&said)
    );
    let second = files(&out);
    for gone in ["images/up/pano.png", "images/down/pano.png", "images/down/"] {
        assert!(!second.contains(&gone.to_string()), "{gone}: {second:?}");
    }
    for kept in ["notes.txt", "images/up/mine.png", "images/left/pano.png"] {
        assert!(second.contains(&kept.to_string()), "{kept}: {second:?}");
    }
    assert_eq!(std::fs::read(out.join("notes.txt")).unwrap(), b"mine");
    let (cams, images) = read_model(&out.join("sparse/0"));
    assert_eq!((cams.len(), images.len()), (4, 4));
    // A file of the user's where a view would land: refused before any work, nothing
    // changed; --overwrite replaces it.
    let other = dir.path().join("other");
    std::fs::create_dir_all(other.join("images/front")).unwrap();
    std::fs::write(other.join("images/front/pano.png"), "the user's").unwrap();
    let refused = run(&["views", &pano, other.to_str().unwrap(), "--size", "8"]);
    assert_eq!(refused.status.code(), Some(2), "{}", stderr(&refused));
    let e = stderr(&refused);
    assert!(
        e.contains("images/front/pano.png") && e.contains("--overwrite"),
        "{e}"
    );
    assert_eq!(
        files(&other),
        ["images/", "images/front/", "images/front/pano.png"]
    );
    ok(&[
        "views",
        &pano,
        other.to_str().unwrap(),
        "--size",
        "8",
        "--overwrite",
        "-q",
    ]);
    assert_ne!(
        std::fs::read(other.join("images/front/pano.png")).unwrap(),
        b"the user's"
    );
}

#[test]
fn views_of_8_and_16_bit_pictures_are_the_views_of_their_floats() {
    // An 8-bit PNG and a 16-bit PNG are read as their codes (no float copy); the same
    // texels as a float EXR are read as floats: every view file is the same bytes.
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (96u32, 48u32);
    let mut img = mirrorball_core::Image::new(w, h, 3);
    for y in 0..h {
        for x in 0..w {
            let k = (x * 7 + y * 13) as f32;
            img.set(x, y, &[(k * 0.37).sin().abs(), (k * 0.11).cos().abs(), 0.5]);
        }
    }
    for (precision, format) in [
        (mirrorball_io::Precision::U8, "png"),
        (mirrorball_io::Precision::U8, "jpg"),
        (mirrorball_io::Precision::U16, "png16"),
    ] {
        let png = dir.path().join(format!("pano{format}.png"));
        let opts = mirrorball_io::WriteOptions {
            precision: Some(precision),
            ..Default::default()
        };
        mirrorball_io::write_image(&png, &img, &opts).unwrap();
        // The PNG's texels, decoded as io reads them, in a float EXR.
        let decoded = mirrorball_io::read(&png, &Default::default()).unwrap();
        let exr = dir.path().join(format!("pano{format}.exr"));
        let float = mirrorball_io::WriteOptions {
            precision: Some(mirrorball_io::Precision::Float),
            ..Default::default()
        };
        mirrorball_io::write_image(&exr, &decoded.layers[0], &float).unwrap();
        let mut made = Vec::new();
        for (src, name) in [(&png, "codes"), (&exr, "floats")] {
            let out = dir.path().join(format!("{format}-{name}"));
            ok(&[
                "views",
                src.to_str().unwrap(),
                out.to_str().unwrap(),
                "--size",
                "20",
                "--format",
                format,
            ]);
            made.push(out);
        }
        let ext = if format == "jpg" { "jpg" } else { "png" };
        for view in ["front", "right", "back", "left", "up", "down"] {
            let [a, b] = [0, 1].map(|i| {
                let file = made[i]
                    .join("images")
                    .join(view)
                    .join(format!("pano{format}.{ext}"));
                std::fs::read(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()))
            });
            assert!(
                a == b,
                "{format} {view}: the codes' view differs from the floats'"
            );
        }
    }
}
