//! What `prefilter` writes: the chain (a KTX2/DDS cube, or a file per level), the
//! spherical-harmonic JSON that describes it, the preview sheet and the split-sum table,
//! and the line that reports them.

use super::plan::Plan;
use crate::error::Error;
use crate::fit;
use crate::load;
use crate::save;
use mirrorball_core::glam::DVec2;
use mirrorball_core::{Choice, EnvMap, Image, Projection, ProjectionKind, WorldProjection};
use mirrorball_filter::mip::texel_solid_angles;
use mirrorball_filter::sh::{self, Window};
use mirrorball_filter::{BrdfLut, EnergyReport, Lobe, LobeKind, Visibility};
use mirrorball_io::{Format, Precision, WriteOptions};
use serde_json::json;
use std::path::{Path, PathBuf};

/// `dir/stem{suffix}` beside `out`.
pub fn beside(out: &str, suffix: &str) -> PathBuf {
    let p = Path::new(out);
    let stem = p
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "prefiltered".into());
    let stem = stem.replace("{level}", "").replace(load::FACE, "");
    let stem = stem.trim_end_matches(['_', '-', '.']).to_string();
    p.with_file_name(format!("{stem}{suffix}"))
}

/// The file for level `i` of a flat (one file per level) output.
pub fn level_path(out: &str, i: usize) -> String {
    if out.contains("{level}") {
        return out.replace("{level}", &i.to_string());
    }
    crate::save::per_part_path(out, "{level}", &format!("mip{i}"))
        .display()
        .to_string()
}

/// Who the side files are recorded as written by, in their folders' records.
const WRITER: &str = "prefilter";

/// `paths` by folder: each folder (`.` for a bare name) and the names in it.
fn by_folder(paths: &[&Path]) -> Vec<(PathBuf, Vec<String>)> {
    let mut out: Vec<(PathBuf, Vec<String>)> = Vec::new();
    for p in paths {
        let dir = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let Some(name) = p.file_name().map(|n| n.to_string_lossy().into_owned()) else {
            continue;
        };
        match out.iter_mut().find(|(d, _)| *d == dir) {
            Some((_, names)) => names.push(name),
            None => out.push((dir, vec![name])),
        }
    }
    out
}

/// Refuses, before any work, to replace a side file (SH JSON, preview, BRDF table) that
/// no mirrorball run wrote (its folder's record, `mirrorball_io::Owned`, does not list
/// it), unless `overwrite`: the message names the file.
pub fn check_side_files(paths: &[&Path], overwrite: bool) -> Result<(), Error> {
    for (dir, names) in by_folder(paths) {
        mirrorball_io::Owned::read(&dir)?.check(&names, overwrite)?;
    }
    Ok(())
}

/// Records the side files in their folders' records, just before they are written: a run
/// stopped between the two leaves a record naming a file that is not there, which costs
/// nothing, where the other order would leave a file of ours that the next run refuses.
pub fn record_side_files(paths: &[&Path]) -> Result<(), Error> {
    for (dir, names) in by_folder(paths) {
        let mut owned = mirrorball_io::Owned::read(&dir)?;
        if names.iter().all(|n| owned.owns(n)) {
            continue;
        }
        owned.add(WRITER, &names);
        owned.write()?;
    }
    Ok(())
}

/// The chain: one cube container, or each level's file(s). Returns the files written and
/// what their storage could not hold, each level a part of the report.
pub fn write_chain(plan: &Plan, chain: &[EnvMap]) -> Result<(Vec<String>, fit::Report), Error> {
    let mut written = Vec::new();
    if plan.format.is_cube_container() {
        let report = write_cube_chain(
            Path::new(&plan.output),
            chain,
            &plan.save.write,
            plan.save.keep_invalid,
        )?;
        written.push(plan.output.clone());
        return Ok((written, report));
    }
    let mut report = fit::Report::new(plan.format.storage(plan.save.write.precision));
    for (i, level) in chain.iter().enumerate() {
        let saved = save::save(level, &level_path(&plan.output, i), &plan.save)?;
        written.extend(saved.files.iter().map(|p| p.display().to_string()));
        report.extend(saved.report);
    }
    Ok((written, report))
}

/// A cube chain (level 0 first) as one KTX2 or DDS file (by `path`'s extension): what
/// `prefilter` writes, and the studio's download of its chain. Each level is measured
/// against the file's storage first (NaN and infinities the work made replaced by 0 unless
/// `keep_invalid`); returns what the file could not hold.
pub fn write_cube_chain(
    path: &Path,
    chain: &[EnvMap],
    write: &WriteOptions,
    keep_invalid: bool,
) -> Result<fit::Report, Error> {
    let format = Format::from_path(path).unwrap_or(Format::Ktx2);
    let (faces, report) = chain_levels(format, chain, write, keep_invalid);
    mirrorball_io::write_cube(path, &faces, write)?;
    Ok(report)
}

