//! Named choices: every value `--help` lists is accepted, scene files accept the same names
//! as the flags, and failures exit with the status of whose fault they are.

use crate::util::{run, stderr};

/// Each flag of `command`'s `--help` that lists possible values, with them.
fn listed(command: &str) -> Vec<(String, Vec<String>)> {
    let o = run(&[command, "--help"]);
    assert!(o.status.success());
    let help = String::from_utf8_lossy(&o.stdout).into_owned();
    let mut out = Vec::new();
    // A flag's help is on its line, or on the lines below it when the flag is long.
    let mut flag = String::new();
    for line in help.lines() {
        if line.trim_start().starts_with('-') {
            flag = line
                .split_whitespace()
                .find(|w| w.starts_with("--"))
                .expect("a long flag")
                .trim_end_matches(',')
                .to_string();
        }
        let Some((_, values)) = line.split_once("[possible values: ") else {
            continue;
        };
        let flag = flag.clone();
        let values = values.trim_end_matches(']');
        out.push((flag, values.split(", ").map(str::to_string).collect()));
    }
    out
}

/// Runs a command that fails after its plan (its input is missing) and asserts that `flag`
/// was not what it refused.
fn accepted(args: &[&str], flag: &str, value: &str) {
    let o = run(args);
    let e = stderr(&o);
    assert!(
        !e.contains(&format!("{flag}:")) && !e.contains(&format!("'{value}' is not")),
        "{flag} {value}: {e}"
    );
}

#[test]
fn every_value_the_help_lists_is_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.exr");
    let missing = missing.to_str().unwrap();
    let out = |ext: &str| dir.path().join(format!("out.{ext}"));
    let mut seen = 0;
    for command in ["convert", "render", "prefilter"] {
        for (flag, values) in listed(command) {
            assert!(!values.is_empty(), "{command} {flag}");
            for v in &values {
                let o = out(if command == "render" { "png" } else { "ktx2" });
                let o = o.to_str().unwrap();
                let mut args: Vec<&str> = match command {
                    "convert" => vec!["convert", missing, o, "--to", "cube"],
                    "render" => vec!["render", "--env", missing, "-o", o],
                    // --lobe is required, and given once.
                    _ if flag == "--lobe" => vec!["prefilter", missing, o],
                    _ => vec!["prefilter", missing, o, "--lobe", "ggx"],
                };
                if flag == "--fisheye-lens" {
                    args.extend(["--fisheye", "90"]);
                }
                args.extend([flag.as_str(), v.as_str()]);
                accepted(&args, &flag, v);
                seen += 1;
            }
        }
    }
    // Layouts (three times), precisions (twice), compressions, modes, attachments,
    // filters, lenses, tone curves, irradiance methods.
    assert!(seen >= 5 * 3 + 4 * 2 + 6 + 4 + 2 + 4 + 4 + 3 + 2, "{seen}");
}

/// A folder with the paths the tests name: an input that is missing (so that a run that
/// gets past its plan fails reading it), an output and a scene file.
struct Paths {
    _dir: tempfile::TempDir,
    missing: String,
    out: String,
    scene: String,
}

impl Paths {
    fn new(out_ext: &str) -> Paths {
        let dir = tempfile::tempdir().unwrap();
        let path = |name: &str| dir.path().join(name).to_str().unwrap().replace('\\', "/");
        Paths {
            missing: path("missing.exr"),
            out: path(&format!("out.{out_ext}")),
            scene: path("scene.json"),
            _dir: dir,
        }
    }
}

/// A run refused as the request's fault, saying `text`.
fn refused(args: &[&str], text: &str) {
    let o = run(args);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains(text), "{}", stderr(&o));
}

/// The help of `command`'s `flag`, from its line to the next flag's.
fn help_of(command: &str, flag: &str) -> String {
    let o = run(&[command, "--help"]);
    let help = String::from_utf8_lossy(&o.stdout).into_owned();
    let start = help
        .find(&format!("      {flag} "))
        .expect("the flag's help");
    let rest = &help[start + flag.len() + 6..];
    let end = rest.find("\n      -").unwrap_or(rest.len());
    rest[..end].split_whitespace().collect::<Vec<_>>().join(" ")
}

#[test]
fn every_lobe_name_is_accepted_and_the_help_lists_the_canonical_ones() {
    let p = Paths::new("ktx2");
    let (missing, out) = (p.missing.as_str(), p.out.as_str());
    let help: std::collections::HashMap<String, Vec<String>> =
        listed("prefilter").into_iter().collect();
    assert_eq!(help["--lobe"], ["lambert", "phong", "ggx"]);
    for name in [
        "lambert",
        "diffuse",
        "irradiance",
        "phong",
        "ggx",
        "specular",
        "trowbridge-reitz",
        "GGX",
        "Lambert",
    ] {
        let o = run(&["prefilter", missing, out, "--lobe", name]);
        let e = stderr(&o);
        assert!(
            e.contains("missing.exr") && !e.contains("--lobe"),
            "{name}: {e}"
        );
    }
    refused(
        &["prefilter", missing, out, "--lobe", "Beckmann"],
        "--lobe: unknown 'beckmann' (lambert, phong, ggx)",
    );
}

