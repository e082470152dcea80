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

#[test]
fn scene_files_accept_the_names_the_flags_accept() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.exr");
    let missing = missing.to_str().unwrap().replace('\\', "/");
    let out = dir.path().join("out.png");
    let out = out.to_str().unwrap();
    let scene = dir.path().join("scene.json");
    let scene_str = scene.to_str().unwrap();
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
            std::fs::write(&scene, body).unwrap();
            let o = run(&["render", scene_str, "-o", out]);
            let e = stderr(&o);
            assert!(e.contains("missing.exr"), "scene {key} = {name}: {e}");
            accepted(
                &["render", "--env", &missing, "-o", out, flag, name],
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
        std::fs::write(&scene, body).unwrap();
        let o = run(&["render", scene_str, "-o", out]);
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        let o = run(&["render", "--env", &missing, "-o", out, flag, "sat"]);
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
