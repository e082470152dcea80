//! `mirrorball render` as a user runs it.
use crate::util::{asset, ok, run, stderr};
use std::path::Path;

fn mesh_asset(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/meshes")
        .join(name)
}

#[test]
fn renders_png_exr_and_the_diagnostic_channels() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ball.png");
    let env = asset("venice.exr");
    let log = ok(&[
        "render",
        "--env",
        env.to_str().unwrap(),
        "--size",
        "40x30",
        "--ss",
        "2",
        "--aovs",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(log.contains("wrote"), "{log}");
    let png = mirrorball_io::read(&out, &Default::default()).unwrap();
    assert_eq!((png.layers[0].width(), png.layers[0].height()), (40, 30));
    for tag in ["st", "reflect", "normal", "depth"] {
        let p = dir.path().join(format!("ball-{tag}.exr"));
        let l = mirrorball_io::read(&p, &Default::default()).unwrap();
        assert_eq!(l.layers[0].width(), 40, "{tag}");
    }
    // The centre pixel of the depth channel: the unit sphere seen from 3.5 is 2.5 away.
    let d = mirrorball_io::read(&dir.path().join("ball-depth.exr"), &Default::default()).unwrap();
    let c = d.layers[0].get(20, 15);
    assert!((c[0] - 2.5).abs() < 0.02, "eye depth {}", c[0]);
    assert!((c[2] - 1.0).abs() < 1e-6, "coverage {}", c[2]);

    // The texture-space diagram.
    let diag = dir.path().join("door.png");
    ok(&[
        "render",
        "--object",
        "quad",
        "--env",
        env.to_str().unwrap(),
        "--env-as",
        "sphere",
        "--env-size",
        "64",
        "--attach",
        "eye",
        "--mode",
        "texgen",
        "--size",
        "24x24",
        "--diagnostics",
        "-o",
        diag.to_str().unwrap(),
        "-q",
    ]);
    let d = mirrorball_io::read(&dir.path().join("door-diag.png"), &Default::default()).unwrap();
    assert_eq!(d.layers[0].width(), 512);
    assert!(
        !dir.path().join("door-st.exr").exists(),
        "AOVs only with --aovs"
    );

    let exr = dir.path().join("ball.exr");
    ok(&[
        "render",
        "--env",
        env.to_str().unwrap(),
        "--size",
        "16x16",
        "--mode",
        "texgen",
        "--env-as",
        "sphere",
        "--env-size",
        "64",
        "--attach",
        "eye",
        "-o",
        exr.to_str().unwrap(),
        "-q",
    ]);
    assert!(exr.exists());
}

#[test]
fn every_mode_object_and_material_renders() {
    let dir = tempfile::tempdir().unwrap();
    let env = asset("city.exr");
    let blurred = dir.path().join("pan.png");
    ok(&[
        "render",
        "--env",
        env.to_str().unwrap(),
        "--size",
        "24x16",
        "--pan-blur",
        "-15",
        "-o",
        blurred.to_str().unwrap(),
        "-q",
    ]);
    assert!(blurred.exists());
    for (obj, mode, material) in [
        ("teapot", "1", "mirror"),
        ("torus", "2", "fresnel"),
        ("cube", "3", "cheap-chrome"),
        ("quad", "4", "mirror"),
        (mesh_asset("bunny.obj").to_str().unwrap(), "cone", "diffuse"),
    ] {
        let out = dir.path().join("x.png");
        ok(&[
            "render",
            "--object",
            obj,
            "--mode",
            mode,
            "--material",
            material,
            "--env",
            env.to_str().unwrap(),
            "--size",
            "24x24",
            "--tessellation",
            "3",
            "-o",
            out.to_str().unwrap(),
            "-q",
        ]);
        assert!(out.exists(), "{obj} {mode} {material}");
        std::fs::remove_file(&out).unwrap();
    }
}

#[test]
fn fisheye_camera_renders_a_square_image_circle() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("dome.png");
    ok(&[
        "render",
        "--object",
        "teapot",
        "--tessellation",
        "2",
        "--env",
        asset("venice.exr").to_str().unwrap(),
        "--fisheye",
        "180",
        "--size",
        "32x32",
        "-o",
        out.to_str().unwrap(),
        "-q",
    ]);
    let img = mirrorball_io::read(&out, &Default::default())
        .unwrap()
        .layers
        .remove(0);
    assert_eq!((img.width(), img.height()), (32, 32));
    assert_eq!(&img.get(0, 0)[..3], &[0.0, 0.0, 0.0]);
    let r = run(&[
        "render",
        "--env",
        asset("venice.exr").to_str().unwrap(),
        "--fisheye",
        "200",
        "--fisheye-lens",
        "orthographic",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        !r.status.success() && stderr(&r).contains("--fisheye"),
        "{}",
        stderr(&r)
    );
}

#[test]
fn turntable_writes_numbered_frames() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("spin.png");
    ok(&[
        "render",
        "--material",
        "cheap-chrome",
        "--no-background",
        "--object",
        "teapot",
        "--tessellation",
        "2",
        "--size",
        "16x16",
        "--turntable",
        "3",
        "-o",
        out.to_str().unwrap(),
    ]);
    for i in 0..3 {
        assert!(dir.path().join(format!("spin-{i:04}.png")).exists());
    }
    // The animated PNG: an acTL chunk saying three frames.
    let apng = std::fs::read(dir.path().join("spin-turntable.png")).unwrap();
    let at = apng
        .windows(4)
        .position(|w| w == b"acTL")
        .expect("an animated PNG");
    assert_eq!(
        u32::from_be_bytes(apng[at + 4..at + 8].try_into().unwrap()),
        3
    );
    // Every file is complete (nothing half-written left).
    assert!(crate::util::files(dir.path())
        .iter()
        .all(|f| !f.ends_with(".partial")));
}

