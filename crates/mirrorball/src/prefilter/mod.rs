//! Prefiltered lighting (Lambert, Phong, GGX) as a mip chain, with spherical-harmonic
//! coefficients and a preview sheet: what `mirrorball prefilter` writes.
//!
//! `PrefilterRequest → Plan (lobe, levels, roughness per level, outputs checked: plan.rs) → read →
//! sanitize → optional clamp/soft compression (energy report) → Prefilterer (working cube,
//! bright split) → one lobe per level (progress bar) → KTX2/DDS cube with the chain, or one
//! image per level → SH JSON → preview PNG (outputs.rs)`.

pub mod outputs;
mod plan;

use crate::budget;
use crate::error::Error;
use crate::hooks::Hooks;
use crate::load::{self, InputPlan};
use crate::save;
use mirrorball_core::{count, EnvMap, Projection, ProjectionKind, WorldProjection};
use mirrorball_filter::mip::level_count;
use mirrorball_filter::sh;
use mirrorball_filter::sh::Window;
use mirrorball_filter::{
    chain_lobes, compress, irradiance, Compression, EnergyReport, IrradianceMethod, Lobe, LobeKind,
    MipChain, MipFilter, PrefilterOptions, Prefilterer, RoughnessMapping,
};
use outputs::Described;
pub use plan::Plan;
use std::time::Instant;

/// A prefiltered chain asked for in memory, apart from any file: the lobe and what each
/// level holds. [`shape`] works out its levels from a source, [`chain`] makes it; `run`
/// makes the command line's chain through the same two.
#[derive(Clone, Debug)]
pub struct ChainRequest {
    pub lobe: LobeKind,
    /// The chain's projection.
    pub to: Projection,
    /// Level 0's size (as `--size`); `None`: 32 for Lambert, else about the source's
    /// resolution, at most 512.
    pub size: Option<u32>,
    /// How many levels (`None`: down to 1×1).
    pub levels: Option<usize>,
    /// Roughness per level (GGX, Phong without exponents).
    pub mapping: RoughnessMapping,
    /// Phong's exponent per level, in place of the mapping.
    pub exponents: Option<Vec<f64>>,
    /// Lambert's irradiance: exact or from the SH9.
    pub irradiance: IrradianceMethod,
    /// The SH window of Lambert's irradiance from the SH9.
    pub window: Window,
    /// Samples per texel and the working cube.
    pub opts: PrefilterOptions,
    /// Level 0's default size taken down to a power of two (a cube container's chain halves
    /// exactly).
    pub power_of_two: bool,
}

impl ChainRequest {
    /// `lobe` into `to` with the command line's defaults (linear roughness, exact
    /// irradiance, 128 samples).
    pub fn new(lobe: LobeKind, to: Projection) -> ChainRequest {
        ChainRequest {
            lobe,
            to,
            size: None,
            levels: None,
            mapping: RoughnessMapping::Linear,
            exponents: None,
            irradiance: IrradianceMethod::Exact,
            window: Window::None,
            opts: PrefilterOptions::default(),
            power_of_two: false,
        }
    }
}

/// A chain's shape, known once the source is read ([`shape`]).
#[derive(Clone, Copy, Debug)]
pub struct Shape {
    pub projection: Projection,
    /// Level 0's size (as `--size`: face edge, width or diameter).
    pub size: u32,
    /// Level 0's layer extent.
    pub extent: (u32, u32),
    pub levels: usize,
}

/// A chain made by [`chain`]: its levels, each level's lobe and the source's SH9.
pub struct Prefiltered {
    pub levels: Vec<EnvMap>,
    pub lobes: Vec<Lobe>,
    pub sh9: sh::Sh9,
}

/// The chain `req` asks for of `env`, made as [`run`] makes it (checked against the memory
/// budget first), with a progress bar through `hooks`.
pub fn chain(
    env: &EnvMap,
    req: &ChainRequest,
    shape: &Shape,
    hooks: &dyn Hooks,
) -> Result<Prefiltered, Error> {
    let lobes = lobes(req, shape.levels);
    check_memory(req, shape, env, &lobes)?;
    let sh9 = sh::project(env);
    let levels = prefilter(req, env, shape, &lobes, &sh9, hooks);
    Ok(Prefiltered { levels, lobes, sh9 })
}

/// What to prefilter, as plain values: the command line's `prefilter` flags (each
/// documented there), their text as given.
#[derive(Clone, Debug)]
pub struct PrefilterRequest {
    pub input: String,
    pub output: String,
    pub lobe: String,
    pub size: Option<i64>,
    pub to: String,
    pub levels: Option<usize>,
    pub mapping: String,
    pub exponents: Option<String>,
    pub samples: u32,
    pub cube_size: Option<u32>,
    pub compress: String,
    pub sh_window: String,
    pub irradiance: String,
    pub sh: Option<String>,
    pub no_sh: bool,
    pub preview: Option<String>,
    pub no_preview: bool,
    pub preview_exposure: f32,
    pub lut: Option<String>,
    pub lut_size: u32,
    pub overwrite: bool,
    pub layout: Option<String>,
    pub precision: Option<String>,
    pub input_plan: InputPlan,
}

