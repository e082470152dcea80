//! The same layout as FFmpeg's `v360`: a direction-coded panorama (colour = ½ + 0.49·d,
//! 16-bit) converted by Debian's `ffmpeg -vf v360=…` and by `mirrorball convert` with the
//! matching options lands on the same pixels: the direction decoded from each output pixel
//! of both agrees within one output pixel's angle.
//!
//! FFmpeg 5.1's faults, and how this test keeps clear of them:
//! - its 16-bit bilinear path (AVX2) wraps values of 65533–65535 to 0–2: the codes here stay
//!   within 0.01–0.99 of full scale;
//! - it reads every input with align-corners scaling (pixel `i` of `w` at `2i/(w − 1) − 1`,
//!   found by decoding its output, up to half a pixel off at the edges): the picture handed
//!   to ffmpeg is coded at those positions (the same mirrorball projection evaluated at
//!   `uv = (i/(w − 1), j/(h − 1))`), the one handed to mirrorball at the texel centres, so
//!   that each tool is given the panorama it believes it reads. Its `dfisheye` input is
//!   read another way (`xyz_to_dfisheye`: pixel `i` of a half `ew` wide at `2i/ew − 1`, its
//!   top-left corner), so a dual fisheye is coded at `uv = (i/w, j/h)`;
//! - a dual fisheye's texels outside both circles are coded with the nearest rim's direction.
//!
//! Skipped, loudly, where no `ffmpeg` is on the PATH (CI installs it).
use crate::util::ok;
use glam::{DVec2, DVec3};
use mirrorball_core::projection::ProjectionSpec;
use mirrorball_core::{Projection, WorldProjection};
use std::path::Path;
use std::process::Command;

pub(crate) fn have_ffmpeg() -> bool {
    let found = Command::new("ffmpeg").arg("-version").output().is_ok();
    if !found {
        eprintln!(
            "\n!!!!!!!! SKIPPED: no ffmpeg on the PATH, so mirrorball's projections were NOT \
             compared with v360 (apt-get install ffmpeg) !!!!!!!!\n"
        );
    }
    found
}

fn ffmpeg(args: &[&str]) -> Vec<u8> {
    let o = Command::new("ffmpeg")
        .args(["-v", "error", "-nostdin", "-y"])
        .args(args)
        .output()
        .expect("ffmpeg runs");
    assert!(
        o.status.success(),
        "ffmpeg {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o.stdout
}

/// What ffmpeg makes of the picture at `input` with `filter`: raw `rgb48le`.
fn v360_raw(input: &Path, filter: &str) -> Vec<u8> {
    ffmpeg(&[
        "-i",
        input.to_str().unwrap(),
        "-vf",
        filter,
        "-f",
        "rawvideo",
        "-pix_fmt",
        "rgb48le",
        "-",
    ])
}

/// The 16-bit code of direction `d`: `½ + 0.49·d` of full scale.
pub(crate) fn code(d: DVec3) -> [u16; 3] {
    d.to_array()
        .map(|c| ((0.5 + 0.49 * c) * 65535.0).round() as u16)
}

fn decode(c: [f64; 3]) -> Option<DVec3> {
    if c.iter().all(|&v| v < 0.005) {
        return None; // black: nothing there
    }
    DVec3::from_array(c.map(|v| (v - 0.5) / 0.49)).try_normalize()
}

/// The direction coded at `(x, y)` of ffmpeg's raw `rgb48le` picture `ff`, `w` wide.
fn ffmpeg_dir(ff: &[u8], w: u32, x: u32, y: u32) -> Option<DVec3> {
    let k = ((y * w + x) * 6) as usize;
    decode([0, 2, 4].map(|o| u16::from_le_bytes([ff[k + o], ff[k + o + 1]]) as f64 / 65535.0))
}

/// `mirrorball convert INPUT OUT ARGS --precision 16 -q` (a 16-bit PNG), read back: its
/// one picture.
fn convert_16(input: &Path, out: &Path, args: &[&str]) -> mirrorball_core::Image {
    let mut all = vec!["convert", input.to_str().unwrap(), out.to_str().unwrap()];
    all.extend(args);
    all.extend(["--precision", "16", "-q"]);
    ok(&all);
    let mut read = mirrorball_io::read(out, &Default::default()).unwrap();
    read.layers.swap_remove(0)
}

/// The direction coded at `(x, y)` of mirrorball's 16-bit PNG, as read (linear values).
fn mirrorball_dir(img: &mirrorball_core::Image, x: u32, y: u32) -> Option<DVec3> {
    decode([0, 1, 2].map(|c| mirrorball_core::color::linear_to_srgb(img.get(x, y)[c] as f64)))
}

/// A `w`×`h` 16-bit PNG of projection `p`, each pixel the code of its direction: at the
/// texel centre, or (`align`) where FFmpeg 5.1 reads it.
fn write_coded(path: &Path, p: &Projection, w: u32, h: u32, align: bool) {
    write_rgb48(path, w, h, &coded(p, w, h, align, 1.0));
}

/// The codes of a `w`×`h` picture of projection `p` (see [`write_coded`]), each the code of
/// `sign` times its direction, row by row.
fn coded(p: &Projection, w: u32, h: u32, align: bool, sign: f64) -> Vec<[u16; 3]> {
    let dfisheye = matches!(p, Projection::DualFisheye(_));
    let mut codes = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let uv = if align && dfisheye {
                DVec2::new(x as f64 / w as f64, y as f64 / h as f64)
            } else if align {
                DVec2::new(x as f64 / (w - 1) as f64, y as f64 / (h - 1) as f64)
            } else {
                DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64)
            };
            let uv = p.nearest_covered(0, uv);
            let d = p.uv_to_dir(0, uv).expect("a direction at every texel");
            codes.push(code(sign * d));
        }
    }
    codes
}

