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
            if p.extension().is_some_and(|x| x == "json" || x == "toml") {
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

/// A constant lat-long environment of `value`, written as EXR into `dir`.
fn constant_env(dir: &Path, value: f32) -> std::path::PathBuf {
    let mut img = mirrorball_core::Image::new(64, 32, 3);
    for y in 0..32 {
        for x in 0..64 {
            img.set(x, y, &[value; 3]);
        }
    }
    let p = dir.join("constant.exr");
    mirrorball_io::write_image(&p, &img, &Default::default()).unwrap();
    p
}

fn exr(p: &Path) -> mirrorball_core::Image {
    mirrorball_io::read(p, &Default::default()).unwrap().layers[0].clone()
}

#[test]
fn render_toml_and_json_scenes_render_identically() {
    let dir = tempfile::tempdir().unwrap();
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    let (a, b) = (dir.path().join("json.exr"), dir.path().join("toml.exr"));
    for (scene, out) in [("chrome-pair.json", &a), ("chrome-pair.toml", &b)] {
        let s = examples.join(scene);
        ok(&[
            "render",
            s.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "-q",
        ]);
    }
    let (ia, ib) = (exr(&a), exr(&b));
    assert_eq!((ia.width(), ia.height()), (480, 270));
    assert_eq!(ia.data(), ib.data(), "the TOML and JSON scenes differ");
    // And the picture is not empty: both objects and the background are there.
    assert!(ia.data().iter().any(|&v| v > 0.05));
}

#[test]
fn render_bad_toml_scene_names_the_file_and_the_place() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    let bad = dir.path().join("broken-scene.toml");
    std::fs::write(&bad, "indexing = \"pixel\"\n[camera\neye = [0, 0, 3]\n").unwrap();
    let r = run(&["render", bad.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(!r.status.success());
    let msg = stderr(&r);
    assert!(msg.contains("broken-scene.toml"), "{msg}");
    assert!(msg.contains("TOML") && msg.contains("line 2"), "{msg}");
    // A well-formed file with an unknown key names the key.
    let typo = dir.path().join("typo.toml");
    std::fs::write(&typo, "indexng = \"pixel\"\n").unwrap();
    let r = run(&[
        "render",
        typo.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    let msg = stderr(&r);
    assert!(!r.status.success());
    assert!(
        msg.contains("typo.toml") && msg.contains("indexng"),
        "{msg}"
    );
    assert!(!out.exists());
}

/// The careless user's `render … out.png`: the picture's name lands where the scene file
/// goes. The message says it was read as a scene file and where the output goes; nothing
/// is written, and the exit status is an input's (1).
#[test]
fn an_output_name_given_as_the_scene_says_how_to_name_the_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("mirror-ball.png");
    let env = asset("venice.exr");
    let r = run(&[
        "render",
        "--env",
        env.to_str().unwrap(),
        out.to_str().unwrap(),
    ]);
    let msg = stderr(&r);
    assert_eq!(r.status.code(), Some(1), "{msg}");
    assert!(
        msg.contains("mirror-ball.png")
            && msg.contains("scene file")
            && msg.contains("-o/--output"),
        "{msg}"
    );
    assert!(!out.exists());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    // A scene file that is missing is named as such, with no hint about pictures.
    let missing = dir.path().join("scene.json");
    let r = run(&["render", missing.to_str().unwrap()]);
    let msg = stderr(&r);
    assert!(
        msg.contains("scene.json: cannot read the scene file") && !msg.contains("-o/"),
        "{msg}"
    );
}

#[test]
fn render_greene_material_from_the_command_line_and_a_scene() {
    let dir = tempfile::tempdir().unwrap();
    let env = constant_env(dir.path(), 0.5);
    let out = dir.path().join("g.exr");
    // On a constant environment L, dc·D + sc·S = (dc + sc)·L whatever the lobe and mode.
    for (spec, mode, filter) in [
        ("greene:dc=0.2,0.1,0.3:sc=0.6:phong=40", "pixel", "bilinear"),
        ("greene:dc=0.2,0.1,0.3:sc=0.6:ggx=0.5", "cone", "ewa"),
        ("greene:dc=0.2,0.1,0.3:sc=0.6", "texgen", "trilinear"),
    ] {
        ok(&[
            "render",
            "--env",
            env.to_str().unwrap(),
            "--from",
            "latlong",
            "--material",
            spec,
            "--mode",
            mode,
            "--filter",
            filter,
            "--no-background",
            "--size",
            "24x24",
            "-o",
            out.to_str().unwrap(),
            "-q",
        ]);
        let img = exr(&out);
        let mut n = 0;
        for p in img.data().chunks_exact(4).filter(|p| p[3] > 0.999) {
            n += 1;
            for (k, want) in [0.4f32, 0.35, 0.45].into_iter().enumerate() {
                // Half-float EXR: a little over 1e-3 relative.
                assert!(
                    (p[k] - want).abs() < 0.01 * want,
                    "{spec}: {} vs {want}",
                    p[k]
                );
            }
        }
        assert!(n > 100, "{spec}: {n} pixels");
    }
    // The same from a JSON scene.
    let scene = dir.path().join("g.json");
    std::fs::write(
        &scene,
        format!(
            r#"{{"environment": {{"file": "{}", "projection": "latlong", "filter": "trilinear"}},
  "material": {{"kind": "greene", "dc": [0.2, 0.1, 0.3], "sc": [0.6, 0.6, 0.6], "lobe": "ggx", "roughness": 0.2}},
  "camera": {{"eye": [0, 0, 3.5], "target": [0, 0, 0], "fov": 40, "width": 24, "height": 24}},
  "background": false}}"#,
            env.display()
        ),
    )
    .unwrap();
    ok(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "-q",
    ]);
    let img = exr(&out);
    let p = img.get(12, 12);
    assert!(
        (p[0] - 0.4).abs() < 0.004 && (p[1] - 0.35).abs() < 0.0035,
        "{p:?}"
    );
}

