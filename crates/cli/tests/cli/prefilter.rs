//! `mirrorball prefilter` as a user runs it: small sizes, every output checked.
use crate::util::{asset, files, ok, run, stderr};
use mirrorball_core::{EnvMap, ProjectionKind};

fn json(path: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn read_cube(path: &std::path::Path) -> EnvMap {
    let l = mirrorball_io::read(path, &Default::default()).unwrap();
    EnvMap::new(ProjectionKind::Cube.default_projection(), l.layers).unwrap()
}

#[test]
fn ggx_chain_to_ktx2_with_sh_and_preview() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sky.ktx2");
    let src = asset("sky.exr");
    let log = ok(&[
        "prefilter",
        src.to_str().unwrap(),
        out.to_str().unwrap(),
        "--lobe",
        "ggx",
        "--size",
        "32",
        "--mapping",
        "filament",
        "--precision",
        "float",
    ]);
    assert!(log.contains("wrote") && log.contains("6 levels"), "{log}");
    assert_eq!(
        files(dir.path()),
        [
            mirrorball_io::RECORD,
            "sky.ktx2",
            "sky.sh.json",
            "sky_preview.png"
        ]
    );
    let info = ok(&["info", out.to_str().unwrap()]);
    assert!(info.contains("cube") && info.contains("32x32"), "{info}");
    let cube = read_cube(&out);
    assert_eq!(cube.width(), 32);
    let stats = cube.stats();
    assert!(stats.nan == 0 && stats.inf == 0 && stats.negative == 0 && stats.max > 10.0);
    let j = json(&dir.path().join("sky.sh.json"));
    assert_eq!(j["radiance"].as_array().unwrap().len(), 9);
    assert_eq!(j["irradiance_over_pi"].as_array().unwrap().len(), 9);
    assert_eq!(j["roughness_mapping"], "filament");
    let levels = j["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 6);
    let r: Vec<f64> = levels
        .iter()
        .map(|l| l["roughness"].as_f64().unwrap())
        .collect();
    assert_eq!(r[0], 0.0);
    assert_eq!(r[5], 1.0);
    assert!(r.windows(2).all(|w| w[0] < w[1]), "{r:?}");
    assert_eq!(levels[3]["width"], 4);
    let png =
        mirrorball_io::read(&dir.path().join("sky_preview.png"), &Default::default()).unwrap();
    assert_eq!(png.layers[0].width(), 4 * 256 + 3 * 4);
}

#[test]
fn lambert_keeps_the_mean_and_matches_sh() {
    // The mean over all normals of E/π is the mean radiance: ∫∫ L max(n·l, 0)/π dl dn = ∫ L.
    let dir = tempfile::tempdir().unwrap();
    let src = asset("city.exr");
    let out = dir.path().join("irr.dds");
    ok(&[
        "prefilter",
        src.to_str().unwrap(),
        out.to_str().unwrap(),
        "--lobe",
        "lambert",
        "--size",
        "16",
        "--sh-window",
        "auto",
        "--precision",
        "float",
        "-q",
    ]);
    let irr = read_cube(&out);
    let l = mirrorball_io::read(&src, &Default::default()).unwrap();
    let mut env = EnvMap::new(ProjectionKind::LatLong.default_projection(), l.layers).unwrap();
    env.sanitize();
    let (a, b) = (irr.stats().mean, env.stats().mean);
    for k in 0..3 {
        assert!((a[k] - b[k]).abs() < 0.01 * b[k], "{a:?} vs {b:?}");
    }
    // The SH path gives about the same map.
    let out_sh = dir.path().join("irr_sh.dds");
    ok(&[
        "prefilter",
        src.to_str().unwrap(),
        out_sh.to_str().unwrap(),
        "--lobe",
        "lambert",
        "--size",
        "16",
        "--irradiance",
        "sh",
        "--no-preview",
        "--no-sh",
        "--precision",
        "float",
        "-q",
    ]);
    let sh = read_cube(&out_sh);
    let (mut e, mut n) = (0.0f64, 0.0f64);
    for (x, y) in irr.layers().iter().zip(sh.layers()) {
        for (p, q) in x.data().iter().zip(y.data()) {
            e += ((p - q) as f64).powi(2);
            n += (*p as f64).powi(2);
        }
    }
    assert!((e / n).sqrt() < 0.05, "{}", (e / n).sqrt());
    assert!(!dir.path().join("irr_sh.sh.json").exists());
    let j = json(&dir.path().join("irr.sh.json"));
    assert!(j["window"]["hann"].is_number() || j["window"]["hann"].is_null());
}

#[test]
fn phong_levels_as_exr_files_in_any_projection() {
    let dir = tempfile::tempdir().unwrap();
    let src = asset("venice.exr");
    let out = dir.path().join("ph_{level}.exr");
    ok(&[
        "prefilter",
        src.to_str().unwrap(),
        out.to_str().unwrap(),
        "--lobe",
        "phong",
        "--to",
        "latlong",
        "--size",
        "64",
        "--exponents",
        "inf,100,10,1",
        "--levels",
        "4",
        "--no-preview",
        "-q",
    ]);
    for (i, w) in [64u32, 32, 16, 8].iter().enumerate() {
        let p = dir.path().join(format!("ph_{i}.exr"));
        let l = mirrorball_io::read(&p, &Default::default()).unwrap();
        assert_eq!((l.layers[0].width(), l.layers[0].height()), (*w, w / 2));
    }
    let j = json(&dir.path().join("ph.sh.json"));
    assert_eq!(j["levels"][0]["exponent"], "inf");
    assert_eq!(j["levels"][2]["exponent"], 10.0);
    assert_eq!(j["projection"], "latlong");
}

#[test]
fn compression_reports_energy_and_lut() {
    let dir = tempfile::tempdir().unwrap();
    let src = asset("sky.exr");
    let out = dir.path().join("c.ktx2");
    let lut = dir.path().join("lut.exr");
    let log = ok(&[
        "prefilter",
        src.to_str().unwrap(),
        out.to_str().unwrap(),
        "--lobe",
        "ggx",
        "--size",
        "16",
        "--compress",
        "soft:20:200",
        "--lut",
        lut.to_str().unwrap(),
        "--lut-size",
        "32",
        "--no-preview",
    ]);
    assert!(log.contains("energy removed"), "{log}");
    let j = json(&dir.path().join("c.sh.json"));
    let f = j["energy_removed"]["fraction"].as_f64().unwrap();
    assert!(f > 0.1 && f < 1.0, "{f}");
    assert!(j["energy_removed"]["luminance_max_after"].as_f64().unwrap() <= 200.0);
    let l = mirrorball_io::read(&lut, &Default::default()).unwrap();
    assert_eq!(l.layers[0].width(), 32);
    let px = l.layers[0].get(31, 0); // n·v ≈ 1, smooth: A ≈ 1, B ≈ 0
    assert!(px[0] > 0.9 && px[1] < 0.05, "{px:?}");
}

#[test]
fn bad_requests_fail_before_work() {
    let dir = tempfile::tempdir().unwrap();
    let src = asset("city.exr");
    let s = src.to_str().unwrap();
    let out = dir.path().join("o.ktx2");
    let o = out.to_str().unwrap();
    for (args, expect) in [
        (vec!["--lobe", "banana"], "--lobe"),
        (vec!["--lobe", "ggx", "--to", "latlong"], "cube"),
        (vec!["--lobe", "ggx", "--size", "30"], "power of two"),
        (vec!["--lobe", "ggx", "--mapping", "2,3"], "--mapping"),
        (vec!["--lobe", "ggx", "--exponents", "10"], "--exponents"),
        // A list shorter than the chain is refused, not padded.
        (
            vec!["--lobe", "ggx", "--size", "8", "--mapping", "0,0.5"],
            "--mapping lists 2 roughness values but the chain has 4 levels",
        ),
        (
            vec!["--lobe", "phong", "--size", "8", "--exponents", "inf,10"],
            "--exponents lists 2 exponents but the chain has 4 levels",
        ),
        (
            vec!["--lobe", "ggx", "--size", "4096", "--max-memory", "100M"],
            "of --max-memory",
        ),
        (
            vec!["--lobe", "ggx", "--compress", "soft:10:5"],
            "--compress",
        ),
        (
            vec!["--lobe", "ggx", "--sh-window", "blackman"],
            "--sh-window",
        ),
        (vec!["--lobe", "ggx", "--preview", "p.jpg"], "--preview"),
    ] {
        let mut a = vec!["prefilter", s, o];
        a.extend(args);
        let r = run(&a);
        let e = stderr(&r);
        assert_eq!(r.status.code(), Some(2), "{a:?}: {e}");
        assert!(e.contains(expect), "{a:?}: '{expect}' not in {e}");
        assert!(!e.contains("panicked"));
    }
    assert!(files(dir.path()).is_empty(), "{:?}", files(dir.path()));
}

/// The side files (SH JSON, preview, BRDF table) replace only files a mirrorball run wrote:
/// a user's file of the same name is refused by name before any work (exit 2, nothing
/// written) unless `--overwrite`, and prefilter's own are replaced again without asking.
#[test]
fn side_files_replace_only_what_mirrorball_wrote() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let src = asset("sky.exr");
    let out = d.join("sky.ktx2");
    let lut = d.join("brdf.png");
    let prefilter = |extra: &[&str]| {
        let mut args = vec![
            "prefilter",
            src.to_str().unwrap(),
            out.to_str().unwrap(),
            "--lobe",
            "ggx",
            "--size",
            "8",
            "--lut",
            lut.to_str().unwrap(),
            "--lut-size",
            "8",
            "-q",
        ];
        args.extend(extra);
        run(&args)
    };
    for side in ["sky.sh.json", "sky_preview.png", "brdf.png"] {
        std::fs::write(d.join(side), "mine").unwrap();
        let before = files(d);
        let o = prefilter(&[]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{side}: {e}");
        assert!(
            e.contains(&d.join(side).display().to_string()) && e.contains("--overwrite"),
            "{side}: {e}"
        );
        assert_eq!(files(d), before, "{side}: nothing written");
        std::fs::remove_file(d.join(side)).unwrap();
    }
    std::fs::write(d.join("sky.sh.json"), "mine").unwrap();
    std::fs::write(d.join("notes.txt"), "mine").unwrap();
    let o = prefilter(&["--overwrite"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_ne!(std::fs::read(d.join("sky.sh.json")).unwrap(), b"mine");
    let o = prefilter(&[]);
    assert!(o.status.success(), "its own again: {}", stderr(&o));
    assert_eq!(
        files(d),
        [
            mirrorball_io::RECORD,
            "brdf.png",
            "notes.txt",
            "sky.ktx2",
            "sky.sh.json",
            "sky_preview.png"
        ]
    );
    assert_eq!(std::fs::read(d.join("notes.txt")).unwrap(), b"mine");
}