/// Writes `w`×`h` codes as a 16-bit PNG, through ffmpeg.
fn write_rgb48(path: &Path, w: u32, h: u32, codes: &[[u16; 3]]) {
    let raw: Vec<u8> = codes
        .iter()
        .flat_map(|c| c.iter().flat_map(|v| v.to_le_bytes()))
        .collect();
    let rawp = path.with_extension("raw");
    std::fs::write(&rawp, raw).unwrap();
    let size = format!("{w}x{h}");
    ffmpeg(&[
        "-f",
        "rawvideo",
        "-pix_fmt",
        "rgb48le",
        "-s",
        &size,
        "-i",
        rawp.to_str().unwrap(),
        path.to_str().unwrap(),
    ]);
}

/// One comparison: `v360=IN:OUT_OPTIONS` against `mirrorball convert --from FROM --to TO`.
struct Case {
    /// mirrorball's input projection and picture size.
    from: &'static str,
    in_size: (u32, u32),
    /// v360's input and output with their options.
    v360: &'static str,
    /// mirrorball's output projection and `--size`.
    to: &'static str,
    size: u32,
}

/// The angle between the directions of neighbouring texel centres at `(x, y)`: one pixel.
fn pixel_angle(p: &Projection, x: u32, y: u32, w: u32, h: u32) -> f64 {
    let at = |x: i64, y: i64| {
        (x >= 0 && y >= 0 && x < w as i64 && y < h as i64)
            .then(|| {
                let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                (p.density(0, uv) > 0.0)
                    .then(|| p.uv_to_dir(0, uv))
                    .flatten()
            })
            .flatten()
    };
    let (x, y) = (x as i64, y as i64);
    let c = at(x, y).unwrap();
    [(1, 0), (-1, 0), (0, 1), (0, -1)]
        .iter()
        .filter_map(|(dx, dy)| at(x + dx, y + dy))
        .map(|n| c.angle_between(n))
        .fold(0.0, f64::max)
}

