//! Values a container cannot hold: a map with a sun of 10⁵–10⁶ written in every container,
//! precision and encoding the CLI writes (`convert` to each format and precision, `bake`
//! for every engine and each encoding of the plain KTX2 bake, `prefilter`'s chains, a
//! rendered frame). Nothing written holds an infinity or NaN; where the storage clips, one
//! line says how many texels, the largest value and the share of the energy lost, each
//! checked against a count made here from a float output; values inside the range are
//! written unchanged. Exposures whose 2^EV is 0 or infinite are refused before any work.

use crate::util::{files, ok, run, stderr};
use mirrorball_core::{Choice, Image, ProjectionKind, WorldProjection};
use mirrorball_io::{Encoding, Format, Limits, Precision, Storage};
use std::path::{Path, PathBuf};

/// A 64×32 lat-long of 1.0 with a sun: texels of 10⁶, 3·10⁵, 7·10⁴ (above B10G11R11's
/// 65024) and 2·10⁴ (inside every float range), as a float EXR.
fn sun(dir: &Path) -> PathBuf {
    let mut img = Image::new(64, 32, 3);
    img.data_mut().fill(1.0);
    img.set(20, 8, &[1e6, 8e5, 6e5]);
    img.set(21, 8, &[3e5, 2e5, 1e5]);
    img.set(20, 9, &[7e4, 7e4, 6.5e4]);
    img.set(21, 9, &[2e4, 2e4, 2e4]);
    let path = dir.join("sun.exr");
    mirrorball_io::write_image(
        &path,
        &img,
        &mirrorball_io::WriteOptions {
            precision: Some(Precision::Float),
            ..Default::default()
        },
    )
    .unwrap();
    path
}

/// Every layer of `path` as read back, checked finite.
fn read_finite(path: &Path) -> Vec<Image> {
    let loaded = mirrorball_io::read(path, &Limits::default()).unwrap();
    for (l, img) in loaded.layers.iter().enumerate() {
        let bad = img.data().iter().filter(|v| !v.is_finite()).count();
        assert_eq!(bad, 0, "{}: layer {l} holds {bad} NaN/inf", path.display());
    }
    loaded.layers
}

/// What a file of `storage` clips of `parts` (each a cube level: its six faces), counted
/// here: texels with a channel past the range, and per part the share of the energy lost,
/// `Σ ω·(v − max)⁺ / Σ ω·v` with each face texel's exact solid angle.
fn expected(storage: Storage, parts: &[Vec<Image>]) -> (u64, Vec<f64>) {
    let max = storage.range().max;
    let cube = ProjectionKind::Cube.default_projection();
    let mut count = 0;
    let shares = parts
        .iter()
        .map(|faces| {
            let (mut lost, mut total) = (0.0, 0.0);
            for (f, face) in faces.iter().enumerate() {
                let n = face.width();
                for y in 0..n {
                    for x in 0..n {
                        let w = cube.texel_solid_angle(f, x, y, n, n);
                        let px = &face.get(x, y)[..3];
                        count += u64::from((0..3).any(|k| px[k] > max[k]));
                        for k in 0..3 {
                            total += w * f64::from(px[k]);
                            lost += w * f64::from((px[k] - max[k]).max(0.0));
                        }
                    }
                }
            }
            lost / total
        })
        .collect();
    (count, shares)
}

/// The line's start for `n` texels past `storage`'s range.
fn clip_text(n: u64, storage: Storage) -> String {
    let max = storage.range().max;
    let mut m = format!("{}", max[0]);
    if max[2] != max[0] {
        m += &format!(" (blue {})", max[2]);
    }
    let texels = if n == 1 { "texel" } else { "texels" };
    format!(
        "{n} {texels} past {}'s largest value {m}, written as it",
        storage.name()
    )
}

/// The outputs of `convert`: each format with each precision it takes (`None`: its
/// default), and KTX2/DDS with their mips.
const CONVERTS: &[(&str, &[Option<&str>])] = &[
    ("exr", &[None, Some("half"), Some("float")]),
    ("hdr", &[None]),
    ("png", &[None, Some("8"), Some("16")]),
    ("jpg", &[None, Some("8")]),
    ("ktx2", &[None, Some("half"), Some("float")]),
    ("dds", &[None, Some("half"), Some("float")]),
];

