//! `mirrorball info`: what a file holds.

use crate::error::CliError;
use crate::{load, InfoArgs};
use mirrorball_core::WorldProjection;

pub fn run(a: InfoArgs) -> Result<(), CliError> {
    if super::tag::is_movie(&a.input) {
        return super::tag::info(&a.input, a.json);
    }
    let input = crate::commands::input_plan(&a.input_args)?;
    let src = load::load(
        &a.input,
        input.from.as_ref(),
        input.layout,
        &mirrorball_io::Limits::default(),
    )?;
    let env = &src.env;
    let s = env.stats();
    let p = env.projection();
    let panorama = super::tag::photo_panorama(&a.input, env.width(), env.height())?;
    if a.json {
        let v = serde_json::json!({
            "file": a.input,
            "container": src.description,
            "projection": p.name(),
            "spec": p.to_string(),
            "decided": src.decided,
            "layers": env.layers().len(),
            "width": env.width(),
            "height": env.height(),
            "channels": env.channels(),
            "solid_angle_sr": s.solid_angle,
            "covered_solid_angle_sr": p.covered_solid_angle(),
            "min": s.min,
            "max": s.max,
            "mean_rgb": s.mean,
            "nan_values": s.nan,
            "inf_values": s.inf,
            "negative_values": s.negative,
            "panorama": panorama,
        });
        println!(
            "{}",
            serde_json::to_string_pretty(&v).expect("serialisable")
        );
        return Ok(());
    }
    println!("file:        {}", a.input);
    println!("container:   {}", src.description);
    println!("projection:  {} ({})", p.name(), src.decided);
    if let Some(pano) = &panorama {
        println!("panorama:    {pano}");
    }
    println!(
        "size:        {}x{}{}, {} channels",
        env.width(),
        env.height(),
        if env.layers().len() > 1 {
            format!(" x {} layers", env.layers().len())
        } else {
            String::new()
        },
        env.channels()
    );
    println!(
        "covers:      {:.6} sr ({:.2}% of the sphere)",
        s.solid_angle,
        s.solid_angle / (4.0 * std::f64::consts::PI) * 100.0
    );
    println!("radiance:    min {:.6e}  max {:.6e}", s.min, s.max);
    println!(
        "mean (RGB):  {:.6e} {:.6e} {:.6e}  (weighted by solid angle)",
        s.mean[0], s.mean[1], s.mean[2]
    );
    println!(
        "invalid:     {} NaN, {} infinite, {} negative colour values ({} in all; convert and prefilter set them to 0)",
        s.nan,
        s.inf,
        s.negative,
        s.nan + s.inf + s.negative
    );
    Ok(())
}