fn compare(dir: &Path, case: &Case) {
    let src = ProjectionSpec::parse(case.from)
        .unwrap()
        .build(Some(case.in_size))
        .unwrap();
    let dst = ProjectionSpec::parse(case.to).unwrap().build(None).unwrap();
    let (iw, ih) = case.in_size;
    let (w, h) = dst.layer_extent(case.size);
    let (for_mb, for_ff) = (dir.join("in_mb.png"), dir.join("in_ff.png"));
    write_coded(&for_mb, &src, iw, ih, false);
    write_coded(&for_ff, &src, iw, ih, true);

    let filter = format!("v360={}:interp=line:w={w}:h={h}", case.v360);
    let ff = v360_raw(&for_ff, &filter);
    assert_eq!(ff.len(), (w * h * 6) as usize, "{filter}: output size");
    let out = dir.join("out_mb.png");
    let size = case.size.to_string();
    let args = ["--from", case.from, "--to", case.to, "--size", &size];
    let img = &convert_16(&for_mb, &out, &args);
    assert_eq!((img.width(), img.height()), (w, h), "{}", case.to);

    let (mut compared, mut inside, mut worst) = (0, 0, 0.0f64);
    for y in 0..h {
        for x in 0..w {
            let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
            // Texels on or next to an outline (Hammer's, the sinusoid's) average only their
            // inside part: leave them out, with those outside.
            let near = [(0.0, 0.0), (1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)]
                .iter()
                .all(|(dx, dy)| {
                    dst.density(0, uv + DVec2::new(dx / w as f64, dy / h as f64)) > 0.0
                });
            if !near {
                continue;
            }
            inside += 1;
            let (Some(df), Some(dm)) = (ffmpeg_dir(&ff, w, x, y), mirrorball_dir(img, x, y)) else {
                continue; // outside a view: black in both (checked below)
            };
            compared += 1;
            let tol = pixel_angle(&dst, x, y, w, h);
            let e = df.angle_between(dm);
            worst = worst.max(e / tol);
            assert!(
                e <= tol,
                "{} vs v360={}: texel ({x}, {y}) differs by {:.3}° (a pixel is {:.3}°): \
                 ffmpeg {df}, mirrorball {dm}",
                case.to,
                case.v360,
                e.to_degrees(),
                tol.to_degrees()
            );
        }
    }
    eprintln!(
        "{:>60} ↔ v360={:<60} {compared}/{inside} texels, worst {worst:.3} of a pixel",
        case.to, case.v360
    );
    assert!(
        compared * 10 >= inside * 9 || case.from.starts_with("perspective"),
        "{}: only {compared} of {inside} texels compared",
        case.to
    );
    assert!(compared > 100, "{}: {compared} texels compared", case.to);
}

#[test]
fn projections_land_where_v360_puts_them() {
    if !have_ffmpeg() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let e = |v360: &'static str, to: &'static str, size: u32| Case {
        from: "latlong",
        in_size: (256, 128),
        v360,
        to,
        size,
    };
    let cases = [
        e("e:e", "latlong", 128),
        e(
            "e:flat:h_fov=100:v_fov=70:yaw=30:pitch=20:roll=10",
            "perspective:hfov=100:vfov=70:yaw=30:pitch=20:roll=10",
            96,
        ),
        e(
            "e:cylindrical:h_fov=360:v_fov=100",
            "cylindrical:hfov=360:vfov=100",
            128,
        ),
        // v360's v_fov for cylindricalea is 180·sin(vfov/2): 180·sin 60° here.
        e(
            "e:cylindricalea:h_fov=180:v_fov=155.884572681",
            "cylindrical-equal-area:hfov=180:vfov=120",
            96,
        ),
        e("e:hammer", "hammer", 128),
        e("e:sinusoidal", "sinusoidal", 128),
        e("e:hequirect", "half-equirect", 96),
        // v360's pannini takes d from h_fov and draws X, Y ∈ [−1, 1]: d = 1 reaches
        // 2·2 atan(½) = 106.26° across, and 90° high.
        e(
            "e:pannini:h_fov=1",
            "pannini:d=1:hfov=106.260204708:vfov=90",
            96,
        ),
        e("e:fisheye:h_fov=180:v_fov=180", "fisheye:fov=180", 96),
        e("e:dfisheye:h_fov=180:v_fov=180", "dfisheye", 128),
        e("e:dfisheye:h_fov=200:v_fov=200", "dfisheye:fov=200", 128),
        Case {
            from: "dfisheye",
            in_size: (256, 128),
            v360: "dfisheye:e:ih_fov=180:iv_fov=180",
            to: "latlong",
            size: 128,
        },
        // Where both lenses see, mirrorball blends them (v360 takes the nearer axis's):
        // both are codes of about the same direction.
        Case {
            from: "dfisheye:fov=200",
            in_size: (256, 128),
            v360: "dfisheye:e:ih_fov=200:iv_fov=200",
            to: "latlong",
            size: 128,
        },
        // A photo put back: black (nothing) outside its frustum in both.
        Case {
            from: "perspective:hfov=100:vfov=70",
            in_size: (100, 59),
            v360: "flat:e:ih_fov=100:iv_fov=70",
            to: "latlong",
            size: 256,
        },
    ];
    for case in &cases {
        compare(dir.path(), case);
    }
}