#[test]
fn render_phong_map_material_needs_no_environment_and_puts_the_highlight_at_the_light() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("p.exr");
    ok(&[
        "render",
        "--material",
        "phong-map:exponent=50:light=0,0,1:specular=1,1,1:ambient=0",
        "--tint",
        "0.2,0.2,0.2",
        "--tessellation",
        "128",
        "--ss",
        "1",
        "--no-background",
        "--ortho",
        "1",
        "--size",
        "33x33",
        "-o",
        out.to_str().unwrap(),
        "-q",
    ]);
    let img = exr(&out);
    // The headlight meets the mirror direction at the centre: 0.2·1 + 1.
    let c = img.get(16, 16)[0];
    assert!((c - 1.2).abs() < 0.03, "centre {c}");
    // Halfway to the limb (n·l ≈ 0.87, r·l = 2(n·l)² − 1 = 0.5, 0.5⁵⁰ ≈ 0): diffuse only.
    let side = img.get(16 + 8, 16)[0];
    assert!((side - 0.2 * 0.866).abs() < 0.02, "side {side}");
}

#[test]
fn render_bad_material_and_filter_specs_say_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    let o = out.to_str().unwrap();
    let env = asset("city.exr");
    let e = env.to_str().unwrap();
    for (material, needle) in [
        ("greene:ggx=2", "roughness"),
        ("greene:phong=-1", "exponent"),
        ("greene:lobe=blinn", "blinn"),
        ("mirror:dc=1", "does not apply"),
        ("greene:shiny=1", "unknown key"),
        ("phong-map:light=0,0,0", "light"),
        ("greene:dc=1,2", "r,g,b"),
    ] {
        let r = run(&["render", "--env", e, "--material", material, "-o", o]);
        assert!(!r.status.success(), "{material}");
        let msg = stderr(&r);
        assert!(
            msg.contains("--material") && msg.contains(needle),
            "{material}: {msg}"
        );
    }
    let r = run(&["render", "--env", e, "--filter", "cubic", "-o", o]);
    assert!(!r.status.success());
    assert!(stderr(&r).contains("trilinear or ewa"));
    assert!(!out.exists());
}

