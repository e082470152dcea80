//! `mirrorball compare`: how close two maps are, in log-domain PSNR over the directions both
//! cover, with an optional difference picture and JSON.

use crate::error::CliError;
use crate::guard::Files;
use crate::save::{self, SaveOptions};
use crate::spec::{bad, ProjSpec};
use crate::{load, CompareArgs};
use mirrorball_core::glam::DVec2;
use mirrorball_core::metrics::log_psnr_where;
use mirrorball_core::{resample_to_extent, EnvMap, Image, ResampleOptions, WorldProjection};
use mirrorball_io::{Format, Precision, WriteOptions};
use rayon::prelude::*;
use serde_json::json;

pub fn run(a: CompareArgs) -> Result<(), CliError> {
    let from = a
        .from
        .as_deref()
        .map(ProjSpec::parse)
        .transpose()
        .map_err(|e| bad("--from", e))?;
    let test_from = a
        .test_from
        .as_deref()
        .map(ProjSpec::parse)
        .transpose()
        .map_err(|e| bad("--test-from", e))?;
    // A difference picture that cannot be written is said after the score, which is
    // worth having without it; one that would overwrite an input is refused now.
    let mut unwritable = None;
    if let Some(d) = &a.diff {
        if !matches!(
            Format::from_path(std::path::Path::new(d)),
            Some(Format::Png | Format::Exr)
        ) {
            return Err(CliError::request(format!(
                "--diff {d}: the difference picture is a .png (a heat map) or an .exr (the log differences)"
            )));
        }
        let mut files = Files::new();
        files
            .input_arg("the reference", &a.reference)
            .input_arg("the test map", &a.test)
            .output("--diff", d);
        files.distinct()?;
        unwritable = files.writable().err();
    }
    let limits = mirrorball_io::Limits::default();
    let mut r = load::load(&a.reference, from.as_ref(), None, &limits)?;
    let mut t = load::load(&a.test, test_from.as_ref(), None, &limits)?;
    if !a.json {
        for (name, src) in [(&a.reference, &r), (&a.test, &t)] {
            eprintln!("{name}: {} ({})", src.env.projection().name(), src.decided);
        }
    }
    r.env.sanitize();
    t.env.sanitize();
    let same = r.env.projection() == t.env.projection()
        && r.env.width() == t.env.width()
        && r.env.height() == t.env.height();
    let covers = |d| t.env.projection().dir_to_uv(d).is_some();
    let test = if same {
        t.env.clone()
    } else {
        resample_to_extent(
            &t.env,
            *r.env.projection(),
            r.env.width(),
            r.env.height(),
            &ResampleOptions::default(),
        )
    };
    let psnr = log_psnr_where(&r.env, &test, covers).expect("same shape");
    let (diff, both_sr, worst) = differences(&r.env, &test, &covers);
    let total_sr = r.env.projection().covered_solid_angle();
    let diff_path = a.diff.as_ref().filter(|_| unwritable.is_none());
    if let Some(d) = diff_path {
        write_diff(&diff, d, worst)?;
    }
    if a.json {
        let v = json!({
            "reference": a.reference,
            "test": a.test,
            "log_psnr_db": if psnr.is_finite() { json!(psnr) } else { json!("inf") },
            "compared_sr": both_sr,
            "compared_fraction_of_sphere": both_sr / (4.0 * std::f64::consts::PI),
            "reference_covers_sr": total_sr,
            "max_log_difference": worst,
            "test_converted": !same,
            "projection": r.env.projection().name(),
            "width": r.env.width(),
            "height": r.env.height(),
            "diff": diff_path,
        });
        println!(
            "{}",
            serde_json::to_string_pretty(&v).expect("serialisable")
        );
        return unwritable.map_or(Ok(()), Err);
    }
    let over = if (both_sr - 4.0 * std::f64::consts::PI).abs() < 1e-6 {
        "over the whole sphere".to_string()
    } else {
        format!(
            "over the {:.1}% of the sphere both cover",
            both_sr / (4.0 * std::f64::consts::PI) * 100.0
        )
    };
    println!(
        "log-PSNR {psnr:.2} dB {over}{}; largest log difference {worst:.3}",
        if same {
            ""
        } else {
            " (test map converted to the reference's projection and size)"
        }
    );
    if let Some(d) = diff_path {
        println!("wrote {d}");
    }
    unwritable.map_or(Ok(()), Err)
}

