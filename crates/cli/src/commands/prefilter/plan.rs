//! `PrefilterArgs → Plan`: the lobe, the output's container, precision and sizes, the
//! roughness or exponents per level, the compression and SH window, the side outputs' paths
//! (SH JSON, preview, BRDF table), and every file read or written, checked before any file
//! is read.

use super::outputs::{beside, check_side_files, level_path};
use crate::choice::parse_flag;
use crate::commands::convert::parse_precision;
use crate::commands::{parse_layout, InputPlan};
use crate::error::CliError;
use crate::guard::Files;
use crate::save::{self, SaveOptions};
use crate::spec::{bad, ProjSpec};
use crate::PrefilterArgs;
use mirrorball_core::{Layout, Stereo, WorldProjection};
use mirrorball_filter::sh::Window;
use mirrorball_filter::IrradianceMethod;
use mirrorball_filter::{Compression, LobeKind, PrefilterOptions, RoughnessMapping};
use mirrorball_io::{Format, Precision, WriteOptions};
use std::path::{Path, PathBuf};

/// Everything `prefilter` will do, checked before any file is read.
pub(super) struct Plan {
    pub input: InputPlan,
    /// The input file, as given.
    pub source: String,
    /// The output, as given (a container, or the name of the levels' files).
    pub output: String,
    pub kind: LobeKind,
    pub to: ProjSpec,
    pub format: Format,
    pub size: Option<u32>,
    pub levels: Option<usize>,
    pub mapping: RoughnessMapping,
    pub exponents: Option<Vec<f64>>,
    pub compression: Compression,
    /// `--compress` as given (the SH JSON records it).
    pub compress_text: String,
    pub window: Window,
    pub irradiance: IrradianceMethod,
    pub sh_path: Option<PathBuf>,
    pub preview_path: Option<PathBuf>,
    pub preview_exposure: f32,
    pub lut_path: Option<PathBuf>,
    pub lut_size: u32,
    pub save: SaveOptions,
    pub opts: PrefilterOptions,
    pub quiet: bool,
}

impl Plan {
    pub fn new(a: &PrefilterArgs) -> Result<Plan, CliError> {
        let input = crate::commands::input_plan(&a.input_args)?;
        let kind = parse_flag::<LobeKind>("--lobe", &a.lobe)?;
        let to = ProjSpec::parse(&a.to).map_err(|e| bad("--to", e))?;
        let layout = parse_layout("--layout", a.layout.as_deref())?;
        let format = output_format(a, &to, layout)?;
        let precision = output_precision(a, format)?;
        let save = SaveOptions {
            layout,
            write: WriteOptions {
                precision,
                ..Default::default()
            },
            mips: false,
            keep_invalid: input.keep_invalid,
        };
        let size = check_sizes(a, format, &to, &save)?;
        let mapping = parse_mapping(a)?;
        let exponents = parse_exponents(a, kind)?;
        let compression = parse_compression(a)?;
        let window = parse_window(a)?;
        let irradiance = parse_flag::<IrradianceMethod>("--irradiance", &a.irradiance)?;
        let opts = prefilter_options(a)?;
        let plan = Plan {
            input,
            source: a.input.clone(),
            output: a.output.clone(),
            kind,
            to,
            format,
            size,
            levels: a.levels,
            mapping,
            exponents,
            compression,
            compress_text: a.compress.clone(),
            window,
            irradiance,
            sh_path: None,
            preview_path: None,
            preview_exposure: a.preview_exposure,
            lut_path: None,
            lut_size: a.lut_size,
            save,
            opts,
            quiet: a.quiet,
        };
        let plan = plan.with_side_outputs(a)?;
        plan.files()?.check()?;
        if let Some(size) = plan.size {
            plan.check_room(size)?;
        }
        check_side_files(&plan.side_files(), a.overwrite)?;
        Ok(plan)
    }

    /// The paths of the SH JSON, the preview sheet and the BRDF table, each checked.
    fn with_side_outputs(mut self, a: &PrefilterArgs) -> Result<Plan, CliError> {
        self.sh_path = (!a.no_sh).then(|| {
            a.sh.clone()
                .map(PathBuf::from)
                .unwrap_or_else(|| beside(&a.output, ".sh.json"))
        });
        self.preview_path = (!a.no_preview).then(|| {
            a.preview
                .clone()
                .map(PathBuf::from)
                .unwrap_or_else(|| beside(&a.output, "_preview.png"))
        });
        if let Some(p) = &self.preview_path {
            if Format::from_path(p) != Some(Format::Png) {
                return Err(CliError::request(format!(
                    "--preview {}: the preview sheet is a .png",
                    p.display()
                )));
            }
        }
        self.lut_path = a.lut.clone().map(PathBuf::from);
        if let Some(p) = &self.lut_path {
            if !matches!(Format::from_path(p), Some(Format::Exr | Format::Png)) {
                return Err(CliError::request(format!(
                    "--lut {}: write the BRDF table as .exr (or .png)",
                    p.display()
                )));
            }
        }
        if a.lut_size == 0 || a.lut_size > 4096 {
            return Err(CliError::request(format!(
                "--lut-size: {} is outside 1..=4096",
                a.lut_size
            )));
        }
        Ok(self)
    }