/// One pixel's angle at `(x, y)` of ffmpeg's output (`ffd` decodes a pixel, `df` the one
/// at `(x, y)`): the farthest of its neighbours, leaving out those across a seam between
/// cells or eyes (more than twice as far as the nearest).
fn ffmpeg_pixel(ffd: &impl Fn(u32, u32) -> Option<DVec3>, x: u32, y: u32, df: DVec3) -> f64 {
    let near: Vec<f64> = [(1, 0), (-1, 0), (0, 1), (0, -1)]
        .iter()
        .filter_map(|(dx, dy)| ffd((x as i64 + dx) as u32, (y as i64 + dy) as u32))
        .map(|n| df.angle_between(n))
        .collect();
    let min = near.iter().cloned().fold(f64::INFINITY, f64::min);
    near.iter()
        .cloned()
        .filter(|&a| a <= 2.0 * min)
        .fold(0.0, f64::max)
}

/// One comparison of a packed cube output: `v360=e:OUT` against `mirrorball convert --to TO
/// --layout LAYOUT --size N` from the same lat-long.
struct Packed {
    v360: &'static str,
    to: &'static str,
    layout: &'static str,
    size: u32,
}

fn compare_packed(dir: &Path, case: &Packed) {
    let src = ProjectionSpec::parse("latlong")
        .unwrap()
        .build(Some((256, 128)))
        .unwrap();
    let layout: mirrorball_core::Layout = case.layout.parse().unwrap();
    let (w, h) = layout.extent(6, case.size, case.size);
    let (for_mb, for_ff) = (dir.join("in_mb.png"), dir.join("in_ff.png"));
    write_coded(&for_mb, &src, 256, 128, false);
    write_coded(&for_ff, &src, 256, 128, true);
    let filter = format!("v360=e:{}:interp=line:w={w}:h={h}", case.v360);
    let ff = v360_raw(&for_ff, &filter);
    assert_eq!(ff.len(), (w * h * 6) as usize, "{filter}: output size");
    let out = dir.join("out_mb.png");
    let size = case.size.to_string();
    let args = [
        "--from",
        "latlong",
        "--to",
        case.to,
        "--layout",
        case.layout,
        "--size",
        &size,
    ];
    let img = &convert_16(&for_mb, &out, &args);
    assert_eq!((img.width(), img.height()), (w, h), "{}", case.layout);
    let ffd = |x: u32, y: u32| ffmpeg_dir(&ff, w, x, y);
    let (mut compared, mut worst) = (0, 0.0f64);
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let (Some(df), Some(dm)) = (ffd(x, y), mirrorball_dir(img, x, y)) else {
                panic!("{}: texel ({x}, {y}) is black", case.layout);
            };
            let tol = ffmpeg_pixel(&ffd, x, y, df);
            let e = df.angle_between(dm);
            worst = worst.max(e / tol);
            compared += 1;
            assert!(
                e <= tol,
                "{} {} vs v360=e:{}: texel ({x}, {y}) differs by {:.3}° (a pixel is {:.3}°): \
                 ffmpeg {df}, mirrorball {dm}",
                case.to,
                case.layout,
                case.v360,
                e.to_degrees(),
                tol.to_degrees()
            );
        }
    }
    eprintln!(
        "{:>40} {:<40} ↔ v360=e:{:<50} {compared} texels, worst {worst:.3} of a pixel",
        case.to, case.layout, case.v360
    );
}

#[test]
fn cube_layouts_land_where_v360_puts_them() {
    if !have_ffmpeg() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let p = |v360, to, layout, size| Packed {
        v360,
        to,
        layout,
        size,
    };
    let cases = [
        p("eac", "eac", "eac", 48),
        p("c3x2", "cube", "c3x2", 48),
        p("c6x1", "cube", "c6x1", 32),
        p("c1x6", "cube", "c1x6", 32),
        p(
            "c3x2:out_forder=fbudlr:out_frot=123012",
            "cube",
            "c3x2:forder=fbudlr:frot=123012",
            40,
        ),
        p(
            "c6x1:out_forder=udfblr:out_frot=321032",
            "cube",
            "c6x1:forder=udfblr:frot=321032",
            32,
        ),
    ];
    for case in &cases {
        compare_packed(dir.path(), case);
    }
}

/// One comparison of stereo pairs: `v360=e:OUT:in_stereo=I:out_stereo=O` against
/// `mirrorball convert --from latlong --in-stereo I --to TO --stereo O` from the same
/// lat-long pair. The left eye is coded with its directions and the right eye with their
/// opposites, so an eye taken from the wrong half, or put in the wrong half, is half a turn
/// off.
struct Pair {
    /// Input arrangement, v360's and mirrorball's name alike.
    in_stereo: &'static str,
    /// v360's output with its options.
    v360: &'static str,
    to: &'static str,
    /// mirrorball's `--layout`, for cube outputs.
    layout: Option<&'static str>,
    /// Output arrangement.
    out_stereo: &'static str,
    size: u32,
}