/// [`write_cube_chain`]'s file in memory: the bytes of a `name` file (its extension says
/// KTX2 or DDS, and messages name it), the same encoder's.
pub fn cube_chain_bytes(
    name: &str,
    chain: &[EnvMap],
    write: &WriteOptions,
    keep_invalid: bool,
) -> Result<(Vec<u8>, fit::Report), Error> {
    let format = Format::from_path(Path::new(name)).unwrap_or(Format::Ktx2);
    let (faces, report) = chain_levels(format, chain, write, keep_invalid);
    let bytes = mirrorball_io::write_bytes(&faces, mirrorball_io::Hint::Name(name), write)?;
    Ok((bytes, report))
}

/// The levels' faces as a `format` file holds them, and what it could not hold.
fn chain_levels(
    format: Format,
    chain: &[EnvMap],
    write: &WriteOptions,
    keep_invalid: bool,
) -> (Vec<Vec<Image>>, fit::Report) {
    let (chain, report) = fit::measure_maps(chain, format.storage(write.precision), keep_invalid);
    let faces = chain.iter().map(|l| l.layers().to_vec()).collect();
    (faces, report)
}

/// A level's lobe as the JSON names it.
fn describe(lobe: &Lobe) -> serde_json::Value {
    let mut v = json!({ "lobe": lobe.kind().name() });
    match *lobe {
        Lobe::Lambert => {}
        Lobe::Phong { exponent } => {
            v["exponent"] = if exponent.is_finite() {
                json!(exponent)
            } else {
                json!("inf")
            }
        }
        Lobe::Ggx { roughness } => v["roughness"] = json!(roughness),
    }
    v
}

/// What the chain's JSON says besides the coefficients.
pub struct Described<'a> {
    pub chain: &'a [EnvMap],
    pub lobes: &'a [Lobe],
    pub projection: &'a Projection,
    pub energy: Option<EnergyReport>,
    /// The files written so far.
    pub written: &'a [String],
}

/// The SH JSON: the radiance's and the windowed irradiance's coefficients, with the
/// chain's levels and what was compressed.
fn sh_document(plan: &Plan, sh9: &sh::Sh9, d: &Described) -> serde_json::Value {
    let windowed = sh9.windowed(plan.window);
    let window = match plan.window {
        Window::None => json!("none"),
        Window::Hann { width } => json!({ "hann": width }),
        Window::Lanczos { width } => json!({ "lanczos": width }),
        Window::NonNegative => {
            json!({ "hann": sh9.nonnegative_hann_width(), "chosen": "non-negative" })
        }
    };
    let coeffs = |s: &sh::Sh9| -> Vec<[f64; 3]> { s.coeffs.to_vec() };
    let level_info: Vec<serde_json::Value> = (d.chain.iter().zip(d.lobes).enumerate())
        .map(|(i, (l, lobe))| {
            let mut v = describe(lobe);
            v["level"] = json!(i);
            v["width"] = json!(l.width());
            v["height"] = json!(l.height());
            v
        })
        .collect();
    json!({
        "generator": format!("mirrorball {}", env!("CARGO_PKG_VERSION")),
        "source": plan.source,
        "output": d.written,
        "basis": sh::BASIS_TEXT,
        "radiance": coeffs(sh9),
        "irradiance_over_pi": coeffs(&windowed.lambert()),
        "irradiance_note": format!("{}; the window is applied", sh::IRRADIANCE_TEXT),
        "window": window,
        "lobe": plan.kind.name(),
        "roughness_mapping": plan.mapping.name(),
        "roughness_to_level": plan.mapping.level_formula(),
        "projection": d.projection.name(),
        "levels": level_info,
        "energy_removed": d.energy.map(|r| json!({
            "operator": plan.compress_text,
            "texels": r.texels,
            "fraction": r.fraction_removed,
            "energy_before_rgb": r.before,
            "energy_after_rgb": r.after,
            "luminance_max_before": r.max_before,
            "luminance_max_after": r.max_after,
        })),
    })
}

