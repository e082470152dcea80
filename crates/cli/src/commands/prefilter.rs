//! `mirrorball prefilter`: prefiltered lighting (Lambert, Phong, GGX) as a mip chain, with
//! spherical-harmonic coefficients and a preview sheet.
//!
//! `args → Plan (lobe, levels, roughness per level, outputs checked) → read → sanitize →
//! optional clamp/soft compression (energy report) → Prefilterer (working cube, bright
//! split) → one lobe per level (progress bar) → KTX2/DDS cube with the chain, or one image
//! per level → SH JSON → preview PNG`.

use super::InputPlan;
use crate::budget;
use crate::commands::convert::parse_precision;
use crate::error::CliError;
use crate::guard::Files;
use crate::progress::with_progress;
use crate::save::{self, SaveOptions};
use crate::spec::{bad, ProjSpec};
use crate::{load, PrefilterArgs};
use mirrorball_core::glam::DVec2;
use mirrorball_core::{Choice, EnvMap, Image, Layout, Projection, ProjectionKind, WorldProjection};
use mirrorball_filter::mip::{level_count, texel_solid_angles};
use mirrorball_filter::sh::{self, Window};
use mirrorball_filter::{
    chain_lobes, compress, irradiance, BrdfLut, Compression, EnergyReport, Lobe, LobeKind,
    MipChain, MipFilter, PrefilterOptions, Prefilterer, RoughnessMapping, Visibility,
};
use mirrorball_io::{Format, Precision, WriteOptions};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// How Lambert maps are computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum IrradianceMethod {
    /// The moment hierarchy: the brute-force sum to a tolerance.
    Exact,
    /// Nine spherical-harmonic coefficients.
    Sh,
}

impl Choice for IrradianceMethod {
    const NAMES: &'static [(Self, &'static [&'static str])] = &[
        (IrradianceMethod::Exact, &["exact", "convolve", "brute"]),
        (IrradianceMethod::Sh, &["sh", "sh9"]),
    ];
}

/// Everything `prefilter` will do, checked before any file is read.
struct Plan {
    input: InputPlan,
    kind: LobeKind,
    to: ProjSpec,
    format: Format,
    size: Option<u32>,
    levels: Option<usize>,
    mapping: RoughnessMapping,
    exponents: Option<Vec<f64>>,
    compression: Compression,
    window: Window,
    irradiance: IrradianceMethod,
    sh_path: Option<PathBuf>,
    preview_path: Option<PathBuf>,
    lut_path: Option<PathBuf>,
    save: SaveOptions,
    opts: PrefilterOptions,
}

