//! Every front end agrees with the tables: every projection of core's registry is named in
//! `convert --help` and in README.md's table, and every projection × layout pair is taken or
//! refused as `Layout::holds` says, the refusal naming the projection that fits.

use crate::util::{run, stderr};
use mirrorball_core::{Choice, Layout, ProjectionKind, WorldProjection};

/// The names in the first column of README.md's projection table.
fn readme_projections() -> Vec<String> {
    let readme = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../README.md"))
        .expect("README.md");
    let table = readme
        .split("## Projections")
        .nth(1)
        .expect("a Projections section");
    let mut names = Vec::new();
    // After the header row and its rule.
    for line in table.lines().skip_while(|l| !l.starts_with('|')).skip(2) {
        if !line.starts_with('|') {
            break;
        }
        let first = line.split('|').nth(1).unwrap_or("");
        // `a`, `b` (`alias`): the code spans outside parentheses.
        let (mut depth, mut code, mut name) = (0, false, String::new());
        for c in first.chars() {
            match c {
                '`' if code => {
                    if depth == 0 {
                        names.push(std::mem::take(&mut name));
                    }
                    name.clear();
                    code = false;
                }
                '`' => code = true,
                _ if code => name.push(c),
                '(' => depth += 1,
                ')' => depth -= 1,
                _ => {}
            }
        }
    }
    names
}

#[test]
fn every_projection_is_named_in_the_help_and_in_the_readme() {
    let o = run(&["convert", "--help"]);
    assert!(o.status.success());
    let help = String::from_utf8_lossy(&o.stdout).into_owned();
    let words: Vec<&str> = help
        .split(|c: char| c.is_whitespace() || c == ',' || c == '(' || c == ')')
        .collect();
    let readme = readme_projections();
    for kind in ProjectionKind::ALL {
        assert!(
            words.contains(&kind.name()),
            "convert --help does not name {kind}:\n{help}"
        );
        assert!(
            help.contains(kind.about()),
            "convert --help does not describe {kind}"
        );
        assert!(
            readme.iter().any(|n| n == kind.name()),
            "README.md's projection table does not name {kind}: {readme:?}"
        );
    }
    // Every name the README's table gives is a projection's canonical name.
    for n in &readme {
        assert_eq!(
            ProjectionKind::from_name(n).map(ProjectionKind::name),
            Some(n.as_str()),
            "README.md names '{n}'"
        );
    }
}

#[test]
fn every_layout_that_cannot_hold_a_projection_is_refused_naming_the_one_that_can() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.exr");
    let out = dir.path().join("out.exr");
    let (missing, out) = (missing.to_str().unwrap(), out.to_str().unwrap());
    let mut refused = 0;
    for kind in ProjectionKind::ALL {
        for layout in Layout::all() {
            let o = run(&[
                "convert",
                missing,
                out,
                "--to",
                kind.name(),
                "--layout",
                layout.name(),
            ]);
            let e = stderr(&o);
            match layout.refusal(kind, "--to") {
                Some(why) => {
                    refused += 1;
                    assert_eq!(o.status.code(), Some(2), "{kind} {layout}: {e}");
                    assert!(
                        e.contains(&format!("--layout {why}")),
                        "{kind} {layout}: {e}"
                    );
                    for other in ProjectionKind::ALL.into_iter().filter(|&k| layout.holds(k)) {
                        assert!(e.contains(&format!("--to {other}")), "{other}: {e}");
                    }
                }
                // Past the plan: the missing input is what fails.
                None => {
                    assert!(!e.contains("--layout"), "{kind} {layout}: {e}");
                    assert_eq!(o.status.code(), Some(1), "{kind} {layout}: {e}");
                }
            }
        }
    }
    assert!(refused > 0);
    let o = run(&["convert", missing, out, "--to", "cube", "--layout", "eac"]);
    assert!(stderr(&o).contains("use --to eac"), "{}", stderr(&o));
}

/// `info --json FILE`'s projection, or the failure.
fn info_projection(file: &std::path::Path) -> Result<String, String> {
    let o = run(&["info", "--json", file.to_str().unwrap()]);
    if !o.status.success() {
        return Err(stderr(&o));
    }
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).map_err(|e| e.to_string())?;
    Ok(v["projection"].as_str().unwrap_or_default().to_string())
}

/// Every file under `dir` but the folder's records and READMEs, relative.
fn written_files(dir: &std::path::Path) -> Vec<String> {
    crate::util::files(dir)
        .into_iter()
        .filter(|f| !f.ends_with('/') && !f.ends_with("README.md"))
        .filter(|f| !f.ends_with(mirrorball_io::RECORD))
        .collect()
}

/// The projection a file written by bake or prefilter holds: cube maps in every container
/// (one face of a set is read with its set), the SH basis in the SH side files.
fn expected_of_side(name: &str) -> &'static str {
    if name.ends_with(".json") || name.ends_with(".txt") {
        mirrorball_io::SH_PROJECTION
    } else {
        "cube"
    }
}

/// `info` reads back every file `bake` writes for every engine of the `Engine` table, and
/// names its projection: the engines' bundles (KTX1, `.env`, `.gltf`) and cube containers
/// as cubes, a single face of three's or glTF's cube (not a mirror ball) as its cube, the
/// SH files as SH.
#[test]
fn info_reads_every_file_every_bake_engine_writes_and_names_its_projection() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("sky.exr");
    let env = mirrorball_bake::direction_coded(64);
    mirrorball_io::write_image(&src, &env.layers()[0], &Default::default()).unwrap();
    let mut checked = 0;
    for engine in mirrorball_bake::Engine::all() {
        let out = dir.path().join(engine.name());
        crate::util::ok(&[
            "bake",
            src.to_str().unwrap(),
            "--for",
            engine.name(),
            out.to_str().unwrap(),
            "--size",
            "16",
            "-q",
        ]);
        let files = written_files(&out);
        assert!(!files.is_empty(), "{engine}");
        for f in files {
            let got = info_projection(&out.join(&f));
            assert_eq!(
                got.as_deref(),
                Ok(expected_of_side(&f)),
                "{engine}: info {f}"
            );
            checked += 1;
        }
    }
    assert!(
        checked >= mirrorball_bake::Engine::all().count() * 2,
        "{checked}"
    );
}

