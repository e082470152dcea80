//! `mirrorball compare`: how close two maps are, in log-domain PSNR.

use crate::error::CliError;
use crate::spec::{bad, ProjSpec};
use crate::{load, CompareArgs};
use mirrorball_core::metrics::log_psnr;
use mirrorball_core::{resample_to_extent, ResampleOptions};

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
    let limits = mirrorball_io::Limits::default();
    let mut r = load::load(&a.reference, from.as_ref(), None, &limits)?;
    let mut t = load::load(&a.test, test_from.as_ref(), None, &limits)?;
    for (name, src) in [(&a.reference, &r), (&a.test, &t)] {
        eprintln!("{name}: {} ({})", src.env.projection().name(), src.decided);
    }
    r.env.sanitize();
    t.env.sanitize();
    let same = r.env.projection() == t.env.projection()
        && r.env.width() == t.env.width()
        && r.env.height() == t.env.height();
    let test = if same {
        t.env
    } else {
        resample_to_extent(
            &t.env,
            *r.env.projection(),
            r.env.width(),
            r.env.height(),
            &ResampleOptions::default(),
        )
    };
    let psnr = log_psnr(&r.env, &test).expect("same shape");
    println!(
        "log-PSNR {psnr:.2} dB{}",
        if same {
            ""
        } else {
            " (test map converted to the reference's projection and size)"
        }
    );
    Ok(())
}