/// `dir/stem{suffix}` beside `out`.
fn beside(out: &str, suffix: &str) -> PathBuf {
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
fn level_path(out: &str, i: usize) -> String {
    if out.contains("{level}") {
        return out.replace("{level}", &i.to_string());
    }
    crate::save::per_part_path(out, "{level}", &format!("mip{i}"))
        .display()
        .to_string()
}

fn check_parent(p: &Path, what: &str) -> Result<(), CliError> {
    if let Some(dir) = p.parent().filter(|d| !d.as_os_str().is_empty()) {
        if !dir.is_dir() {
            return Err(CliError::request(format!(
                "{what} {}: the folder {} does not exist",
                p.display(),
                dir.display()
            )));
        }
    }
    Ok(())
}

impl Plan {
    fn new(a: &PrefilterArgs) -> Result<Plan, CliError> {
        let input = InputPlan::new(&a.input_args)?;
        let kind = match a.lobe.to_ascii_lowercase().as_str() {
            "lambert" | "diffuse" | "irradiance" => LobeKind::Lambert,
            "phong" => LobeKind::Phong,
            "ggx" | "specular" | "trowbridge-reitz" => LobeKind::Ggx,
            other => {
                return Err(CliError::request(format!(
                    "--lobe: unknown '{other}' (lambert, phong, ggx)"
                )))
            }
        };
        let to = ProjSpec::parse(&a.to).map_err(|e| bad("--to", e))?;
        let layout = a
            .layout
            .as_deref()
            .map(str::parse::<Layout>)
            .transpose()
            .map_err(|e| bad("--layout", e))?;
        // Flat outputs are checked with the name of level 0.
        let probe =
            if Format::from_path(Path::new(&a.output)).is_some_and(|f| f.is_cube_container()) {
                a.output.clone()
            } else {
                level_path(&a.output, 0)
            };
        let format = save::check(&probe, to.kind, layout)?;
        if format == Format::Jpeg {
            return Err(CliError::request(format!(
                "{}: prefiltered radiance is HDR; write .exr, .hdr, .ktx2 or .dds (PNG for previews)",
                a.output
            )));
        }
        let precision = parse_precision(a.precision.as_deref())?;
        if matches!(precision, Some(Precision::U8 | Precision::U16)) && format != Format::Png {
            return Err(CliError::request(format!(
                "{}: 8/16-bit integers are for PNG; use half or float",
                a.output
            )));
        }
        if let Some(s) = a.size {
            if s == 0 || s > 8192 {
                return Err(CliError::request(format!(
                    "--size: {s} is outside 1..=8192"
                )));
            }
            if format.is_cube_container() && !s.is_power_of_two() && a.levels != Some(1) {
                return Err(CliError::request(format!(
                    "--size {s}: a cube map's mip chain halves exactly only from a power of two"
                )));
            }
        }
        if let Some(l) = a.levels {
            if l == 0 || l > 16 {
                return Err(CliError::request(format!(
                    "--levels: {l} is outside 1..=16"
                )));
            }
        }
        let mapping = RoughnessMapping::parse(&a.mapping).ok_or_else(|| {
            CliError::request(format!(
                "--mapping: '{}' is not linear, ue4, filament or a list of roughness values in [0, 1]",
                a.mapping
            ))
        })?;
        let exponents = match &a.exponents {
            None => None,
            Some(s) => {
                if kind != LobeKind::Phong {
                    return Err(CliError::request("--exponents applies to --lobe phong"));
                }
                let v: Result<Vec<f64>, _> = s
                    .split(',')
                    .map(|t| match t.trim() {
                        "inf" | "mirror" => Ok(f64::INFINITY),
                        t => t
                            .parse::<f64>()
                            .ok()
                            .filter(|x| *x >= 0.0)
                            .ok_or(t.to_string()),
                    })
                    .collect();
                Some(v.map_err(|t| {
                    CliError::request(format!(
                        "--exponents: '{t}' is not a non-negative number (or inf)"
                    ))
                })?)
            }
        };
        let compression = Compression::parse(&a.compress).ok_or_else(|| {
            CliError::request(format!(
                "--compress: '{}' is not none, clamp:MAX, soft:MAX or soft:KNEE:MAX (KNEE < MAX, both > 0)",
                a.compress
            ))
        })?;
        let window = Window::parse(&a.sh_window).ok_or_else(|| {
            CliError::request(format!(
                "--sh-window: '{}' is not none, hann[:W], lanczos[:W] or auto",
                a.sh_window
            ))
        })?;
        let irradiance = IrradianceMethod::parse_name(&a.irradiance).map_err(|e| {
            CliError::request(format!(
                "--irradiance: unknown '{}' ({})",
                e.given.to_ascii_lowercase(),
                e.list()
            ))
        })?;
        if a.samples == 0 || a.samples > 65536 {
            return Err(CliError::request(format!(
                "--samples: {} is outside 1..=65536",
                a.samples
            )));
        }
        if let Some(c) = a.cube_size {
            if c == 0 || c > 4096 {
                return Err(CliError::request(format!(
                    "--cube-size: {c} is outside 1..=4096"
                )));
            }
        }
        if !a.preview_exposure.is_finite() {
            return Err(CliError::request(
                "--preview-exposure must be a finite number",
            ));
        }
        let sh_path = (!a.no_sh).then(|| {
            a.sh.clone()
                .map(PathBuf::from)
                .unwrap_or_else(|| beside(&a.output, ".sh.json"))
        });
        let preview_path = (!a.no_preview).then(|| {
            a.preview
                .clone()
                .map(PathBuf::from)
                .unwrap_or_else(|| beside(&a.output, "_preview.png"))
        });
        if let Some(p) = &preview_path {
            if Format::from_path(p) != Some(Format::Png) {
                return Err(CliError::request(format!(
                    "--preview {}: the preview sheet is a .png",
                    p.display()
                )));
            }
            check_parent(p, "--preview")?;
        }
        if let Some(p) = &sh_path {
            check_parent(p, "--sh")?;
        }
        let lut_path = a.lut.clone().map(PathBuf::from);
        if let Some(p) = &lut_path {
            if !matches!(Format::from_path(p), Some(Format::Exr | Format::Png)) {
                return Err(CliError::request(format!(
                    "--lut {}: write the BRDF table as .exr (or .png)",
                    p.display()
                )));
            }
            check_parent(p, "--lut")?;
        }
        if a.lut_size == 0 || a.lut_size > 4096 {
            return Err(CliError::request(format!(
                "--lut-size: {} is outside 1..=4096",
                a.lut_size
            )));
        }
        let save = SaveOptions {
            layout,
            write: WriteOptions {
                precision,
                ..Default::default()
            },
            mips: false,
        };
        let mut files = Files::new();
        files.input_arg("the input", &a.input);
        if format.is_cube_container() {
            files.output("the output", &a.output);
        } else {
            // Every level the chain may have (its length is known once the source is read).
            let layers = to.build(None).map_err(|e| bad("--to", e))?.layer_count();
            for i in 0..a.levels.unwrap_or(16) {
                let level = level_path(&a.output, i);
                match save::layer_files(&level, layers, &save) {
                    Some(paths) => paths.into_iter().for_each(|p| {
                        files.output("a level of the output", p);
                    }),
                    None => {
                        files.output("a level of the output", level);
                    }
                }
            }
        }
        for (what, p) in [
            ("--sh", &sh_path),
            ("--preview", &preview_path),
            ("--lut", &lut_path),
        ] {
            if let Some(p) = p {
                files.output(what, p);
            }
        }
        files.check()?;
        Ok(Plan {
            input,
            kind,
            to,
            format,
            size: a.size,
            levels: a.levels,
            mapping,
            exponents,
            compression,
            window,
            irradiance,
            sh_path,
            preview_path,
            lut_path,
            save,
            opts: PrefilterOptions {
                samples: a.samples,
                cube_size: a.cube_size,
                ..Default::default()
            },
        })
    }
}

/// The lobe of each level.
fn lobes(plan: &Plan, levels: usize) -> Vec<Lobe> {
    match (&plan.exponents, plan.kind) {
        (Some(e), LobeKind::Phong) => (0..levels)
            .map(|i| Lobe::Phong {
                exponent: *e.get(i).or(e.last()).unwrap_or(&f64::INFINITY),
            })
            .collect(),
        _ => chain_lobes(plan.kind, &plan.mapping, levels),
    }
}

fn describe(lobe: &Lobe) -> serde_json::Value {
    match *lobe {
        Lobe::Lambert => json!({ "lobe": "lambert" }),
        Lobe::Phong { exponent } => json!({
            "lobe": "phong",
            "exponent": if exponent.is_finite() { json!(exponent) } else { json!("inf") },
        }),
        Lobe::Ggx { roughness } => json!({ "lobe": "ggx", "roughness": roughness }),
    }
}

pub fn run(a: PrefilterArgs) -> Result<(), CliError> {
    let mut plan = Plan::new(&a)?;
    let say = |s: String| {
        if !a.quiet {
            eprintln!("{s}");
        }
    };
    let t0 = Instant::now();
    let limits = mirrorball_io::Limits::default();
    let mut src = load::load(
        &a.input,
        plan.input.from.as_ref(),
        plan.input.layout,
        &limits,
    )?;
    for line in src.prepare(&a.input, plan.input.keep_invalid) {
        say(line);
    }
    let mut env = src.env;
    let energy: Option<EnergyReport> = (plan.compression != Compression::None).then(|| {
        let r = compress(&mut env, plan.compression);
        say(format!(
            "compressed {} texels (luminance max {:.4e} → {:.4e}): {:.3}% of the energy removed",
            r.texels,
            r.max_before,
            r.max_after,
            100.0 * r.fraction_removed
        ));
        r
    });

    // Output geometry.
    let out_proj: Projection = plan.to.build(None).map_err(|e| bad("--to", e))?;
    let size = plan.size.unwrap_or_else(|| match plan.kind {
        LobeKind::Lambert => 32,
        _ => {
            let s = save::default_size(&env, ProjectionKind::Cube).clamp(1, 512);
            if plan.format.is_cube_container() {
                // Largest power of two not above it.
                1 << (31 - s.leading_zeros())
            } else {
                s
            }
        }
    });
    let (w0, h0) = out_proj.layer_extent(size);
    let full = level_count(w0, h0);
    let levels = plan.levels.unwrap_or(full).min(full);
    // A list of values per level must say every level: padding would be a silent guess.
    let listed = match (&plan.mapping, &plan.exponents) {
        (_, Some(e)) => Some(("--exponents", "exponents", e.len())),
        (RoughnessMapping::Custom(r), None) if plan.kind != LobeKind::Lambert => {
            Some(("--mapping", "roughness values", r.len()))
        }
        _ => None,
    };
    if let Some((flag, what, n)) = listed.filter(|&(_, _, n)| n != levels) {
        return Err(CliError::request(format!(
            "{flag} lists {n} {what} but the chain has {levels} levels ({w0}x{h0} down to {}); give {levels}, or --levels {n}",
            if plan.levels.is_some() { "--levels" } else { "1x1" }
        )));
    }
    let lobes = lobes(&plan, levels);
    {
        // The working cube (bordered, with its pyramid, twice when bright texels are split
        // off) is about as fine as level 0 needs, at least 256² and at most 4096², unless
        // --cube-size says; the chain is four channels with its mips.
        let face = plan.opts.cube_size.unwrap_or(size.clamp(256, 4096)) as u64;
        let working = budget::f32_texels(6 * (face + 2) * (face + 2) * 4 / 3, 4) * 2;
        let chain = budget::f32_texels(
            w0 as u64 * h0 as u64 * out_proj.layer_count() as u64 * 4 / 3,
            4,
        );
        let held = budget::f32_texels(
            env.width() as u64 * env.height() as u64 * env.layers().len() as u64,
            env.channels() as u64,
        );
        budget::check(
            &format!(
                "prefiltering into {} {w0}x{h0}x{} (working cube {face}²)",
                out_proj.name(),
                out_proj.layer_count()
            ),
            held,
            working.saturating_add(chain),
            "a smaller --size or --cube-size",
        )?;
    }

    // Prefilter.
    let t1 = Instant::now();
    // Lambert renders level 0 only (the rest are its box mips).
    let rendered = if plan.kind == LobeKind::Lambert {
        1
    } else {
        levels
    };
    let rows = mirrorball_filter::chain_rows(&out_proj, size, rendered);
    let sh9 = sh::project(&env);
    let chain: Vec<EnvMap> = with_progress("prefilter", rows, a.quiet, |counter| {
        plan.opts.progress = Some(counter);
        // The working cube is made as fine as the levels rendered need (no finer than the
        // source), unless --cube-size says otherwise.
        match (plan.kind, plan.irradiance) {
            (LobeKind::Lambert, method) => {
                // One irradiance map; the further levels are its solid-angle-weighted box
                // mips (the irradiance is smooth, and engines read any level).
                let top = match method {
                    IrradianceMethod::Exact => Prefilterer::for_chain(
                        &env,
                        &[Lobe::Lambert],
                        out_proj,
                        size,
                        plan.opts.clone(),
                    )
                    .render(&Lobe::Lambert, out_proj, size),
                    IrradianceMethod::Sh => {
                        irradiance::irradiance_map_sh(&sh9, plan.window, out_proj, size)
                    }
                };
                MipChain::build_levels(&top, MipFilter::Box, levels).into_levels()
            }
            _ => Prefilterer::for_chain(&env, &lobes, out_proj, size, plan.opts.clone())
                .render_chain(&lobes, out_proj, size),
        }
    });
    let t_filter = t1.elapsed();

    // Write the chain.
    let t2 = Instant::now();
    let mut written: Vec<String> = Vec::new();
    if plan.format.is_cube_container() {
        let faces: Vec<Vec<Image>> = chain.iter().map(|l| l.layers().to_vec()).collect();
        mirrorball_io::write_cube(Path::new(&a.output), &faces, &plan.save.write)?;
        written.push(a.output.clone());
    } else {
        for (i, level) in chain.iter().enumerate() {
            let files = save::save(level, &level_path(&a.output, i), &plan.save)?;
            written.extend(files.iter().map(|p| p.display().to_string()));
        }
    }

    // Spherical harmonics and the description of the chain.
    if let Some(p) = &plan.sh_path {
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
        let level_info: Vec<serde_json::Value> = chain
            .iter()
            .zip(&lobes)
            .enumerate()
            .map(|(i, (l, lobe))| {
                let mut v = describe(lobe);
                v["level"] = json!(i);
                v["width"] = json!(l.width());
                v["height"] = json!(l.height());
                v
            })
            .collect();
        let doc = json!({
            "generator": format!("mirrorball {}", env!("CARGO_PKG_VERSION")),
            "source": a.input,
            "output": written,
            "basis": "real spherical harmonics, bands 0-2, index l(l+1)+m, orthonormal over the sphere, in world axes (+Y up, -Z ahead): Y0=0.282095, Y1=0.488603 y, Y2=0.488603 z, Y3=0.488603 x, Y4=1.092548 xy, Y5=1.092548 yz, Y6=0.315392 (3z^2-1), Y7=1.092548 xz, Y8=0.546274 (x^2-y^2)",
            "radiance": coeffs(&sh9),
            "irradiance_over_pi": coeffs(&windowed.lambert()),
            "irradiance_note": "evaluate sum_i c_i Y_i(n) with irradiance_over_pi to get E(n)/pi, the radiance a white Lambertian surface with normal n reflects (Ramamoorthi & Hanrahan 2001: A0 = pi, A1 = 2pi/3, A2 = pi/4, divided by pi); the window is applied",
            "window": window,
            "lobe": match plan.kind { LobeKind::Lambert => "lambert", LobeKind::Phong => "phong", LobeKind::Ggx => "ggx" },
            "roughness_mapping": plan.mapping.name(),
            "roughness_to_level": match plan.mapping {
                RoughnessMapping::Linear => "level = roughness * (levels - 1)",
                RoughnessMapping::Ue4 => "level = levels - 2 + 1.2 * log2(roughness)",
                RoughnessMapping::Filament => "level = (levels - 1) * roughness * (2 - roughness)",
                RoughnessMapping::Custom(_) => "piecewise-linear inverse of the listed roughness values",
            },
            "projection": out_proj.name(),
            "levels": level_info,
            "energy_removed": energy.map(|r| json!({
                "operator": a.compress,
                "texels": r.texels,
                "fraction": r.fraction_removed,
                "energy_before_rgb": r.before,
                "energy_after_rgb": r.after,
                "luminance_max_before": r.max_before,
                "luminance_max_after": r.max_after,
            })),
        });
        let text = serde_json::to_string_pretty(&doc).expect("JSON values serialise");
        mirrorball_io::atomic_write(p, |w| {
            use std::io::Write;
            w.write_all(text.as_bytes())
                .map_err(|e| mirrorball_io::Error::io(p, e))
        })?;
        written.push(p.display().to_string());
    }

    // Preview sheet.
    if let Some(p) = &plan.preview_path {
        let sheet = preview_sheet(&chain, a.preview_exposure);
        mirrorball_io::write_image(
            p,
            &sheet,
            &WriteOptions {
                precision: Some(Precision::U8),
                ..Default::default()
            },
        )?;
        written.push(p.display().to_string());
    }

    // The split-sum table.
    if let Some(p) = &plan.lut_path {
        let lut = BrdfLut::new(a.lut_size, 1024, Visibility::SchlickUe4);
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
                ..Default::default()
            },
        )?;
        written.push(p.display().to_string());
    }

    let detail: Vec<String> = chain
        .iter()
        .zip(&lobes)
        .map(|(l, lobe)| {
            let what = match *lobe {
                Lobe::Lambert => "lambert".to_string(),
                Lobe::Phong { exponent } if exponent.is_finite() => format!("s={exponent:.0}"),
                Lobe::Phong { .. } => "mirror".to_string(),
                Lobe::Ggx { roughness } => format!("r={roughness:.3}"),
            };
            format!("{}:{what}", l.width())
        })
        .collect();
    say(format!(
        "wrote {}: {} {} level(s) [{}] (read {:.2}s, prefilter {:.2}s, write {:.2}s)",
        written.join(", "),
        out_proj.name(),
        chain.len(),
        detail.join(" "),
        (t1 - t0).as_secs_f64(),
        t_filter.as_secs_f64(),
        t2.elapsed().as_secs_f64()
    ));
    Ok(())
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
