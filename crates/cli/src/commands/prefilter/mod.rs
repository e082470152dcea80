//! `mirrorball prefilter`: prefiltered lighting (Lambert, Phong, GGX) as a mip chain, with
//! spherical-harmonic coefficients and a preview sheet.
//!
//! `args → Plan (lobe, levels, roughness per level, outputs checked: plan.rs) → read →
//! sanitize → optional clamp/soft compression (energy report) → Prefilterer (working cube,
//! bright split) → one lobe per level (progress bar) → KTX2/DDS cube with the chain, or one
//! image per level → SH JSON → preview PNG (outputs.rs)`.

pub(crate) mod outputs;
mod plan;

use crate::budget;
use crate::error::CliError;
use crate::load;
use crate::progress::with_progress;
use crate::save;
use crate::spec::bad;
use crate::PrefilterArgs;
use mirrorball_core::{count, EnvMap, Projection, ProjectionKind, WorldProjection};
use mirrorball_filter::mip::level_count;
use mirrorball_filter::sh;
use mirrorball_filter::{
    chain_lobes, compress, irradiance, Compression, EnergyReport, IrradianceMethod, Lobe, LobeKind,
    MipChain, MipFilter, Prefilterer, RoughnessMapping,
};
use outputs::Described;
use plan::Plan;
use std::time::Instant;

/// The chain's shape, known once the source is read.
struct Chain {
    projection: Projection,
    /// Level 0's size (as `--size`: face edge, width or diameter).
    size: u32,
    /// Level 0's layer extent.
    extent: (u32, u32),
    levels: usize,
}

pub fn run(a: PrefilterArgs) -> Result<(), CliError> {
    let mut plan = Plan::new(&a)?;
    let t0 = Instant::now();
    let (env, energy) = read(&plan)?;
    let shape = chain_shape(&plan, &env)?;
    if plan.size.is_none() {
        plan.check_room(shape.size)?;
    }
    let lobes = lobes(&plan, shape.levels);
    check_memory(&plan, &shape, &env, &lobes)?;

    let t1 = Instant::now();
    let sh9 = sh::project(&env);
    let chain = prefilter(&mut plan, &env, &shape, &lobes, &sh9);
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
        say(&plan, line);
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
    say(
        &plan,
        format!(
            "wrote {}: {} {} [{}] (read {:.2}s, prefilter {:.2}s, write {:.2}s)",
            written.join(", "),
            shape.projection.name(),
            count(chain.len() as u64, "level"),
            outputs::levels_detail(&chain, &lobes),
            (t1 - t0).as_secs_f64(),
            t_filter.as_secs_f64(),
            t2.elapsed().as_secs_f64()
        ),
    );
    Ok(())
}

/// Prints `s`, unless quiet.
fn say(plan: &Plan, s: String) {
    if !plan.quiet {
        eprintln!("{s}");
    }
}

/// The source, prepared (sanitized unless asked not to), and compressed as `--compress`
/// says, with its energy report.
fn read(plan: &Plan) -> Result<(EnvMap, Option<EnergyReport>), CliError> {
    let (env, notes) = load::read_prepared(&plan.source, &plan.input)?;
    if !plan.quiet {
        notes.iter().for_each(|line| eprintln!("{line}"));
    }
    let mut env = env;
    let energy = (plan.compression != Compression::None).then(|| {
        let r = compress(&mut env, plan.compression);
        say(
            plan,
            format!(
                "compressed {} texels (luminance max {:.4e} → {:.4e}): {:.3}% of the energy removed",
                r.texels,
                r.max_before,
                r.max_after,
                100.0 * r.fraction_removed
            ),
        );
        r
    });
    Ok((env, energy))
}

/// The output's projection, level 0's size (32 for Lambert; else about the source's, at
/// most 512, a power of two in a cube container) and the number of levels; a list of values
/// per level must say every level (padding would be a silent guess).
fn chain_shape(plan: &Plan, env: &EnvMap) -> Result<Chain, CliError> {
    let projection: Projection = plan.to.build(None).map_err(|e| bad("--to", e))?;
    let size = plan.size.unwrap_or_else(|| match plan.kind {
        LobeKind::Lambert => 32,
        _ => {
            let s = save::default_size(env, ProjectionKind::Cube).clamp(1, 512);
            if plan.format.is_cube_container() {
                // Largest power of two not above it.
                1 << (31 - s.leading_zeros())
            } else {
                s
            }
        }
    });
    let (w0, h0) = projection.layer_extent(size);
    let full = level_count(w0, h0);
    let levels = plan.levels.unwrap_or(full).min(full);
    let listed = match (&plan.mapping, &plan.exponents) {
        (_, Some(e)) => Some(("--exponents", "exponent", e.len())),
        (RoughnessMapping::Custom(r), None) if plan.kind != LobeKind::Lambert => {
            Some(("--mapping", "roughness value", r.len()))
        }
        _ => None,
    };
    if let Some((flag, what, n)) = listed.filter(|&(_, _, n)| n != levels) {
        return Err(CliError::request(format!(
            "{flag} lists {} but the chain has {} ({w0}x{h0} down to {}); give {levels}, or --levels {n}",
            count(n as u64, what),
            count(levels as u64, "level"),
            if plan.levels.is_some() { "--levels" } else { "1x1" }
        )));
    }
    Ok(Chain {
        projection,
        size,
        extent: (w0, h0),
        levels,
    })
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

/// The prefilterer's peak (its working cube and pyramids, as fine as the levels rendered
/// need), the chain (the source's channels, with its mips) and the source held meanwhile.
/// Lambert from SH makes no working cube.
fn check_memory(plan: &Plan, shape: &Chain, env: &EnvMap, lobes: &[Lobe]) -> Result<(), CliError> {
    let (w0, h0) = shape.extent;
    let out = shape.projection;
    let working = match (plan.kind, plan.irradiance) {
        (LobeKind::Lambert, IrradianceMethod::Sh) => 0,
        (LobeKind::Lambert, IrradianceMethod::Exact) => {
            Prefilterer::memory_for_chain(env, &[Lobe::Lambert], out, shape.size, &plan.opts)
        }
        _ => Prefilterer::memory_for_chain(env, lobes, out, shape.size, &plan.opts),
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
    plan: &mut Plan,
    env: &EnvMap,
    shape: &Chain,
    lobes: &[Lobe],
    sh9: &sh::Sh9,
) -> Vec<EnvMap> {
    let (out, size, levels) = (shape.projection, shape.size, shape.levels);
    // The work the bar runs to, in the prefilterer's units (none for SH irradiance, which
    // takes no time worth a bar).
    let work = match (plan.kind, plan.irradiance) {
        (LobeKind::Lambert, IrradianceMethod::Sh) => 0,
        (LobeKind::Lambert, IrradianceMethod::Exact) => {
            mirrorball_filter::chain_work(env, &[Lobe::Lambert], out, size, &plan.opts)
        }
        _ => mirrorball_filter::chain_work(env, lobes, out, size, &plan.opts),
    };
    let quiet = plan.quiet;
    with_progress("prefilter", work, quiet, |counter| {
        plan.opts.progress = Some(counter);
        let opts = plan.opts.clone();
        match (plan.kind, plan.irradiance) {
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
                        irradiance::irradiance_map_sh(sh9, plan.window, out, size)
                    }
                };
                MipChain::build_levels(&top, MipFilter::Box, levels).into_levels()
            }
            _ => Prefilterer::for_chain(env, lobes, out, size, opts).render_chain(lobes, out, size),
        }
    })
}