/// The SH JSON at `p`.
pub fn write_sh(plan: &Plan, p: &Path, sh9: &sh::Sh9, d: &Described) -> Result<(), Error> {
    let text =
        serde_json::to_string_pretty(&sh_document(plan, sh9, d)).expect("JSON values serialise");
    mirrorball_io::atomic_write(p, |w| {
        use std::io::Write;
        w.write_all(text.as_bytes())
            .map_err(|e| mirrorball_io::Error::io(p, e))
    })?;
    Ok(())
}

/// The preview sheet at `p`, 8-bit.
pub fn write_preview(plan: &Plan, p: &Path, chain: &[EnvMap]) -> Result<(), Error> {
    let sheet = preview_sheet(chain, plan.preview_exposure);
    mirrorball_io::write_image(
        p,
        &sheet,
        &WriteOptions {
            precision: Some(Precision::U8),
            note: Some(mirrorball_io::Picture::PreviewSheet),
            ..Default::default()
        },
    )?;
    Ok(())
}

/// The split-sum BRDF table at `p`: 16-bit in a PNG, float in an EXR.
pub fn write_lut(plan: &Plan, p: &Path) -> Result<(), Error> {
    let lut = BrdfLut::new(plan.lut_size, 1024, Visibility::SchlickUe4);
    let precision = if Format::from_path(p) == Some(Format::Png) {
        Precision::U16
    } else {
        Precision::Float
    };
    mirrorball_io::write_image(
        p,
        &lut.to_image(),
        &WriteOptions {
            precision: Some(precision),
            note: Some(mirrorball_io::Picture::BrdfTable),
            ..Default::default()
        },
    )?;
    Ok(())
}

/// Each level as `WIDTH:LOBE` for the report: `512:r=0.000 256:r=0.125 …`.
pub fn levels_detail(chain: &[EnvMap], lobes: &[Lobe]) -> String {
    let detail: Vec<String> = chain
        .iter()
        .zip(lobes)
        .map(|(l, lobe)| {
            let what = match *lobe {
                Lobe::Lambert => LobeKind::Lambert.name().to_string(),
                Lobe::Phong { exponent } if exponent.is_finite() => format!("s={exponent:.0}"),
                Lobe::Phong { .. } => "mirror".to_string(),
                Lobe::Ggx { roughness } => format!("r={roughness:.3}"),
            };
            format!("{}:{what}", l.width())
        })
        .collect();
    detail.join(" ")
}

/// Every level as a 256×128 lat-long thumbnail (bilinear, seamless), four to a row, on
/// black, exposed so that level 0's mean luminance lands at 0.18·2^EV.
fn preview_sheet(chain: &[EnvMap], exposure: f32) -> Image {
    let (tw, th, gap) = (256u32, 128u32, 4u32);
    let cols = chain.len().clamp(1, 4) as u32;
    let rows = (chain.len() as u32).div_ceil(cols).max(1);
    let mut sheet = Image::new(cols * (tw + gap) - gap, rows * (th + gap) - gap, 3);
    let mean = chain.first().map_or(1.0, mean_rgb);
    let scale = if mean > 0.0 && mean.is_finite() {
        (0.18 / mean) as f32 * 2f32.powf(exposure)
    } else {
        2f32.powf(exposure)
    };
    let ll = ProjectionKind::LatLong.default_projection();
    for (i, level) in chain.iter().enumerate() {
        let (cx, cy) = (
            (i as u32 % cols) * (tw + gap),
            (i as u32 / cols) * (th + gap),
        );
        for y in 0..th {
            for x in 0..tw {
                let uv = DVec2::new((x as f64 + 0.5) / tw as f64, (y as f64 + 0.5) / th as f64);
                let Some(d) = ll.uv_to_dir(0, uv) else {
                    continue;
                };
                let v = level.sample(d);
                sheet.set(cx + x, cy + y, &[v[0] * scale, v[1] * scale, v[2] * scale]);
            }
        }
    }
    sheet
}

/// The mean of R, G and B over the sphere, weighted by exact texel solid angle (one table
/// for all six faces of a cube).
fn mean_rgb(env: &EnvMap) -> f64 {
    let omega = texel_solid_angles(env.projection(), env.width(), env.height());
    let c = env.channels();
    let (mut sum, mut total) = (0.0f64, 0.0f64);
    for (layer, img) in env.layers().iter().enumerate() {
        let om = &omega[layer.min(omega.len() - 1)];
        for (px, &w) in img.data().chunks_exact(c).zip(om) {
            let v = (px[0] + px[1] + px[2]) as f64 / 3.0;
            if v.is_finite() && w > 0.0 {
                sum += v * w;
                total += w;
            }
        }
    }
    if total > 0.0 {
        sum / total
    } else {
        0.0
    }
}