    /// Refuses the job when the outputs' file system lacks room for a chain from level 0 at
    /// `size` (at most four channels), the preview and the BRDF table.
    pub fn check_room(&self, size: u32) -> Result<(), CliError> {
        let out = self.to.build(None).map_err(|e| bad("--to", e))?;
        let (w, h) = out.layer_extent(size);
        let chain = w as u64 * h as u64 * out.layer_count() as u64 * 4 / 3;
        let lut = self.lut_path.as_ref().map_or(0, |_| {
            Format::Exr.bytes_estimate(self.lut_size as u64 * self.lut_size as u64, 3, None)
        });
        let preview = self
            .preview_path
            .as_ref()
            .map_or(0, |_| Format::Png.bytes_estimate(chain, 3, None));
        let bytes = self
            .format
            .bytes_estimate(chain, 4, self.save.write.precision)
            .saturating_add(lut + preview);
        self.files()?.room(bytes)
    }

    /// The side outputs that will be written: the SH JSON, the preview sheet, the BRDF
    /// table.
    pub fn side_files(&self) -> Vec<&Path> {
        [&self.sh_path, &self.preview_path, &self.lut_path]
            .into_iter()
            .flatten()
            .map(PathBuf::as_path)
            .collect()
    }

    /// Every file read and written: the input, the container or every level the chain may
    /// have (its length is known once the source is read), and the side outputs.
    fn files(&self) -> Result<Files, CliError> {
        let mut files = Files::new();
        files.input_arg("the input", &self.source);
        if self.format.is_cube_container() {
            files.output("the output", &self.output);
        } else {
            files.named("the output", &self.output);
            let layers = self
                .to
                .build(None)
                .map_err(|e| bad("--to", e))?
                .layer_count();
            for i in 0..self.levels.unwrap_or(16) {
                let level = level_path(&self.output, i);
                match save::layer_files(&level, layers, &self.save) {
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
            ("--sh", &self.sh_path),
            ("--preview", &self.preview_path),
            ("--lut", &self.lut_path),
        ] {
            if let Some(p) = p {
                files.output(what, p);
            }
        }
        Ok(files)
    }
}

/// The output as one file: the cube container, or level 0's file of flat outputs.
fn output_probe(a: &PrefilterArgs) -> String {
    if Format::from_path(Path::new(&a.output)).is_some_and(|f| f.is_cube_container()) {
        a.output.clone()
    } else {
        level_path(&a.output, 0)
    }
}

/// The output's format (flat outputs are checked with the name of level 0): not JPEG,
/// prefiltered radiance being HDR.
fn output_format(
    a: &PrefilterArgs,
    to: &ProjSpec,
    layout: Option<Layout>,
) -> Result<Format, CliError> {
    let format = save::check(&output_probe(a), to.kind, layout)?;
    if format == Format::Jpeg {
        return Err(CliError::request(format!(
            "{}: prefiltered radiance is HDR; write .exr, .hdr, .ktx2 or .dds (PNG for previews)",
            a.output
        )));
    }
    Ok(format)
}

/// `--precision` and `--layout`, where the container takes them ([`save::check_flags`]).
fn output_precision(a: &PrefilterArgs, format: Format) -> Result<Option<Precision>, CliError> {
    let precision = parse_precision(a.precision.as_deref())?;
    let given: &[&str] = if a.layout.is_some() {
        &["--layout"]
    } else {
        &[]
    };
    save::check_flags(&a.output, format, given, precision)?;
    Ok(precision)
}

/// `--size` (within what level 0's file holds; a power of two for a cube container's
/// chain) and `--levels`.
fn check_sizes(
    a: &PrefilterArgs,
    format: Format,
    to: &ProjSpec,
    save: &SaveOptions,
) -> Result<Option<u32>, CliError> {
    let size = match a.size {
        Some(s) => {
            let out = to.build(None).map_err(|e| bad("--to", e))?;
            let level0 = output_probe(a);
            Some(save::size_bound(&level0, out, save, Stereo::Mono).check("--size", s)?)
        }
        None => None,
    };
    if let Some(s) = size {
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
    Ok(size)
}

/// `--exponents` (Phong only): non-negative numbers, `inf` or `mirror` for a mirror.
fn parse_exponents(a: &PrefilterArgs, kind: LobeKind) -> Result<Option<Vec<f64>>, CliError> {
    let Some(s) = &a.exponents else {
        return Ok(None);
    };
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
    v.map(Some).map_err(|t| {
        CliError::request(format!(
            "--exponents: '{t}' is not a non-negative number (or inf)"
        ))
    })
}

/// `--samples` and `--cube-size`, and `--preview-exposure` (checked here, in the order
/// the flags were always checked).
fn prefilter_options(a: &PrefilterArgs) -> Result<PrefilterOptions, CliError> {
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
    Ok(PrefilterOptions {
        samples: a.samples,
        cube_size: a.cube_size,
        ..Default::default()
    })
}

/// `--mapping`: a named mapping or a list of roughness values.
fn parse_mapping(a: &PrefilterArgs) -> Result<RoughnessMapping, CliError> {
    RoughnessMapping::parse(&a.mapping).ok_or_else(|| {
        CliError::request(format!(
            "--mapping: '{}' is not linear, ue4, filament or a list of roughness values in [0, 1]",
            a.mapping
        ))
    })
}

/// `--compress`.
fn parse_compression(a: &PrefilterArgs) -> Result<Compression, CliError> {
    Compression::parse(&a.compress).ok_or_else(|| {
        CliError::request(format!(
            "--compress: '{}' is not none, clamp:MAX, soft:MAX or soft:KNEE:MAX (KNEE < MAX, both > 0)",
            a.compress
        ))
    })
}

/// `--sh-window`.
fn parse_window(a: &PrefilterArgs) -> Result<Window, CliError> {
    Window::parse(&a.sh_window).ok_or_else(|| {
        CliError::request(format!(
            "--sh-window: '{}' is not none, hann[:W], lanczos[:W] or auto",
            a.sh_window
        ))
    })
}