fn compare_pair(dir: &Path, case: &Pair) {
    use mirrorball_core::{Layout, Stereo};
    let (ew, eh) = (128, 64);
    let src = ProjectionSpec::parse("latlong")
        .unwrap()
        .build(Some((ew, eh)))
        .unwrap();
    let (sin, sout): (Stereo, Stereo) = (
        case.in_stereo.parse().unwrap(),
        case.out_stereo.parse().unwrap(),
    );
    // The input pair: each eye coded as FFmpeg or mirrorball reads it, joined.
    let pair = |align: bool| {
        let eye = |sign| {
            let codes = coded(&src, ew, eh, align, sign);
            let data = codes.iter().flat_map(|c| c.map(|v| v as f32)).collect();
            mirrorball_core::Image::from_vec(ew, eh, 3, data).unwrap()
        };
        let eyes = [eye(1.0), eye(-1.0)];
        let joined = sin.join(eyes[..sin.eyes()].to_vec()).unwrap();
        let codes: Vec<[u16; 3]> = joined
            .data()
            .chunks(3)
            .map(|c| [c[0] as u16, c[1] as u16, c[2] as u16])
            .collect();
        (joined.width(), joined.height(), codes)
    };
    let (for_mb, for_ff) = (dir.join("pair_mb.png"), dir.join("pair_ff.png"));
    let (pw, ph, codes) = pair(false);
    write_rgb48(&for_mb, pw, ph, &codes);
    let (_, _, codes) = pair(true);
    write_rgb48(&for_ff, pw, ph, &codes);

    let dst = ProjectionSpec::parse(case.to).unwrap().build(None).unwrap();
    let (lw, lh) = dst.layer_extent(case.size);
    let (w, h) = match case.layout {
        Some(l) => l
            .parse::<Layout>()
            .unwrap()
            .extent(dst.layer_count(), lw, lh),
        None => (lw, lh),
    };
    let (fw, fh) = sout.extent(w, h);
    let filter = format!(
        "v360=e:{}:in_stereo={}:out_stereo={}:interp=line:w={w}:h={h}",
        case.v360, case.in_stereo, case.out_stereo
    );
    let ff = v360_raw(&for_ff, &filter);
    assert_eq!(ff.len(), (fw * fh * 6) as usize, "{filter}: output size");
    let out = dir.join("pair_out.png");
    let size = case.size.to_string();
    let mut args = vec![
        "--from",
        "latlong",
        "--in-stereo",
        case.in_stereo,
        "--to",
        case.to,
        "--stereo",
        case.out_stereo,
        "--size",
        &size,
    ];
    if let Some(l) = case.layout {
        args.extend(["--layout", l]);
    }
    let img = &convert_16(&for_mb, &out, &args);
    assert_eq!((img.width(), img.height()), (fw, fh), "{filter}");
    let ffd = |x: u32, y: u32| ffmpeg_dir(&ff, fw, x, y);
    let (mut compared, mut worst) = (0, 0.0f64);
    for e in 0..sout.eyes() {
        let (ox, oy) = match sout {
            Stereo::SideBySide => (e as u32 * w, 0),
            Stereo::TopBottom => (0, e as u32 * h),
            Stereo::Mono => (0, 0),
        };
        // Which input eye this output eye shows, by the sign of its codes: v360's rule.
        let sign = if sin.source_eye(e) == 0 { 1.0 } else { -1.0 };
        for y in oy + 1..oy + h - 1 {
            for x in ox + 1..ox + w - 1 {
                let (Some(df), Some(dm)) = (ffd(x, y), mirrorball_dir(img, x, y)) else {
                    panic!("{filter}: texel ({x}, {y}) is black");
                };
                let tol = ffmpeg_pixel(&ffd, x, y, df);
                let err = df.angle_between(dm);
                worst = worst.max(err / tol);
                compared += 1;
                assert!(
                    err <= tol,
                    "{} ({}) vs {filter}: eye {e}, texel ({x}, {y}) differs by {:.3}° (a pixel \
                     is {:.3}°): ffmpeg {df}, mirrorball {dm}",
                    case.to,
                    case.out_stereo,
                    err.to_degrees(),
                    tol.to_degrees()
                );
                // And the eye is the one v360's rule names: a lat-long output's texel shows
                // its own direction, times the source eye's sign.
                if case.to == "latlong" {
                    let uv = DVec2::new(
                        (x - ox) as f64 / w as f64 + 0.5 / w as f64,
                        (y - oy) as f64 / h as f64 + 0.5 / h as f64,
                    );
                    let want = sign * dst.uv_to_dir(0, uv).unwrap();
                    assert!(
                        dm.angle_between(want) <= 2.0 * tol,
                        "{filter}: eye {e} at ({x}, {y}) shows {dm}, not {want}"
                    );
                }
            }
        }
    }
    eprintln!(
        "{:>30} {:<8} ↔ {:<70} {compared} texels, worst {worst:.3} of a pixel",
        case.to, case.out_stereo, filter
    );
    assert!(compared > 1000, "{filter}: {compared} texels compared");
}

