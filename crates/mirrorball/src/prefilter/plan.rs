//! `PrefilterRequest → Plan`: the lobe, the output's container, precision and sizes, the
//! roughness or exponents per level, the compression and SH window, the side outputs' paths
//! (SH JSON, preview, BRDF table), and every file read or written, checked before any file
//! is read.

use super::outputs::{beside, check_side_files, level_path};
use super::PrefilterRequest;
use crate::error::Error;
use crate::guard::Files;
use crate::load::InputPlan;
use crate::save::{self, SaveOptions};
use crate::spec::{bad, ProjSpec};
use crate::spec::{parse_flag, parse_layout, parse_precision};
use mirrorball_core::{Layout, Stereo, WorldProjection};
use mirrorball_filter::sh::Window;
use mirrorball_filter::IrradianceMethod;
use mirrorball_filter::{Compression, LobeKind, PrefilterOptions, RoughnessMapping};
use mirrorball_io::{Format, Precision, WriteOptions};
use std::path::{Path, PathBuf};

/// Everything `prefilter` will do, checked before any file is read.
pub struct Plan {
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
}

impl Plan {
    pub fn new(a: &PrefilterRequest) -> Result<Plan, Error> {
        let input = a.input_plan.clone();
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
    fn with_side_outputs(mut self, a: &PrefilterRequest) -> Result<Plan, Error> {
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
                return Err(Error::request(format!(
                    "--preview {}: the preview sheet is a .png",
                    p.display()
                )));
            }
        }
        self.lut_path = a.lut.clone().map(PathBuf::from);
        if let Some(p) = &self.lut_path {
            if !matches!(Format::from_path(p), Some(Format::Exr | Format::Png)) {
                return Err(Error::request(format!(
                    "--lut {}: write the BRDF table as .exr (or .png)",
                    p.display()
                )));
            }
        }
        if a.lut_size == 0 || a.lut_size > 4096 {
            return Err(Error::request(format!(
                "--lut-size: {} is outside 1..=4096",
                a.lut_size
            )));
        }
        Ok(self)
    }

    /// Refuses the job when the outputs' file system lacks room for a chain from level 0 at
    /// `size` (at most four channels), the preview and the BRDF table.
    pub fn check_room(&self, size: u32) -> Result<(), Error> {
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

    /// The chain this plan asks for, as [`super::chain`] takes it.
    pub fn chain_request(&self) -> Result<super::ChainRequest, Error> {
        Ok(super::ChainRequest {
            lobe: self.kind,
            to: self.to.build(None).map_err(|e| bad("--to", e))?,
            size: self.size,
            levels: self.levels,
            mapping: self.mapping.clone(),
            exponents: self.exponents.clone(),
            irradiance: self.irradiance,
            window: self.window,
            opts: self.opts.clone(),
            power_of_two: self.format.is_cube_container(),
        })
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
    fn files(&self) -> Result<Files, Error> {
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
fn output_probe(a: &PrefilterRequest) -> String {
    if Format::from_path(Path::new(&a.output)).is_some_and(|f| f.is_cube_container()) {
        a.output.clone()
    } else {
        level_path(&a.output, 0)
    }
}

/// The output's format (flat outputs are checked with the name of level 0): not JPEG,
/// prefiltered radiance being HDR.
fn output_format(
    a: &PrefilterRequest,
    to: &ProjSpec,
    layout: Option<Layout>,
) -> Result<Format, Error> {
    let format = save::check(&output_probe(a), to.kind, layout)?;
    if format == Format::Jpeg {
        return Err(Error::request(format!(
            "{}: prefiltered radiance is HDR; write .exr, .hdr, .ktx2 or .dds (PNG for previews)",
            a.output
        )));
    }
    Ok(format)
}

/// `--precision` and `--layout`, where the container takes them ([`save::check_flags`]).
fn output_precision(a: &PrefilterRequest, format: Format) -> Result<Option<Precision>, Error> {
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
    a: &PrefilterRequest,
    format: Format,
    to: &ProjSpec,
    save: &SaveOptions,
) -> Result<Option<u32>, Error> {
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
            return Err(Error::request(format!(
                "--size {s}: a cube map's mip chain halves exactly only from a power of two"
            )));
        }
    }
    if let Some(l) = a.levels {
        if l == 0 || l > 16 {
            return Err(Error::request(format!("--levels: {l} is outside 1..=16")));
        }
    }
    Ok(size)
}

/// `--exponents` (Phong only): non-negative numbers, `inf` or `mirror` for a mirror.
fn parse_exponents(a: &PrefilterRequest, kind: LobeKind) -> Result<Option<Vec<f64>>, Error> {
    let Some(s) = &a.exponents else {
        return Ok(None);
    };
    if kind != LobeKind::Phong {
        return Err(Error::request("--exponents applies to --lobe phong"));
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
        Error::request(format!(
            "--exponents: '{t}' is not a non-negative number (or inf)"
        ))
    })
}

/// `--samples` and `--cube-size`, and `--preview-exposure` (checked here, in the order
/// the flags were always checked).
fn prefilter_options(a: &PrefilterRequest) -> Result<PrefilterOptions, Error> {
    if a.samples == 0 || a.samples > 65536 {
        return Err(Error::request(format!(
            "--samples: {} is outside 1..=65536",
            a.samples
        )));
    }
    if let Some(c) = a.cube_size {
        if c == 0 || c > 4096 {
            return Err(Error::request(format!(
                "--cube-size: {c} is outside 1..=4096"
            )));
        }
    }
    if !a.preview_exposure.is_finite() {
        return Err(Error::request("--preview-exposure must be a finite number"));
    }
    Ok(PrefilterOptions {
        samples: a.samples,
        cube_size: a.cube_size,
        ..Default::default()
    })
}

/// `--mapping`: a named mapping or a list of roughness values.
fn parse_mapping(a: &PrefilterRequest) -> Result<RoughnessMapping, Error> {
    RoughnessMapping::parse(&a.mapping).ok_or_else(|| {
        Error::request(format!(
            "--mapping: '{}' is not linear, ue4, filament or a list of roughness values in [0, 1]",
            a.mapping
        ))
    })
}

/// `--compress`.
fn parse_compression(a: &PrefilterRequest) -> Result<Compression, Error> {
    Compression::parse(&a.compress).ok_or_else(|| {
        Error::request(format!(
            "--compress: '{}' is not none, clamp:MAX, soft:MAX or soft:KNEE:MAX (KNEE < MAX, both > 0)",
            a.compress
        ))
    })
}

/// `--sh-window`.
fn parse_window(a: &PrefilterRequest) -> Result<Window, Error> {
    Window::parse(&a.sh_window).ok_or_else(|| {
        Error::request(format!(
            "--sh-window: '{}' is not none, hann[:W], lanczos[:W] or auto",
            a.sh_window
        ))
    })
}