#[test]
fn convert_writes_a_sun_in_every_container_without_infinity_and_says_what_it_clips() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let src = sun(d);
    let s = src.to_str().unwrap();
    let cube = ["--to", "cube", "--size", "16"];
    // The references: float faces (KTX2) and a float cross (EXR), nothing clipped.
    let faces_ref = d.join("ref.ktx2");
    let cross_ref = d.join("ref.exr");
    for r in [&faces_ref, &cross_ref] {
        let said = ok(&[
            &["convert", s, r.to_str().unwrap()],
            &cube[..],
            &["--precision", "float"],
        ]
        .concat());
        assert!(!said.contains("warning"), "{said}");
    }
    let faces = read_finite(&faces_ref);
    let cross = read_finite(&cross_ref);
    for (ext, precisions) in CONVERTS {
        for p in *precisions {
            let mips: &[bool] = if Format::from_path(Path::new(&format!("x.{ext}")))
                .unwrap()
                .is_cube_container()
            {
                &[false, true]
            } else {
                &[false]
            };
            for &mip in mips {
                let out = d.join(format!("out_{}_{mip}.{ext}", p.unwrap_or("default")));
                let o = out.to_str().unwrap();
                let mut args = [&["convert", s, o], &cube[..]].concat();
                if let Some(p) = p {
                    args.extend(["--precision", p]);
                }
                if mip {
                    args.push("--mips");
                }
                let said = ok(&args);
                let format = Format::from_path(&out).unwrap();
                let precision = p.map(|p| p.parse::<Precision>().unwrap());
                let storage = format.storage(precision);
                let back = read_finite(&out);
                let reference = if format.is_cube_container() {
                    &faces
                } else {
                    &cross
                };
                let range = storage.range();
                let clips = !range.display && range.max[0] < 1e6;
                let what = format!("{args:?}: {said}");
                assert_eq!(said.contains("warning"), clips, "{what}");
                if range.display {
                    continue;
                }
                if clips {
                    let (n, shares) = expected(storage, std::slice::from_ref(&faces));
                    assert!(n > 0);
                    let line = format!("warning: {o}: {}", clip_text(n, storage));
                    if mip {
                        // Level 0's texels and those of the levels made from them: more.
                        let counted: u64 = said
                            .split(&format!("warning: {o}: "))
                            .nth(1)
                            .and_then(|t| t.split(' ').next())
                            .and_then(|t| t.parse().ok())
                            .unwrap_or_else(|| panic!("{what}"));
                        assert!(counted > n, "{what}: {counted} after level 0's {n}");
                        let rest = clip_text(n, storage);
                        let rest = rest.split_once(' ').unwrap().1;
                        assert!(said.contains(rest), "{what}\nwants {rest}");
                    } else {
                        assert!(said.contains(&line), "{what}\nwants {line}");
                    }
                    if !mip {
                        let share = format!(": {:.1}% of the map's energy lost", 100.0 * shares[0]);
                        assert!(said.contains(&share), "{what}\nwants {share}");
                    } else {
                        assert!(
                            said.contains("of level 0's energy lost (the worst of 5)"),
                            "{what}"
                        );
                    }
                    assert!(
                        said.contains("to keep it: --precision float, or --exposure -4"),
                        "{what}"
                    );
                }
                // Inside the range: unchanged (to the storage's precision); past it: its end.
                for (got, want) in back.iter().zip(reference) {
                    for (g, w) in got.data().iter().zip(want.data()) {
                        let max = range.max[0];
                        let expect = w.min(max);
                        let tol = if storage == Storage::Rgbe {
                            0.01
                        } else {
                            1.0 / 2048.0
                        };
                        assert!(
                            (g - expect).abs() <= expect.abs() * tol,
                            "{what}: {g} for {w}"
                        );
                    }
                }
            }
        }
    }
    // One file a face: each measured as it is written, the same line for the whole map.
    let cross_half = ok(&[
        &["convert", s, d.join("c.exr").to_str().unwrap()],
        &cube[..],
    ]
    .concat());
    let per_face = ok(&[
        &["convert", s, d.join("f_{face}.exr").to_str().unwrap()],
        &cube[..],
    ]
    .concat());
    let tail = |said: &str| {
        said.lines().find(|l| l.starts_with("warning")).map(|l| {
            l.split_once(": ")
                .unwrap()
                .1
                .split_once(": ")
                .unwrap()
                .1
                .to_string()
        })
    };
    assert_eq!(
        tail(&cross_half),
        tail(&per_face),
        "{cross_half}\n{per_face}"
    );
    assert!(tail(&per_face).is_some());
}