#[test]
fn stereo_pairs_land_where_v360_puts_them() {
    if !have_ffmpeg() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let p = |in_stereo, v360, to, layout, out_stereo, size| Pair {
        in_stereo,
        v360,
        to,
        layout,
        out_stereo,
        size,
    };
    let cases = [
        p("sbs", "c3x2", "cube", Some("c3x2"), "sbs", 24),
        p("tb", "e", "latlong", None, "sbs", 96),
        p(
            "2d",
            "flat:h_fov=100:v_fov=70",
            "perspective:hfov=100:vfov=70",
            None,
            "tb",
            64,
        ),
        p("sbs", "e", "latlong", None, "2d", 96),
        p("tb", "e", "latlong", None, "tb", 64),
        p("2d", "e", "latlong", None, "sbs", 64),
    ];
    for case in &cases {
        compare_pair(dir.path(), case);
    }
}

/// The picture of a map of projection `from` (`w`×`h`, or for a cube in v360's cells a face
/// of `w`) coded with its directions, for ffmpeg and for mirrorball: a single-layer map as
/// [`write_coded`] codes it, a map with layers (EAC) packed by its layout from faces coded at
/// their texel centres (v360 reads EAC at pixel centres, so both get the same picture).
fn write_input(
    dir: &Path,
    from: &str,
    (w, h): (u32, u32),
) -> (std::path::PathBuf, std::path::PathBuf) {
    let (for_mb, for_ff) = (dir.join("opt_mb.png"), dir.join("opt_ff.png"));
    let src = ProjectionSpec::parse(from)
        .unwrap()
        .build(Some((w, h)))
        .unwrap();
    if src.layer_count() == 1 {
        write_coded(&for_mb, &src, w, h, false);
        write_coded(&for_ff, &src, w, h, true);
        return (for_mb, for_ff);
    }
    let layers = (0..src.layer_count())
        .map(|layer| {
            let data = (0..w * w)
                .flat_map(|i| {
                    let uv = DVec2::new(
                        ((i % w) as f64 + 0.5) / w as f64,
                        ((i / w) as f64 + 0.5) / w as f64,
                    );
                    code(src.uv_to_dir(layer, uv).unwrap()).map(|c| c as f32)
                })
                .collect();
            mirrorball_core::Image::from_vec(w, w, 3, data).unwrap()
        })
        .collect();
    let env = mirrorball_core::EnvMap::new(src, layers).unwrap();
    let picture = mirrorball_core::Layout::default_for(src.kind())
        .pack(&env)
        .unwrap();
    let codes: Vec<[u16; 3]> = picture
        .data()
        .chunks(3)
        .map(|c| [c[0], c[1], c[2]].map(|v| v.round() as u16))
        .collect();
    write_rgb48(&for_mb, picture.width(), picture.height(), &codes);
    std::fs::copy(&for_mb, &for_ff).unwrap();
    (for_mb, for_ff)
}

