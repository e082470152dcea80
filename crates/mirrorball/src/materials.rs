//! Materials by name: the `--material NAME[:key=value…]` spec and a scene file's material
//! entries (`docs/render-scene.md`, "Materials") both become a [`MaterialEntry`], which
//! [`material_of`] checks and turns into the renderer's [`Material`].

use crate::spec::parse_dir;
use mirrorball_core::{Choice, UnknownName};
use mirrorball_filter::LobeKind;
use mirrorball_render::{Material, MaterialKind, Ramp, SpecularLobe};
use serde::Deserialize;

/// The keys besides `kind`, `tint` and `f0` that apply to material `kind`.
fn keys(kind: MaterialKind) -> &'static [&'static str] {
    match kind {
        MaterialKind::Greene => &["dc", "sc", "lobe", "exponent", "roughness"],
        MaterialKind::PhongMap => &["specular", "exponent", "light", "ambient"],
        _ => &[],
    }
}

/// A material as a scene file (or a `--material` spec) writes it: its kind and whichever
/// keys it sets.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct MaterialEntry {
    kind: String,
    /// Mirror tint; base colour of fresnel, diffuse and phong-map.
    tint: Option<[f32; 3]>,
    f0: Option<f32>,
    /// Greene: diffuse and specular reflectance.
    dc: Option<[f32; 3]>,
    sc: Option<[f32; 3]>,
    /// Greene: `phong` or `ggx` (as [`LobeKind`] names them).
    lobe: Option<String>,
    /// Phong exponent (Greene's phong lobe, phong-map).
    exponent: Option<f32>,
    /// GGX perceptual roughness (Greene's ggx lobe).
    roughness: Option<f32>,
    /// phong-map: highlight colour, eye-space light direction, ambient term.
    specular: Option<[f32; 3]>,
    light: Option<[f32; 3]>,
    ambient: Option<f32>,
}

/// `r,g,b` (or one value for all three) of key `k` in a spec.
fn spec_colour(k: &str, v: &str) -> Result<[f32; 3], String> {
    let c: Vec<f32> = v
        .split(',')
        .map(|x| x.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("{k}='{v}' is not r,g,b"))?;
    match c[..] {
        [r, g, b] => Ok([r, g, b]),
        [x] => Ok([x; 3]),
        _ => Err(format!("{k}='{v}' is not r,g,b")),
    }
}

/// A number of key `k` in a spec.
fn spec_number(k: &str, v: &str) -> Result<f32, String> {
    v.trim()
        .parse::<f32>()
        .map_err(|_| format!("{k}='{v}' is not a number"))
}

/// Parses a `--material` spec, `NAME[:key=value…]` (see [`material_of`] for the keys), with
/// `--tint` and `--f0` as the defaults of `tint` and `f0`. A spec it cannot take is the
/// request's fault.
pub fn parse_material(spec: &str, tint: [f32; 3], f0: f32) -> Result<Material, crate::Error> {
    material_text(spec, tint, f0).map_err(crate::Error::request)
}

fn material_text(spec: &str, tint: [f32; 3], f0: f32) -> Result<Material, String> {
    let mut parts = spec.split(':');
    let mut e = MaterialEntry {
        kind: parts.next().unwrap_or_default().trim().to_string(),
        tint: Some(tint),
        f0: Some(f0),
        ..MaterialEntry::default()
    };
    for kv in parts {
        let (k, v) = kv
            .split_once('=')
            .ok_or_else(|| format!("'{kv}' in '{spec}' is not key=value"))?;
        match k.trim() {
            "tint" | "colour" | "color" => e.tint = Some(spec_colour(k, v)?),
            "f0" => e.f0 = Some(spec_number(k, v)?),
            "dc" => e.dc = Some(spec_colour(k, v)?),
            "sc" => e.sc = Some(spec_colour(k, v)?),
            "specular" => e.specular = Some(spec_colour(k, v)?),
            "lobe" => e.lobe = Some(v.trim().to_string()),
            "exponent" | "phong" => {
                e.exponent = Some(spec_number(k, v)?);
                if k.trim() == "phong" {
                    e.lobe = Some(LobeKind::Phong.name().into());
                }
            }
            "roughness" | "ggx" => {
                e.roughness = Some(spec_number(k, v)?);
                if k.trim() == "ggx" {
                    e.lobe = Some(LobeKind::Ggx.name().into());
                }
            }
            "ambient" => e.ambient = Some(spec_number(k, v)?),
            "light" => {
                let d = parse_dir(v).map_err(|x| format!("light: {x}"))?;
                e.light = Some(d.as_vec3().to_array());
            }
            other => {
                return Err(format!(
                    "unknown key '{other}' in '{spec}' (known: tint, f0, dc, sc, lobe, exponent, roughness, specular, light, ambient)"
                ))
            }
        }
    }
    entry_text(&e)
}

/// `c` of key `k`, if every channel is finite and non-negative.
fn colour(k: &str, c: [f32; 3]) -> Result<[f32; 3], String> {
    if c.iter().all(|v| v.is_finite() && *v >= 0.0) {
        Ok(c)
    } else {
        Err(format!("{k} {c:?} has a negative or non-finite channel"))
    }
}