impl PrefilterRequest {
    /// The command line's defaults for `lobe` from `input` to `output`.
    pub fn new(input: &str, output: &str, lobe: &str) -> PrefilterRequest {
        PrefilterRequest {
            input: input.into(),
            output: output.into(),
            lobe: lobe.into(),
            size: None,
            to: "cube".into(),
            levels: None,
            mapping: "linear".into(),
            exponents: None,
            samples: 128,
            cube_size: None,
            compress: "none".into(),
            sh_window: "none".into(),
            irradiance: "exact".into(),
            sh: None,
            no_sh: false,
            preview: None,
            no_preview: false,
            preview_exposure: 0.0,
            lut: None,
            lut_size: 128,
            overwrite: false,
            layout: None,
            precision: None,
            input_plan: InputPlan::default(),
        }
    }
}

/// Prefilters what `a` asks for and writes its files, saying what it does through `hooks`.
pub fn run(a: &PrefilterRequest, hooks: &dyn Hooks) -> Result<(), Error> {
    let plan = Plan::new(a)?;
    let t0 = Instant::now();
    let (env, energy) = read(&plan, hooks)?;
    let req = plan.chain_request()?;
    let shape = shape(&env, &req)?;
    if plan.size.is_none() {
        plan.check_room(shape.size)?;
    }

    let t1 = Instant::now();
    let Prefiltered {
        levels: chain,
        lobes,
        sh9,
    } = self::chain(&env, &req, &shape, hooks)?;
    let t_filter = t1.elapsed();

    let t2 = Instant::now();
    let (mut written, report) = outputs::write_chain(&plan, &chain)?;
    outputs::record_side_files(&plan.side_files())?;
    // Float holds the values; else the source's highlights are tamed first, under the
    // container's largest value (the energy that removes is reported).
    let keep: Vec<String> = crate::fit::precision_advice(report.storage)
        .into_iter()
        .chain([format!(
            "--compress soft:{}",
            report.storage.range().least_max()
        )])
        .collect();
    if let Some(line) = report.line(&plan.output, &keep) {
        hooks.note(&line);
    }
    if let Some(p) = &plan.sh_path {
        let described = Described {
            chain: &chain,
            lobes: &lobes,
            projection: &shape.projection,
            energy,
            written: &written,
        };
        outputs::write_sh(&plan, p, &sh9, &described)?;
        written.push(p.display().to_string());
    }
    if let Some(p) = &plan.preview_path {
        outputs::write_preview(&plan, p, &chain)?;
        written.push(p.display().to_string());
    }
    if let Some(p) = &plan.lut_path {
        outputs::write_lut(&plan, p)?;
        written.push(p.display().to_string());
    }
    hooks.note(&format!(
        "wrote {}: {} {} [{}] (read {:.2}s, prefilter {:.2}s, write {:.2}s)",
        written.join(", "),
        shape.projection.name(),
        count(chain.len() as u64, "level"),
        outputs::levels_detail(&chain, &lobes),
        (t1 - t0).as_secs_f64(),
        t_filter.as_secs_f64(),
        t2.elapsed().as_secs_f64()
    ));
    Ok(())
}

/// The source, prepared (sanitized unless asked not to), and compressed as `--compress`
/// says, with its energy report.
fn read(plan: &Plan, hooks: &dyn Hooks) -> Result<(EnvMap, Option<EnergyReport>), Error> {
    let (env, notes) = load::read_prepared(&plan.source, &plan.input)?;
    notes.iter().for_each(|line| hooks.note(line));
    let mut env = env;
    let energy = (plan.compression != Compression::None).then(|| {
        let r = compress(&mut env, plan.compression);
        hooks.note(&format!(
            "compressed {} texels (luminance max {:.4e} → {:.4e}): {:.3}% of the energy removed",
            r.texels,
            r.max_before,
            r.max_after,
            100.0 * r.fraction_removed
        ));
        r
    });
    Ok((env, energy))
}