/// `mirrorball convert --v360 OPTIONS` against `ffmpeg -vf v360=OPTIONS:interp=line` on
/// the same direction-coded input of projection `from`: the same picture size, and the
/// direction decoded from each texel within one of ffmpeg's pixels (its farthest
/// neighbour, seams left out) wherever ffmpeg's texel is not black and the output
/// projection covers it (v360 draws past a fisheye's circle), at least 97% of those
/// compared (the rest: rim texels mirrorball leaves black).
fn compare_options(dir: &Path, from: &str, in_size: (u32, u32), options: &str) {
    let (for_mb, for_ff) = write_input(dir, from, in_size);
    let filter = format!("v360={options}:interp=line");
    let ff = v360_raw(&for_ff, &filter);
    let out = dir.join("opt_out.png");
    // The input's projection is the options' own: no --from.
    let img = &convert_16(&for_mb, &out, &["--v360", options]);
    let (w, h) = (img.width(), img.height());
    assert_eq!(
        ff.len(),
        (w * h * 6) as usize,
        "{filter}: ffmpeg's size is not {w}x{h}"
    );
    let ffd = |x: u32, y: u32| (x < w && y < h).then(|| ffmpeg_dir(&ff, w, x, y))?;
    let to = mirrorball::v360::parse(options)
        .unwrap()
        .to
        .build(None)
        .unwrap();
    let single = (to.layer_count() == 1).then_some(to);
    let uv = |x: u32, y: u32| DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
    let (mut compared, mut seen, mut worst) = (0, 0, 0.0f64);
    for y in 0..h {
        for x in 0..w {
            let Some(df) = ffd(x, y) else {
                continue;
            };
            // v360 draws past a fisheye's circle; mirrorball leaves it black.
            if single
                .as_ref()
                .is_some_and(|p| p.density(0, uv(x, y)) <= 0.0)
            {
                continue;
            }
            seen += 1;
            let Some(dm) = mirrorball_dir(img, x, y) else {
                continue; // a rim texel mirrorball leaves black (counted below)
            };
            // One pixel: a single-layer output's own (its farthest neighbour's angle,
            // as `compare` takes it), ffmpeg's for cells (seams left out).
            let tol = match &single {
                Some(p) => pixel_angle(p, x, y, w, h),
                None => ffmpeg_pixel(&ffd, x, y, df),
            };
            if tol == 0.0 {
                continue; // no neighbour decodes: a lone texel at a rim
            }
            let e = df.angle_between(dm);
            worst = worst.max(e / tol);
            compared += 1;
            assert!(
                e <= tol,
                "--v360 {options}: texel ({x}, {y}) differs by {:.3}° (a pixel is {:.3}°): \
                 ffmpeg {df}, mirrorball {dm}",
                e.to_degrees(),
                tol.to_degrees()
            );
        }
    }
    eprintln!("--v360 {options:<70} {compared}/{seen} texels, worst {worst:.3} of a pixel");
    assert!(
        compared * 100 >= seen * 97 && compared > 500,
        "--v360 {options}: only {compared} of the {seen} texels ffmpeg shows compared"
    );
}

#[test]
fn v360_options_land_where_v360_puts_them() {
    if !have_ffmpeg() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let e = (256, 128);
    for order in ["ypr", "yrp", "pyr", "pry", "ryp", "rpy"] {
        let s = format!("e:eac:yaw=30:pitch=20:roll=-50:rorder={order}:w=148:h=104");
        compare_options(dir.path(), "latlong", e, &s);
    }
    for s in [
        "e:c3x2:out_forder=fbudlr:out_frot=123012:yaw=-45:pitch=10:w=120:h=80",
        "e:c6x1:out_forder=udfblr:roll=30:w=192:h=32",
        "e:flat:h_fov=90:v_fov=58.71551708:w=160:h=90:yaw=40:pitch=-30:roll=20",
        "e:flat:d_fov=100:w=160:h=90:pitch=45",
        "e:e:yaw=20:pitch=30:roll=-40:rorder=rpy:w=128:h=64",
        "e:e:yaw=60:h_flip=1:v_flip=true:w=128:h=64",
        "e:e:pitch=25:d_flip=1:w=128:h=64",
        "e:fisheye:h_fov=180:v_fov=180:yaw=90:w=96:h=96",
        "e:sg:h_fov=200:v_fov=200:w=96:h=96",
        "e:equisolid:h_fov=180:v_fov=180:w=96:h=96",
        "e:og:h_fov=160:v_fov=160:w=96:h=96",
        "e:hequirect:yaw=-30:w=96:h=96",
        "e:tetrahedron:yaw=30:pitch=-20:w=128:h=64",
        // v360's eac at sizes of its own: YouTube's 3840x2160 scaled by a fifth (faces
        // 254⅔ by 212 texels), and faces of whole but unequal sizes.
        "e:eac:w=768:h=432",
        "e:eac:yaw=100:pitch=-30:w=772:h=440",
    ] {
        compare_options(dir.path(), "latlong", e, s);
    }
    compare_options(
        dir.path(),
        "dfisheye:fov=190",
        e,
        "dfisheye:e:ih_fov=190:iv_fov=190:w=128:h=64",
    );
    compare_options(dir.path(), "eac", (40, 40), "eac:e:yaw=15:w=128:h=64");
    compare_options(dir.path(), "tetrahedron", e, "tetrahedron:e:w=128:h=64");
}

