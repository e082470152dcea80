//! `mirrorball analyze`: every projection's distortion and error, measured exactly and
//! drawn, in a folder a person can open (`index.html`), with the plots as SVG files and the
//! numbers as `report.json`.

use crate::error::CliError;
use crate::spec::{bad, ProjSpec};
use crate::AnalyzeArgs;
use mirrorball_analysis::{analyze, html, json, Config, Sizing};
use mirrorball_core::{Projection, ProjectionKind};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The largest edge `--size` accepts: an 8192² disk map is 67 M texels, about a minute.
const MAX_SIZE: u32 = 8192;
/// The largest `--texel-budget`.
const MAX_BUDGET: u64 = 64 << 20;

/// The validated request.
struct Plan {
    projections: Vec<Projection>,
    sizing: Sizing,
    out: PathBuf,
}

fn plan(a: &AnalyzeArgs) -> Result<Plan, CliError> {
    let projections = if a.projections.is_empty() {
        ProjectionKind::ALL
            .iter()
            .map(|k| k.default_projection())
            .collect()
    } else {
        a.projections
            .iter()
            .map(|s| {
                ProjSpec::parse(s)
                    .and_then(|p| p.build(None))
                    .map_err(|e| bad("--projection", e))
            })
            .collect::<Result<Vec<_>, _>>()?
    };
    let sizing = match (a.size, a.texel_budget) {
        (Some(n), _) => Sizing::Size(
            crate::size::Bound {
                min: 1,
                max: MAX_SIZE,
                why: "an 8192² disk map is 67 M texels, about a minute to measure".into(),
            }
            .check("--size", n)?,
        ),
        (None, Some(b)) if b == 0 || b > MAX_BUDGET => {
            return Err(CliError::request(format!(
                "--texel-budget {b} is outside 1..={MAX_BUDGET}"
            )))
        }
        (None, Some(b)) => Sizing::Budget(b),
        (None, None) => Sizing::Budget(6 * 512 * 512),
    };
    let out = PathBuf::from(&a.out);
    if out.exists() && !out.is_dir() {
        return Err(CliError::request(format!(
            "--out {}: exists and is not a folder",
            out.display()
        )));
    }
    let mut files = crate::guard::Files::new();
    files
        .making(mirrorball_io::Folders::MakeAll)
        .output("--out", out.join("index.html"));
    files.check()?;
    Ok(Plan {
        projections,
        sizing,
        out,
    })
}

/// Writes `bytes` to `path` through a temporary file and a rename.
fn write(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    mirrorball_io::atomic_write(path, |w| {
        w.write_all(bytes)
            .map_err(|e| mirrorball_io::Error::io(path, e))
    })
    .map_err(CliError::from)
}

pub fn run(a: AnalyzeArgs) -> Result<(), CliError> {
    let plan = plan(&a)?;
    std::fs::create_dir_all(&plan.out).map_err(|e| {
        CliError::system(format!(
            "{}: cannot create the folder: {e}",
            plan.out.display()
        ))
    })?;
    let t0 = Instant::now();
    if !a.quiet {
        let what = match plan.sizing {
            Sizing::Size(n) => format!("edge size {n}"),
            Sizing::Budget(b) => format!("a budget of {b} texels each"),
        };
        eprintln!(
            "analysing {} projection{} at {what}",
            plan.projections.len(),
            if plan.projections.len() == 1 { "" } else { "s" }
        );
    }
    let cfg = Config {
        projections: plan.projections,
        sizing: plan.sizing,
        ..Default::default()
    };
    let analysis = analyze(&cfg);
    let mut written = Vec::new();
    for f in &analysis.figures {
        let p = plan.out.join(format!("{}.svg", f.id));
        write(&p, f.svg.as_bytes())?;
        written.push(p);
    }
    let p = plan.out.join("report.json");
    write(&p, json(&analysis.report).as_bytes())?;
    written.push(p);
    let index = plan.out.join("index.html");
    write(&index, html(&analysis).as_bytes())?;
    written.push(index.clone());
    if !a.quiet {
        eprintln!(
            "{:<24} {:>16} {:>9} {:>12} {:>10} {:>10}",
            "projection", "layers x size", "used", "texel ratio", "aniso max", "aniso mean"
        );
        for e in &analysis.report.projections {
            let s = &e.stats;
            eprintln!(
                "{:<24} {:>16} {:>8.2}% {:>12.4} {:>10.3} {:>10.4}",
                s.projection,
                format!("{}x{}x{}", s.layers, s.width, s.height),
                100.0 * s.used_area_fraction,
                s.full.ratio,
                s.anisotropy_max.value,
                s.anisotropy_mean
            );
        }
        eprintln!(
            "wrote {} in {:.2}s: open {}",
            mirrorball_core::count(written.len() as u64, "file"),
            t0.elapsed().as_secs_f64(),
            index.display()
        );
    }
    Ok(())
}