/// The shape of the chain `req` asks for of `env`: level 0's size (32 for Lambert; else
/// about the source's, at most 512, a power of two where `req.power_of_two`) and the number
/// of levels; a list of values per level must say every level (padding would be a silent
/// guess).
pub fn shape(env: &EnvMap, req: &ChainRequest) -> Result<Shape, Error> {
    let projection = req.to;
    let size = req.size.unwrap_or_else(|| match req.lobe {
        LobeKind::Lambert => 32,
        _ => {
            let s = save::default_size(env, ProjectionKind::Cube).clamp(1, 512);
            if req.power_of_two {
                // Largest power of two not above it.
                1 << (31 - s.leading_zeros())
            } else {
                s
            }
        }
    });
    let (w0, h0) = projection.layer_extent(size);
    let full = level_count(w0, h0);
    let levels = req.levels.unwrap_or(full).min(full);
    let listed = match (&req.mapping, &req.exponents) {
        (_, Some(e)) => Some(("--exponents", "exponent", e.len())),
        (RoughnessMapping::Custom(r), None) if req.lobe != LobeKind::Lambert => {
            Some(("--mapping", "roughness value", r.len()))
        }
        _ => None,
    };
    if let Some((flag, what, n)) = listed.filter(|&(_, _, n)| n != levels) {
        return Err(Error::request(format!(
            "{flag} lists {} but the chain has {} ({w0}x{h0} down to {}); give {levels}, or --levels {n}",
            count(n as u64, what),
            count(levels as u64, "level"),
            if req.levels.is_some() { "--levels" } else { "1x1" }
        )));
    }
    Ok(Shape {
        projection,
        size,
        extent: (w0, h0),
        levels,
    })
}

/// The lobe of each level.
fn lobes(req: &ChainRequest, levels: usize) -> Vec<Lobe> {
    match (&req.exponents, req.lobe) {
        (Some(e), LobeKind::Phong) => (0..levels)
            .map(|i| Lobe::Phong {
                exponent: *e.get(i).or(e.last()).unwrap_or(&f64::INFINITY),
            })
            .collect(),
        _ => chain_lobes(req.lobe, &req.mapping, levels),
    }
}

/// The prefilterer's peak (its working cube and pyramids, as fine as the levels rendered
/// need), the chain (the source's channels, with its mips) and the source held meanwhile.
/// Lambert from SH makes no working cube.
fn check_memory(
    req: &ChainRequest,
    shape: &Shape,
    env: &EnvMap,
    lobes: &[Lobe],
) -> Result<(), Error> {
    let (w0, h0) = shape.extent;
    let out = shape.projection;
    let working = match (req.lobe, req.irradiance) {
        (LobeKind::Lambert, IrradianceMethod::Sh) => 0,
        (LobeKind::Lambert, IrradianceMethod::Exact) => {
            Prefilterer::memory_for_chain(env, &[Lobe::Lambert], out, shape.size, &req.opts)
        }
        _ => Prefilterer::memory_for_chain(env, lobes, out, shape.size, &req.opts),
    };
    let chain = w0 as u64 * h0 as u64 * out.layer_count() as u64;
    budget::check_prefilter(
        &format!(
            "prefiltering into {} {w0}x{h0}x{}",
            out.name(),
            out.layer_count()
        ),
        env,
        working,
        chain * 4 / 3,
        "a smaller --size or --cube-size",
    )
}

/// The chain, with a progress bar. Lambert renders level 0 only: one irradiance
/// map, the further levels its solid-angle-weighted box mips (the irradiance is smooth, and
/// engines read any level). The working cube is made as fine as the levels rendered need
/// (no finer than the source), unless --cube-size says otherwise.
fn prefilter(
    req: &ChainRequest,
    env: &EnvMap,
    shape: &Shape,
    lobes: &[Lobe],
    sh9: &sh::Sh9,
    hooks: &dyn Hooks,
) -> Vec<EnvMap> {
    let (out, size, levels) = (shape.projection, shape.size, shape.levels);
    // The work the bar runs to, in the prefilterer's units (none for SH irradiance, which
    // takes no time worth a bar).
    let work = match (req.lobe, req.irradiance) {
        (LobeKind::Lambert, IrradianceMethod::Sh) => 0,
        (LobeKind::Lambert, IrradianceMethod::Exact) => {
            mirrorball_filter::chain_work(env, &[Lobe::Lambert], out, size, &req.opts)
        }
        _ => mirrorball_filter::chain_work(env, lobes, out, size, &req.opts),
    };
    let mut chain = Vec::new();
    hooks.progress("prefilter", work, &mut |counter| {
        let mut opts = req.opts.clone();
        opts.progress = Some(counter);
        chain = match (req.lobe, req.irradiance) {
            (LobeKind::Lambert, method) => {
                let top = match method {
                    IrradianceMethod::Exact => {
                        Prefilterer::for_chain(env, &[Lobe::Lambert], out, size, opts).render(
                            &Lobe::Lambert,
                            out,
                            size,
                        )
                    }
                    IrradianceMethod::Sh => {
                        irradiance::irradiance_map_sh(sh9, req.window, out, size)
                    }
                };
                MipChain::build_levels(&top, MipFilter::Box, levels).into_levels()
            }
            _ => Prefilterer::for_chain(env, lobes, out, size, opts).render_chain(lobes, out, size),
        }
    });
    chain
}