#[test]
fn exposures_whose_scale_is_zero_or_infinite_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let src = sun(d);
    let s = src.to_str().unwrap();
    let out = d.join("o.exr");
    let o = out.to_str().unwrap();
    for ev in ["200", "1e30", "-1e30", "-200", "128"] {
        let cases: [Vec<&str>; 4] = [
            vec!["convert", s, o, "--to", "cube", "--exposure", ev],
            vec!["render", "--env", s, "-o", o, "--exposure", ev],
            vec!["prefilter", s, o, "--lobe", "ggx", "--preview-exposure", ev],
            vec!["demo", "--out", o, "--exposure", ev],
        ];
        for args in cases {
            let r = run(&args);
            assert_eq!(r.status.code(), Some(2), "{args:?}: {}", stderr(&r));
            assert!(
                stderr(&r).contains("stops is outside -126..=127"),
                "{}",
                stderr(&r)
            );
        }
    }
    assert_eq!(files(d), ["sun.exr"]);
    // The ends of the range are taken: 2^127 and 2^-126 are normal floats.
    for ev in ["127", "-126"] {
        ok(&[
            "convert",
            s,
            o,
            "--to",
            "cube",
            "--size",
            "4",
            "--exposure",
            ev,
            "-q",
        ]);
        read_finite(&out);
    }
}

/// KTX2 levels as their faces: a KTX 2.0 file without supercompression in RGBA32F, read
/// here from the specification's header and level index.
fn ktx2_float_levels(path: &Path) -> Vec<Vec<Image>> {
    let b = std::fs::read(path).unwrap();
    let u32_at = |o: usize| u32::from_le_bytes(b[o..o + 4].try_into().unwrap());
    let u64_at = |o: usize| u64::from_le_bytes(b[o..o + 8].try_into().unwrap()) as usize;
    assert_eq!(u32_at(12), 109, "R32G32B32A32_SFLOAT");
    assert_eq!(u32_at(44), 0, "no supercompression");
    let size = u32_at(20);
    (0..u32_at(40) as usize)
        .map(|i| {
            let (offset, n) = (u64_at(80 + 24 * i), (size >> i).max(1));
            let face_bytes = (n * n * 16) as usize;
            (0..6)
                .map(|f| {
                    let at = offset + f * face_bytes;
                    let data = b[at..at + face_bytes]
                        .chunks_exact(4)
                        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
                        .collect();
                    Image::from_vec(n, n, 4, data).unwrap()
                })
                .collect()
        })
        .collect()
}

/// Bakes `src` for `engine` (with `more` flags) into `dir/name`; returns what it said.
fn bake(src: &Path, engine: &str, dir: &Path, name: &str, more: &[&str]) -> (PathBuf, String) {
    let out = dir.join(name);
    let args = [
        &[
            "bake",
            src.to_str().unwrap(),
            "--for",
            engine,
            out.to_str().unwrap(),
            "--size",
            "16",
            "--samples",
            "8",
        ][..],
        more,
    ]
    .concat();
    (out.clone(), ok(&args))
}

#[test]
fn the_plain_ktx2_bake_says_what_each_encoding_clips() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let src = sun(d);
    let (float, said) = bake(
        &src,
        "ktx2",
        d,
        "float",
        &["--encoding", "rgba32f", "--no-zstd"],
    );
    assert!(!said.contains("warning"), "{said}");
    let mut parts = ktx2_float_levels(&float.join("specular.ktx2"));
    parts.extend(ktx2_float_levels(&float.join("diffuse.ktx2")));
    for (e, _) in Encoding::NAMES {
        if *e == Encoding::Rgba32F {
            continue;
        }
        let storage = Storage::Texels(*e);
        let (out, said) = bake(&src, "ktx2", d, e.name(), &["--encoding", e.name()]);
        let (n, shares) = expected(storage, &parts);
        let (worst, share) = shares
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .unwrap();
        let line = format!("warning: {}/: {}", out.display(), clip_text(n, storage));
        assert!(said.contains(&line), "{said}\nwants {line}");
        let of = format!(
            ": {:.1}% of specular level {worst}'s energy lost (the worst of {})",
            100.0 * share,
            parts.len()
        );
        assert!(said.contains(&of), "{said}\nwants {of}");
        assert!(said.contains("to keep it: --encoding rgba32f"), "{said}");
        for f in ["specular.ktx2", "diffuse.ktx2"] {
            read_finite(&out.join(f));
        }
    }
}

