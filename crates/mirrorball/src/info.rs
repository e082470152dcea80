//! What a file holds, said for people and as JSON (`mirrorball info`): an environment map
//! (its container, projection and how it was decided, size, coverage, radiance statistics,
//! a photo's GPano panorama), one face of a set of six (read with its set), spherical
//! harmonics (`sh.json`, Filament's `sh.txt`), or a picture that records what it is (a
//! preview sheet, a BRDF table).

use crate::error::Error;
use crate::load::{self, InputPlan};
use mirrorball_core::WorldProjection;
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::path::Path;

/// A file described: the lines for people and the same as JSON.
pub struct Info {
    pub text: String,
    pub json: Value,
}

/// What `input` holds, read as `plan` says.
pub fn describe(input: &str, plan: &InputPlan) -> Result<Info, Error> {
    if let Some(sh) = mirrorball_io::read_sh(Path::new(input))? {
        return Ok(Info {
            text: sh.info_text(input),
            json: sh.info_json(input),
        });
    }
    if let Some(p) = mirrorball_io::picture_of(Path::new(input)) {
        return Ok(Info {
            text: format!(
                "file:        {input}\nprojection:  {} ({})\n",
                p.projection(),
                p.describe()
            ),
            json: json!({"file": input, "projection": p.projection(), "content": p.describe()}),
        });
    }
    // One face of a set (`cube/px.hdr`) is read with its set, as `{face}` reads it.
    let set = (plan.from.is_none() && plan.layout.is_none())
        .then(|| mirrorball_io::layer_set(input))
        .flatten();
    let mut src = load::load(
        set.as_deref().unwrap_or(input),
        plan.from.as_ref(),
        plan.layout,
        &mirrorball_io::Limits::default(),
    )?;
    if let Some(set) = &set {
        src.decided = format!("{}; one file of the set {set}", src.decided);
    }
    let panorama = photo_panorama(input, src.env.width(), src.env.height())?;
    Ok(Info {
        text: map_text(input, &src, panorama.as_deref()),
        json: map_json(input, &src, panorama.as_deref()),
    })
}

/// A map's description as JSON.
fn map_json(input: &str, src: &load::Source, panorama: Option<&str>) -> Value {
    let (env, p) = (&src.env, src.env.projection());
    let s = env.stats();
    json!({
        "file": input,
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
    })
}

/// A map's description for people, a line each.
fn map_text(input: &str, src: &load::Source, panorama: Option<&str>) -> String {
    let (env, p) = (&src.env, src.env.projection());
    let s = env.stats();
    let mut t = String::new();
    let _ = writeln!(t, "file:        {input}");
    let _ = writeln!(t, "container:   {}", src.description);
    let _ = writeln!(t, "projection:  {} ({})", p.name(), src.decided);
    if let Some(pano) = panorama {
        let _ = writeln!(t, "panorama:    {pano}");
    }
    let layers = match env.layers().len() {
        1 => String::new(),
        n => format!(" x {n} layers"),
    };
    let _ = writeln!(
        t,
        "size:        {}x{}{layers}, {} channels",
        env.width(),
        env.height(),
        env.channels()
    );
    let _ = writeln!(
        t,
        "covers:      {:.6} sr ({:.2}% of the sphere)",
        s.solid_angle,
        s.solid_angle / (4.0 * std::f64::consts::PI) * 100.0
    );
    let _ = writeln!(t, "radiance:    min {:.6e}  max {:.6e}", s.min, s.max);
    let _ = writeln!(
        t,
        "mean (RGB):  {:.6e} {:.6e} {:.6e}  (weighted by solid angle)",
        s.mean[0], s.mean[1], s.mean[2]
    );
    let _ = writeln!(
        t,
        "invalid:     {} NaN, {} infinite, {} negative colour values ({} in all; convert and prefilter set them to 0)",
        s.nan,
        s.inf,
        s.negative,
        s.nan + s.inf + s.negative
    );
    t
}

/// The extension of `input`, lowercase.
pub fn extension(input: &str) -> Option<String> {
    let ext = Path::new(input).extension()?;
    Some(ext.to_string_lossy().to_ascii_lowercase())
}

/// What a PNG's or JPEG's GPano XMP says: `None` for other files and for pictures
/// without it.
pub fn photo_panorama(input: &str, w: u32, h: u32) -> Result<Option<String>, Error> {
    let photo = matches!(extension(input).as_deref(), Some("png" | "jpg" | "jpeg"));
    if !photo || input.contains(crate::load::FACE) {
        return Ok(None);
    }
    let Some(xmp) = mirrorball_io::read_xmp(Path::new(input))? else {
        return Ok(None);
    };
    Ok(
        mirrorball_spherical::gpano::parse(&xmp, w, h).map(|r| match r {
            Ok(c) => {
                let as_read = match c.mapping() {
                    Some(m) => format!("{}", m.projection()),
                    None => "off-centre, not a mirrorball projection".into(),
                };
                format!(
                    "GPano equirectangular, {}x{} of a {}x{} panorama at ({}, {}): {as_read}",
                    c.width, c.height, c.full_width, c.full_height, c.left, c.top
                )
            }
            Err(e) => format!("GPano: {e}"),
        }),
    )
}