#[test]
fn scene_file_sets_meshes_camera_and_environment() {
    let dir = tempfile::tempdir().unwrap();
    let env = asset("venice.exr");
    let scene = format!(
        r#"{{
  "meshes": [
    {{"mesh": "sphere", "tessellation": 24,
      "model": [0.5,0,0,0, 0,0.5,0,0, 0,0,0.5,0, -0.6,0,0,1]}},
    {{"mesh": "teapot", "tessellation": 3,
      "model": [0.5,0,0,0, 0,0.5,0,0, 0,0,0.5,0, 0.6,0,0,1],
      "material": {{"kind": "fresnel", "tint": [0.8, 0.1, 0.1]}}}}
  ],
  "camera": {{"eye": [0, 0.5, 3], "target": [0, 0, 0], "fov": 35, "width": 32, "height": 20}},
  "environment": {{"file": "{}", "projection": "latlong", "attach": "world", "filter": "bilinear"}},
  "indexing": "pixel",
  "supersample": 1
}}"#,
        env.display()
    );
    let sf = dir.path().join("scene.json");
    std::fs::write(&sf, scene).unwrap();
    let out = dir.path().join("s.png");
    ok(&["render", sf.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    let l = mirrorball_io::read(&out, &Default::default()).unwrap();
    assert_eq!((l.layers[0].width(), l.layers[0].height()), (32, 20));

    // The example scenes in the repository parse and render.
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    if let Ok(rd) = std::fs::read_dir(&examples) {
        for e in rd {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "json") {
                let o = dir.path().join("ex.png");
                ok(&[
                    "render",
                    p.to_str().unwrap(),
                    "-o",
                    o.to_str().unwrap(),
                    "--size",
                    "24x16",
                    "-q",
                ]);
            }
        }
    }
}

#[test]
fn bad_requests_say_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    let o = out.to_str().unwrap();
    let env = asset("city.exr");
    let e = env.to_str().unwrap();
    for (args, needle) in [
        (vec!["render", "-o", o], "--env"),
        (vec!["render", "--env", e, "--mode", "7", "-o", o], "--mode"),
        (
            vec!["render", "--env", e, "--size", "0x10", "-o", o],
            "--size",
        ),
        (
            vec!["render", "--env", e, "--object", "dodecahedron", "-o", o],
            "--object",
        ),
        (
            vec!["render", "--env", e, "--fov", "190", "-o", o],
            "field of view",
        ),
        (
            vec!["render", "--env", e, "--eye", "0,0,0", "-o", o],
            "eye and target",
        ),
        (vec!["render", "--env", e, "-o", "x.ktx2"], "--output"),
        (
            vec!["render", "--env", e, "--material", "gold", "-o", o],
            "material",
        ),
        (
            vec!["render", "/nonexistent/scene.json", "-o", o],
            "scene.json",
        ),
    ] {
        let r = run(&args);
        assert!(!r.status.success(), "{args:?}");
        let msg = stderr(&r);
        assert!(msg.contains(needle), "{args:?}: {msg}");
    }
    assert!(!out.exists());
}
