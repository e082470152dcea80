//! `mirrorball compare`: how close two maps are (the library's `compare`), printed as a
//! line or as JSON, with an optional difference picture.

use crate::error::CliError;
use crate::guard::Files;
use crate::spec::{bad, ProjSpec};
use crate::{load, CompareArgs};
use mirrorball::compare::{compare, write_diff};
use mirrorball_io::Format;
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
    let c = compare(&r.env, &t.env);
    let (psnr, both_sr, worst, same) = (
        c.log_psnr_db,
        c.compared_sr,
        c.max_log_difference,
        !c.test_converted,
    );
    let diff_path = a.diff.as_ref().filter(|_| unwritable.is_none());
    if let Some(d) = diff_path {
        write_diff(&c.differences, d, worst)?;
    }
    if a.json {
        let v = json!({
            "reference": a.reference,
            "test": a.test,
            "log_psnr_db": if psnr.is_finite() { json!(psnr) } else { json!("inf") },
            "compared_sr": both_sr,
            "compared_fraction_of_sphere": both_sr / (4.0 * std::f64::consts::PI),
            "reference_covers_sr": c.reference_covers_sr,
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
