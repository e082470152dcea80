//! How close two maps are: log-domain PSNR over the directions both cover (the test map
//! converted to the reference's projection and size first when they differ), the
//! per-texel log differences and a picture of them.

use crate::error::Error;
use crate::save::{self, SaveOptions};
use mirrorball_core::glam::DVec2;
use mirrorball_core::metrics::log_psnr_where;
use mirrorball_core::{resample_to_extent, EnvMap, Image, ResampleOptions, WorldProjection};
use mirrorball_io::{Format, Precision, WriteOptions};
use rayon::prelude::*;

/// What [`compare`] measured.
pub struct Comparison {
    /// Log-domain PSNR in dB (infinite when equal).
    pub log_psnr_db: f64,
    /// The solid angle compared: the directions both maps cover.
    pub compared_sr: f64,
    /// The solid angle the reference covers.
    pub reference_covers_sr: f64,
    /// The largest log difference.
    pub max_log_difference: f64,
    /// Whether the test map was converted to the reference's projection and size.
    pub test_converted: bool,
    /// Per texel of the reference, `|ln(1 + r) − ln(1 + t)|` per colour channel.
    pub differences: EnvMap,
}

/// `test` measured against `reference` (both sanitized).
pub fn compare(reference: &EnvMap, test: &EnvMap) -> Comparison {
    let same = reference.projection() == test.projection()
        && reference.width() == test.width()
        && reference.height() == test.height();
    let covers = |d| test.projection().dir_to_uv(d).is_some();
    let converted;
    let t = if same {
        test
    } else {
        converted = resample_to_extent(
            test,
            *reference.projection(),
            reference.width(),
            reference.height(),
            &ResampleOptions::default(),
        );
        &converted
    };
    let psnr = log_psnr_where(reference, t, covers).expect("same shape");
    let (differences, compared_sr, worst) = differences(reference, t, &covers);
    Comparison {
        log_psnr_db: psnr,
        compared_sr,
        reference_covers_sr: reference.projection().covered_solid_angle(),
        max_log_difference: worst,
        test_converted: !same,
        differences,
    }
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
pub fn write_diff(diff: &EnvMap, out: &str, worst: f64) -> Result<(), Error> {
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