/// The material a scene file's (or a `--material` spec's) entry describes, every value
/// checked. An entry it cannot take is the request's fault (a scene file's reader makes it
/// the file's).
pub fn material_of(e: &MaterialEntry) -> Result<Material, crate::Error> {
    entry_text(e).map_err(crate::Error::request)
}

fn entry_text(e: &MaterialEntry) -> Result<Material, String> {
    let tint = colour("tint", e.tint.unwrap_or([1.0; 3]))?;
    let f0 = e.f0.unwrap_or(0.04);
    if !(0.0..=1.0).contains(&f0) {
        return Err(format!("f0 {f0} is outside [0, 1]"));
    }
    let kind = MaterialKind::from_name(&e.kind).ok_or_else(|| {
        format!(
            "unknown material '{}' (known: {})",
            e.kind,
            UnknownName::new::<MaterialKind>(&e.kind).list()
        )
    })?;
    for (key, set) in [
        ("dc", e.dc.is_some()),
        ("sc", e.sc.is_some()),
        ("lobe", e.lobe.is_some()),
        ("exponent", e.exponent.is_some()),
        ("roughness", e.roughness.is_some()),
        ("specular", e.specular.is_some()),
        ("light", e.light.is_some()),
        ("ambient", e.ambient.is_some()),
    ] {
        if set && !keys(kind).contains(&key) {
            return Err(format!("'{key}' does not apply to material '{}'", e.kind));
        }
    }
    Ok(match kind {
        MaterialKind::Mirror => Material::Mirror { tint },
        MaterialKind::Fresnel => Material::Fresnel { f0, base: tint },
        MaterialKind::CheapChrome => Material::CheapChrome {
            ramp: Ramp::chrome(),
        },
        MaterialKind::Diffuse => Material::diffuse(tint),
        MaterialKind::Greene => greene(e)?,
        MaterialKind::PhongMap => phong_map(e, tint)?,
    })
}

/// Greene's `dc·D + sc·S`: a Phong lobe (by default, exponent 32) or, given a roughness, a
/// GGX one (by default, roughness 0.3).
fn greene(e: &MaterialEntry) -> Result<Material, String> {
    let kind = match e.lobe.as_deref() {
        Some(name) => LobeKind::from_name(name),
        None if e.roughness.is_some() => Some(LobeKind::Ggx),
        None => Some(LobeKind::Phong),
    };
    let lobe = match kind {
        Some(LobeKind::Phong) => {
            if e.roughness.is_some() {
                return Err("'roughness' is for the ggx lobe; phong takes 'exponent'".into());
            }
            SpecularLobe::Phong {
                exponent: e.exponent.unwrap_or(32.0) as f64,
            }
        }
        Some(LobeKind::Ggx) => {
            if e.exponent.is_some() {
                return Err("'exponent' is for the phong lobe; ggx takes 'roughness'".into());
            }
            SpecularLobe::Ggx {
                roughness: e.roughness.unwrap_or(0.3) as f64,
            }
        }
        Some(LobeKind::Lambert) | None => {
            let given = e.lobe.as_deref().unwrap_or_default().to_ascii_lowercase();
            let offered = [LobeKind::Phong.name(), LobeKind::Ggx.name()];
            return Err(format!("lobe {}", UnknownName::among(&given, offered)));
        }
    };
    // An infinite exponent (a mirror, to the filter crate) is refused here.
    if !lobe.is_valid()
        || matches!(lobe, SpecularLobe::Phong { exponent } if exponent.is_infinite())
    {
        // The parameters were read as `f32`: print them so.
        return Err(match lobe {
            SpecularLobe::Ggx { roughness } => {
                format!("ggx roughness {} is outside [0, 1]", roughness as f32)
            }
            _ => format!(
                "phong exponent {} must be a number ≥ 0",
                e.exponent.unwrap_or(32.0)
            ),
        });
    }
    Ok(Material::Greene {
        dc: colour("dc", e.dc.unwrap_or([0.2; 3]))?,
        sc: colour("sc", e.sc.unwrap_or([0.8; 3]))?,
        lobe,
    })
}

/// Highlights from a sphere map of Phong intensities: diffuse colour `tint` (grey unless
/// the entry sets it), highlight colour `specular`, exponent 32, an eye-space light from
/// (0.3, 0.5, 1), ambient 0.1, unless the entry says otherwise.
fn phong_map(e: &MaterialEntry, tint: [f32; 3]) -> Result<Material, String> {
    let exponent = e.exponent.unwrap_or(32.0);
    if !(exponent.is_finite() && exponent >= 0.0) {
        return Err(format!("exponent {exponent} must be ≥ 0"));
    }
    let light = e.light.unwrap_or([0.3, 0.5, 1.0]);
    if !light.iter().all(|v| v.is_finite()) || light == [0.0; 3] {
        return Err(format!("light {light:?} points nowhere"));
    }
    let ambient = e.ambient.unwrap_or(0.1);
    if !(ambient.is_finite() && ambient >= 0.0) {
        return Err(format!("ambient {ambient} must be ≥ 0"));
    }
    Ok(Material::PhongMap {
        colour: if e.tint.is_some() { tint } else { [0.5; 3] },
        specular: colour("specular", e.specular.unwrap_or([1.0; 3]))?,
        exponent,
        light,
        ambient,
    })
}