#[test]
fn every_material_name_is_accepted_by_the_flag_and_the_scene() {
    let p = Paths::new("png");
    let (missing, out, scene) = (p.missing.as_str(), p.out.as_str(), p.scene.as_str());
    let with_material =
        |m: &str| ["render", "--env", missing, "--material", m, "-o", out].map(String::from);
    let canonical = [
        "mirror",
        "fresnel",
        "cheap-chrome",
        "diffuse",
        "greene",
        "phong-map",
    ];
    let help = help_of("render", "--material");
    for name in canonical {
        assert!(
            help.contains(name),
            "--material's help lacks {name}: {help}"
        );
    }
    let aliases = ["chrome", "varnish", "plastic", "ramp", "matte", "phongmap"];
    for name in canonical.into_iter().chain(aliases) {
        let args = with_material(name);
        let e = stderr(&run(&args.each_ref().map(String::as_str)));
        assert!(e.contains("missing.exr"), "--material {name}: {e}");
        let body = format!(
            r#"{{"environment": {{"file": "{missing}"}}, "material": {{"kind": "{name}"}}}}"#
        );
        std::fs::write(scene, body).unwrap();
        let e = stderr(&run(&["render", scene, "-o", out]));
        assert!(e.contains("missing.exr"), "scene kind {name}: {e}");
    }
    let known = format!("(known: {})", canonical.join(", "));
    refused(
        &with_material("plastc").each_ref().map(String::as_str),
        &known,
    );
    // Greene's lobe is a lobe name, phong or ggx.
    for lobe in ["phong", "ggx", "GGX", "specular"] {
        let args = with_material(&format!("greene:lobe={lobe}"));
        let e = stderr(&run(&args.each_ref().map(String::as_str)));
        assert!(e.contains("missing.exr"), "greene:lobe={lobe}: {e}");
    }
    refused(
        &with_material("greene:lobe=lambert")
            .each_ref()
            .map(String::as_str),
        "lobe 'lambert' is not phong or ggx",
    );
}

#[test]
fn scene_files_accept_the_names_the_flags_accept() {
    let p = Paths::new("png");
    let (missing, out, scene) = (p.missing.as_str(), p.out.as_str(), p.scene.as_str());
    let help: std::collections::HashMap<String, Vec<String>> =
        listed("render").into_iter().collect();
    // Every name, canonical or alias, of the flags that scene keys mirror.
    for (flag, key, names) in [
        (
            "--mode",
            "indexing",
            vec!["1", "texgen", "gl", "greene", "4", "per-pixel"],
        ),
        ("--attach", "attach", vec!["scene", "view", "camera"]),
        (
            "--filter",
            "filter",
            vec!["point", "linear", "mip", "mipmap", "anisotropic"],
        ),
    ] {
        for name in help[flag].iter().map(String::as_str).chain(names) {
            let body = if key == "indexing" {
                format!(r#"{{"environment": {{"file": "{missing}"}}, "indexing": "{name}"}}"#)
            } else {
                format!(r#"{{"environment": {{"file": "{missing}", "{key}": "{name}"}}}}"#)
            };
            std::fs::write(scene, body).unwrap();
            let o = run(&["render", scene, "-o", out]);
            let e = stderr(&o);
            assert!(e.contains("missing.exr"), "scene {key} = {name}: {e}");
            accepted(
                &["render", "--env", missing, "-o", out, flag, name],
                flag,
                name,
            );
        }
        // And both refuse the same names.
        let body = if key == "indexing" {
            format!(r#"{{"environment": {{"file": "{missing}"}}, "indexing": "sat"}}"#)
        } else {
            format!(r#"{{"environment": {{"file": "{missing}", "{key}": "sat"}}}}"#)
        };
        std::fs::write(scene, body).unwrap();
        let o = run(&["render", scene, "-o", out]);
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        let o = run(&["render", "--env", missing, "-o", out, flag, "sat"]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    }
}

#[test]
fn failures_exit_with_the_status_of_whose_fault_they_are() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.png");
    let out = out.to_str().unwrap();
    // A missing environment file: the input's fault.
    let missing = dir.path().join("missing.exr");
    let o = run(&["render", "--env", missing.to_str().unwrap(), "-o", out]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("no such file"), "{}", stderr(&o));
    // A malformed mesh: the input's fault.
    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let render_mesh = |mesh: &std::path::Path| {
        let m = mesh.to_str().unwrap();
        run(&[
            "render",
            "--object",
            m,
            "--material",
            "diffuse",
            "--no-background",
            "-o",
            out,
        ])
    };
    let o = render_mesh(&bad);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("bad.obj"), "{}", stderr(&o));
    // A missing mesh: the input's fault too.
    let gone = dir.path().join("gone.glb");
    let o = render_mesh(&gone);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    // Flags that do not go together: the request's fault.
    let env = crate::util::asset("city.exr");
    let o = run(&[
        "render",
        "--env",
        env.to_str().unwrap(),
        "--fisheye",
        "180",
        "--aovs",
        "-o",
        out,
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--fisheye"), "{}", stderr(&o));
    assert!(!std::path::Path::new(out).exists());
}