/// `info` reads back every file `prefilter` writes (the chain in each container, the SH
/// JSON, the preview sheet and the BRDF table) and names its projection.
#[test]
fn info_reads_every_file_prefilter_writes_and_names_its_projection() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("sky.exr");
    let env = mirrorball_bake::direction_coded(32);
    mirrorball_io::write_image(&src, &env.layers()[0], &Default::default()).unwrap();
    for (i, (out, to)) in [
        ("chain.ktx2", "cube"),
        ("chain.dds", "cube"),
        ("flat/level_{level}.exr", "latlong"),
        ("faces/level_{level}.png", "octahedral"),
    ]
    .into_iter()
    .enumerate()
    {
        let folder = dir.path().join(format!("p{i}"));
        std::fs::create_dir(&folder).unwrap();
        let o = folder.join(out);
        if let Some(p) = o.parent() {
            std::fs::create_dir_all(p).unwrap();
        }
        crate::util::ok(&[
            "prefilter",
            src.to_str().unwrap(),
            o.to_str().unwrap(),
            "--lobe",
            "ggx",
            "--size",
            "8",
            "--to",
            to,
            "--lut",
            folder.join(["lut.exr", "lut.png"][i % 2]).to_str().unwrap(),
            "-q",
        ]);
        let files = written_files(&folder);
        for side in [".json", "_preview.png", "lut."] {
            assert!(files.iter().any(|f| f.contains(side)), "{side}: {files:?}");
        }
        for f in files {
            let want = if f.ends_with(".json") {
                mirrorball_io::SH_PROJECTION
            } else if f.contains("_preview.png") {
                mirrorball_io::Picture::PreviewSheet.projection()
            } else if f.starts_with("lut.") {
                mirrorball_io::Picture::BrdfTable.projection()
            } else {
                to
            };
            assert_eq!(
                info_projection(&folder.join(&f)).as_deref(),
                Ok(want),
                "prefilter --to {to}: info {f}"
            );
        }
    }
}

/// `info` reads back every container `convert` writes, for every projection the container
/// holds, and names the projection; one file of a `{face}` set is read with its set.
#[test]
fn info_reads_every_writable_container_and_names_its_projection() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("sky.exr");
    let env = mirrorball_bake::direction_coded(32);
    mirrorball_io::write_image(&src, &env.layers()[0], &Default::default()).unwrap();
    let mut checked = 0;
    for format in mirrorball_io::Format::ALL
        .into_iter()
        .filter(|f| f.is_written())
    {
        for kind in ProjectionKind::ALL {
            if format.is_cube_container() && kind != ProjectionKind::Cube {
                continue;
            }
            let out = dir.path().join(format!("{kind}{}", format.extension()));
            crate::util::ok(&[
                "convert",
                src.to_str().unwrap(),
                out.to_str().unwrap(),
                "--to",
                kind.name(),
                "--size",
                "16",
                "-q",
            ]);
            assert_eq!(
                info_projection(&out).as_deref(),
                Ok(kind.name()),
                "{kind} in {}",
                format.name()
            );
            checked += 1;
        }
    }
    assert!(checked > ProjectionKind::ALL.len() * 4, "{checked}");
    // One file a layer: each file names the set's projection.
    for kind in ProjectionKind::ALL
        .into_iter()
        .filter(|k| k.default_projection().layer_count() > 1)
    {
        let out = dir.path().join(format!("{kind}_{{face}}.exr"));
        crate::util::ok(&[
            "convert",
            src.to_str().unwrap(),
            out.to_str().unwrap(),
            "--to",
            kind.name(),
            "--size",
            "16",
            "-q",
        ]);
        let names = if kind.default_projection().layer_count() == 6 {
            ["px", "nz"]
        } else {
            ["front", "back"]
        };
        for n in names {
            let one = dir.path().join(format!("{kind}_{n}.exr"));
            assert_eq!(
                info_projection(&one).as_deref(),
                Ok(kind.name()),
                "{kind} {n}"
            );
        }
    }
}

/// A picture of v360's padded `eac` shape that records nothing is read as EAC (not as a
/// cube in EAC's packing), and `--from cube` cannot read it so.
#[test]
fn a_padded_eac_frame_without_a_record_is_read_as_eac() {
    let dir = tempfile::tempdir().unwrap();
    for n in [16u32, 24] {
        let (w, h) = Layout::eac().extent(6, n, n);
        let frame = dir.path().join(format!("frame{n}.exr"));
        let img = mirrorball_core::Image::new(w, h, 3);
        mirrorball_io::write_image(&frame, &img, &Default::default()).unwrap();
        assert_eq!(info_projection(&frame).as_deref(), Ok("eac"), "{w}x{h}");
        let o = run(&[
            "info",
            frame.to_str().unwrap(),
            "--from",
            "cube",
            "--in-layout",
            "eac",
        ]);
        assert_eq!(o.status.code(), Some(2));
        assert!(stderr(&o).contains("use --from eac"), "{}", stderr(&o));
    }
}