/// A flag given on the command line wins over the scene file; the scene's other values
/// stay (its camera size and samples, its indexing mode, when no flag names them).
#[test]
fn flags_on_the_command_line_win_over_the_scene_file() {
    let dir = tempfile::tempdir().unwrap();
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/scenes/greene-trio.toml");
    let out = dir.path().join("trio.png");
    let e = crate::util::ok(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--size",
        "64x36",
        "--ss",
        "2",
        "--mode",
        "pixel",
    ]);
    assert!(
        e.contains("64x36") && e.contains("2x2 samples") && e.contains("mode pixel"),
        "{e}"
    );
    let img = mirrorball_io::read(&out, &Default::default()).unwrap();
    assert_eq!((img.layers[0].width(), img.layers[0].height()), (64, 36));
    // Without the flags, the scene's own values.
    let e = crate::util::ok(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        e.contains("320x180") && e.contains("1x1 samples") && e.contains("mode cone"),
        "{e}"
    );
}

/// The README's render examples run as written, from the repository's root, each writing
/// its picture; the trio's is the figure beside it (`docs/img/render-materials.png`).
#[test]
fn the_readmes_render_examples_make_the_pictures_beside_them() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let section = readme
        .split("## Rendering")
        .nth(1)
        .and_then(|s| s.split("```sh").nth(1))
        .and_then(|s| s.split("```").next())
        .expect("the README's render block");
    let dir = tempfile::tempdir().unwrap();
    let mut made = std::collections::HashMap::new();
    for line in section
        .lines()
        .filter(|l| l.starts_with("mirrorball render"))
    {
        let command = line.split("  #").next().unwrap();
        let mut args: Vec<String> = command
            .split_whitespace()
            .skip(1)
            .map(String::from)
            .collect();
        let at = args.iter().position(|a| a == "-o").expect("-o") + 1;
        let name = args[at].clone();
        let out = dir.path().join(&name);
        args[at] = out.display().to_string();
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_mirrorball"))
            .args(&args)
            .current_dir(&root)
            .output()
            .unwrap();
        assert!(o.status.success(), "{line}: {}", stderr(&o));
        assert!(out.exists(), "{line}: no {name}");
        made.insert(name, out);
    }
    assert_eq!(made.len(), 5, "{made:?}");
    // Pictures as 8-bit sRGB codes, compared: the share of channels more than 2 codes
    // apart, and the mean difference.
    let codes = |p: &Path| mirrorball_io::read(p, &Default::default()).unwrap().layers[0].clone();
    let compare = |ours: &mirrorball_core::Image, fig: &mirrorball_core::Image, x0: u32| {
        let (mut far, mut sum, mut n) = (0u64, 0f64, 0u64);
        for y in 0..ours.height() {
            for x in 0..ours.width() {
                let (a, b) = (ours.get(x, y), fig.get(x0 + x, y));
                for c in 0..3 {
                    let code =
                        |v: f32| (mirrorball_core::color::linear_to_srgb(v as f64) * 255.0).round();
                    let d = (code(a[c]) - code(b[c])).abs();
                    far += u64::from(d > 2.0);
                    sum += d;
                    n += 1;
                }
            }
        }
        (far as f64 / n as f64, sum / n as f64)
    };
    let trio = codes(&made["trio.png"]);
    let figure = codes(&root.join("docs/img/render-materials.png"));
    assert_eq!(
        (trio.width(), trio.height()),
        (figure.width(), figure.height())
    );
    let (far, mean) = compare(&trio, &figure, 0);
    assert!(
        far < 0.03 && mean < 0.5,
        "trio: {far} of channels over 2 codes apart, mean {mean}"
    );
}