/// Options mirrorball cannot make exactly, or v360 would refuse: exit 2, the key named, no
/// output written.
#[test]
fn v360_options_refused_name_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let input = crate::util::asset("city.exr");
    let out = dir.path().join("out.png");
    for (options, extra, named) in [
        ("e:eac:bogus=1", &[][..], "bogus"),
        ("e:eac:yaw=400", &[], "yaw"),
        ("e:tsp", &[], "tsp"),
        ("e:barrel", &[], "barrel"),
        ("e:c3x2:out_forder=rludfq", &[], "out_forder"),
        ("e:e:ih_flip=1", &[], "ih_flip"),
        ("e:c3x2:w=100:h=60", &[], "h=60"),
        ("e:eac", &["--to", "cube"][..], "--to"),
        ("e:eac", &["--pitch", "10"][..], "--pitch"),
        ("e:eac:w=148:h=104", &["--size", "48"][..], "--size"),
    ] {
        let mut args = vec![
            "convert",
            input.to_str().unwrap(),
            out.to_str().unwrap(),
            "--v360",
            options,
        ];
        args.extend(extra);
        let o = crate::util::run(&args);
        let err = crate::util::stderr(&o);
        assert_eq!(
            o.status.code(),
            Some(2),
            "--v360 {options} {extra:?}: {err}"
        );
        assert!(err.contains(named), "--v360 {options} {extra:?}: {err}");
        assert!(!out.exists(), "--v360 {options}: an output was written");
    }
}

/// An EAC frame of v360's at a size of its own (768x432: YouTube's 3840x2160 scaled by a
/// fifth), made by ffmpeg from a direction-coded lat-long, read with `--from eac` and by
/// v360's `eac` input alike: the same directions within one pixel. And `--to eac --size
/// WxH` makes the frame `--v360 e:eac:w=W:h=H` makes, to the bit.
#[test]
fn eac_frames_of_any_size() {
    if !have_ffmpeg() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (_, ll) = write_input(dir.path(), "latlong", (512, 256));
    let frame = dir.path().join("frame.png");
    ffmpeg(&[
        "-i",
        ll.to_str().unwrap(),
        "-vf",
        "v360=e:eac:w=768:h=432:interp=line",
        "-pix_fmt",
        "rgb48be",
        frame.to_str().unwrap(),
    ]);
    let ff = v360_raw(&frame, "v360=eac:e:w=256:h=128:yaw=20:interp=line");
    let out = dir.path().join("read.png");
    let o = ok(&[
        "convert",
        frame.to_str().unwrap(),
        out.to_str().unwrap(),
        "--from",
        "eac",
        "--to",
        "latlong",
        "--size",
        "256",
        "--yaw",
        "20",
        "--precision",
        "16",
    ]);
    assert!(o.contains("fits eac"), "{o}");
    let img = mirrorball_io::read(&out, &Default::default()).unwrap();
    let img = &img.layers[0];
    let dst = ProjectionSpec::parse("latlong")
        .unwrap()
        .build(None)
        .unwrap();
    let (mut compared, mut worst) = (0, 0.0f64);
    for y in 1..127 {
        for x in 0..256 {
            let (Some(df), Some(dm)) = (ffmpeg_dir(&ff, 256, x, y), mirrorball_dir(img, x, y))
            else {
                panic!("texel ({x}, {y}) is black");
            };
            let tol = pixel_angle(&dst, x, y, 256, 128);
            let e = df.angle_between(dm);
            worst = worst.max(e / tol);
            compared += 1;
            assert!(
                e <= tol,
                "eac 768x432 read: texel ({x}, {y}) differs by {:.3}° (a pixel is {:.3}°)",
                e.to_degrees(),
                tol.to_degrees()
            );
        }
    }
    eprintln!("eac 768x432 read: {compared} texels, worst {worst:.3} of a pixel");

    // --to eac --size WxH is --v360 e:eac:w=W:h=H.
    let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
    let src = crate::util::asset("city.exr");
    ok(&[
        "convert",
        src.to_str().unwrap(),
        a.to_str().unwrap(),
        "--to",
        "eac",
        "--size",
        "768x432",
        "-q",
    ]);
    ok(&[
        "convert",
        src.to_str().unwrap(),
        b.to_str().unwrap(),
        "--v360",
        "e:eac:w=768:h=432",
        "-q",
    ]);
    let (a, b) = (
        mirrorball_io::read(&a, &Default::default()).unwrap(),
        mirrorball_io::read(&b, &Default::default()).unwrap(),
    );
    assert_eq!((a.layers[0].width(), a.layers[0].height()), (768, 432));
    assert_eq!(a.layers[0], b.layers[0]);
}