/// Every texel of a KTX1 file's images, B10G11R11 or RGBA16F/32F, finite: the file read
/// from the KTX 1.1 header (its glType) and its images (`imageSize` before each level).
fn ktx1_finite(path: &Path) {
    let b = std::fs::read(path).unwrap();
    let u32_at = |o: usize| u32::from_le_bytes(b[o..o + 4].try_into().unwrap()) as usize;
    let gl_type = u32_at(16);
    let mut at = 64 + u32_at(60);
    for _ in 0..u32_at(56).max(1) {
        let size = u32_at(at);
        at += 4;
        for _ in 0..6 {
            let image = &b[at..at + size];
            let values: Vec<f32> = match gl_type {
                // GL_R11F_G11F_B10F, as Filament reads it (see io's ktx1_io)
                0x8C3A => image
                    .chunks_exact(4)
                    .flat_map(|w| Encoding::B10G11R11.decode(w, 1, 1).data().to_vec())
                    .collect(),
                // GL_HALF_FLOAT
                0x140B => Encoding::Rgba16F
                    .decode(image, (size / 8) as u32, 1)
                    .into_vec(),
                // GL_FLOAT
                0x1406 => Encoding::Rgba32F
                    .decode(image, (size / 16) as u32, 1)
                    .into_vec(),
                t => panic!("{}: glType {t:#x}", path.display()),
            };
            assert!(values.iter().all(|v| v.is_finite()), "{}", path.display());
            at += size.next_multiple_of(4);
        }
    }
}

#[test]
fn every_engine_bakes_a_sun_without_infinity_and_says_what_it_clips() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let src = sun(d);
    for engine in mirrorball_bake::ENGINES {
        let (out, said) = bake(&src, &engine.to_string(), d, &engine.to_string(), &[]);
        let encoding = mirrorball_bake::BakeOptions::default().encoding_for(engine);
        let storage = Storage::Texels(encoding);
        let line = format!("warning: {}/: ", out.display());
        let clip = format!("texels past {}'s largest value", storage.name());
        assert!(
            said.contains(&line) && said.contains(&clip),
            "{engine}: {said}"
        );
        let keep = if engine.describe().encodings.contains(&Encoding::Rgba32F) {
            "to keep it: --encoding rgba32f".to_string()
        } else {
            "to keep it: darken the source first (mirrorball convert --exposure -".to_string()
        };
        assert!(said.contains(&keep), "{engine}: {said}");
        let mut read = 0;
        for f in files(&out) {
            let p = out.join(&f);
            match Format::from_path(&p) {
                Some(_) => {
                    read_finite(&p);
                }
                None if f.ends_with(".ktx") => ktx1_finite(&p),
                None => continue,
            }
            read += 1;
        }
        // Babylon's .env holds RGBD bytes (PNG faces in its own container): no value it
        // holds can be infinite, and the clip line above is what the test needs of it.
        let bytes_only = engine.to_string() == "babylon";
        assert!(read > 0 || bytes_only, "{engine}: {:?}", files(&out));
    }
}

#[test]
fn prefilter_and_render_say_what_their_outputs_clip() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let src = sun(d);
    let s = src.to_str().unwrap();
    for (out, clips) in [
        ("p.ktx2", true),
        ("p.dds", true),
        ("p_{level}.exr", true),
        ("p_{level}.hdr", false),
    ] {
        let o = d.join(out);
        let said = ok(&[
            "prefilter",
            s,
            o.to_str().unwrap(),
            "--lobe",
            "ggx",
            "--size",
            "8",
            "--samples",
            "8",
            "--no-preview",
            "--no-sh",
        ]);
        assert_eq!(said.contains("warning"), clips, "{out}: {said}");
        if clips {
            assert!(
                said.contains("of level 0's energy lost (the worst of 4)"),
                "{out}: {said}"
            );
            assert!(
                said.contains("to keep it: --precision float, or --compress soft:65504"),
                "{out}: {said}"
            );
        }
    }
    for f in files(d) {
        if f.starts_with("p") {
            read_finite(&d.join(f));
        }
    }
    // A frame exposed past half: every pixel clipped, the advice an exposure that fits.
    let r = d.join("r.exr");
    let said = ok(&[
        "render",
        "--env",
        s,
        "-o",
        r.to_str().unwrap(),
        "--size",
        "8x6",
        "--exposure",
        "17",
    ]);
    assert!(said.contains("of the picture's energy lost"), "{said}");
    read_finite(&r);
}