/// Per texel of `reference`, `|ln(1 + r) − ln(1 + t)|` per colour channel (0 where `keep`
/// rejects the texel's direction), the solid angle compared, and the largest difference.
fn differences(
    reference: &EnvMap,
    test: &EnvMap,
    keep: &(impl Fn(mirrorball_core::glam::DVec3) -> bool + Sync),
) -> (EnvMap, f64, f64) {
    let (w, h) = (reference.width(), reference.height());
    let p = *reference.projection();
    let lg = |x: f32| (x.max(0.0) as f64).ln_1p();
    let mut sr = 0.0;
    let mut worst = 0.0f64;
    let mut layers = Vec::new();
    for layer in 0..reference.layers().len() {
        let (a, b) = (&reference.layers()[layer], &test.layers()[layer]);
        let mut out = Image::new(w, h, 3);
        let (s, wst) = out
            .data_mut()
            .par_chunks_mut(3 * w as usize)
            .enumerate()
            .map(|(y, row)| {
                let y = y as u32;
                let (mut s, mut wst) = (0.0f64, 0.0f64);
                for x in 0..w {
                    let wt = p.texel_solid_angle(layer, x, y, w, h);
                    let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                    let covered = wt > 0.0
                        && p.uv_to_dir(layer, p.nearest_covered(layer, uv))
                            .is_some_and(keep);
                    if !covered {
                        continue;
                    }
                    s += wt;
                    let (pa, pb) = (a.get(x, y), b.get(x, y));
                    for c in 0..3 {
                        let d = (lg(pa[c]) - lg(pb[c])).abs();
                        if d.is_finite() {
                            row[3 * x as usize + c] = d as f32;
                            wst = wst.max(d);
                        }
                    }
                }
                (s, wst)
            })
            .reduce(|| (0.0, 0.0), |a, b| (a.0 + b.0, a.1.max(b.1)));
        sr += s;
        worst = worst.max(wst);
        layers.push(out);
    }
    let env = EnvMap::new(p, layers).expect("the reference's shape");
    (env, sr, worst)
}

/// Writes the differences: an EXR of the log differences as they are, or a PNG heat map
/// (black: equal; through red and yellow to white: the largest difference).
fn write_diff(diff: &EnvMap, out: &str, worst: f64) -> Result<(), CliError> {
    let png = Format::from_path(std::path::Path::new(out)) == Some(Format::Png);
    let env = if png {
        let scale = if worst > 0.0 { 1.0 / worst as f32 } else { 0.0 };
        let layers = diff
            .layers()
            .iter()
            .map(|l| {
                let mut img = l.clone();
                for px in img.data_mut().chunks_exact_mut(3) {
                    let t = (px[0].max(px[1]).max(px[2]) * scale).clamp(0.0, 1.0);
                    // A black-red-yellow-white ramp, linear light (the PNG is sRGB-encoded).
                    let rgb = [
                        (3.0 * t).min(1.0),
                        (3.0 * t - 1.0).clamp(0.0, 1.0),
                        (3.0 * t - 2.0).clamp(0.0, 1.0),
                    ];
                    px.copy_from_slice(&rgb.map(|c| c * c));
                }
                img
            })
            .collect();
        EnvMap::new(*diff.projection(), layers).expect("same shape")
    } else {
        diff.clone()
    };
    let opts = SaveOptions {
        layout: None,
        write: WriteOptions {
            precision: Some(if png { Precision::U8 } else { Precision::Float }),
            ..Default::default()
        },
        mips: false,
        keep_invalid: false,
    };
    save::save(&env, out, &opts)?;
    Ok(())
}
