//! `mirrorball render`: environment-mapped objects, as each indexing mode truly behaves.
//!
//! `args → RenderPlan` (every option parsed and checked, the output's folder and format
//! checked, the scene file read) `→` environment and meshes loaded `→`
//! `mirrorball_render::render` for each frame `→` PNG/JPEG (exposure, tone curve, sRGB) or
//! EXR/HDR (linear) `→` diagnostic channels as separate float EXRs beside the image.

use super::InputPlan;
use crate::budget;
use crate::error::CliError;
use crate::guard::Files;
use crate::progress::with_progress;
use crate::spec::{bad, parse_dir, ProjSpec};
use crate::{load, RenderArgs};
use mirrorball_core::glam::{Mat4, Vec3};
use mirrorball_core::{resample, EnvMap, Image, ResampleOptions, WorldProjection};
use mirrorball_core::{Choice, Fault, UnknownName};
use mirrorball_io::{Format, Precision, WriteOptions};
use mirrorball_render::mesh::MAX_TRIANGLES;
use mirrorball_render::tone::{self, Tone};
use mirrorball_render::{
    environment_filter, Attach, Builtin, Camera, Environment, Filter, Indexing, Lens, Material,
    Mesh, Object, Ramp, Scene, Settings, SpecularLobe,
};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::sync::Arc;

/// Where a mesh comes from.
#[derive(Clone, Debug)]
enum MeshSource {
    Builtin(Builtin, u32),
    File(PathBuf),
}

/// One object to load.
#[derive(Clone, Debug)]
struct ObjectPlan {
    source: MeshSource,
    model: Mat4,
    /// Centre the file's mesh and scale it to unit size before `model`.
    normalize: bool,
    material: Material,
}

/// Everything `render` will do, checked.
struct RenderPlan {
    objects: Vec<ObjectPlan>,
    env_file: Option<String>,
    input: InputPlan,
    env_as: Option<(ProjSpec, u32)>,
    attach: Attach,
    filter: Filter,
    intensity: f32,
    background: bool,
    camera: Camera,
    settings: Settings,
    exposure: f32,
    tone: Tone,
    output: PathBuf,
    format: Format,
    frames: u32,
    /// Write the texture-space diagram beside each frame.
    diagnostics: bool,
    /// Fisheye lens and full field of view.
    fisheye: Option<(mirrorball_core::Lens, f64)>,
    /// Pan since the previous frame, radians (motion blur).
    pan_blur: Option<f32>,
    quiet: bool,
}

fn parse_vec3(option: &str, s: &str) -> Result<Vec3, CliError> {
    let d = parse_dir(s).map_err(|e| bad(option, e))?;
    Ok(d.as_vec3())
}

fn parse_point(option: &str, s: &str) -> Result<Vec3, CliError> {
    let parts: Vec<f32> = s
        .split(',')
        .map(|p| p.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad(option, format!("'{s}' is not a point x,y,z")))?;
    if parts.len() != 3 || parts.iter().any(|v| !v.is_finite()) {
        return Err(bad(option, format!("'{s}' is not a point x,y,z")));
    }
    Ok(Vec3::new(parts[0], parts[1], parts[2]))
}

fn parse_colour(option: &str, s: &str) -> Result<[f32; 3], CliError> {
    let v = parse_point(option, s)?;
    if v.min_element() < 0.0 {
        return Err(bad(option, format!("'{s}' has a negative channel")));
    }
    Ok(v.to_array())
}

fn parse_size(s: &str) -> Result<(u32, u32), CliError> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| bad("--size", format!("'{s}' is not WIDTHxHEIGHT")))?;
    let p = |v: &str| {
        v.trim()
            .parse::<u32>()
            .ok()
            .filter(|&n| (1..=16384).contains(&n))
            .ok_or_else(|| bad("--size", format!("'{s}': each side must be 1..=16384")))
    };
    Ok((p(w)?, p(h)?))
}

/// Parses a `--material` spec, `NAME[:key=value…]` (see [`material_of`] for the keys), with
/// `--tint` and `--f0` as the defaults of `tint` and `f0`.
fn parse_material(spec: &str, tint: [f32; 3], f0: f32) -> Result<Material, String> {
    let mut parts = spec.split(':');
    let mut e = MaterialEntry {
        kind: parts.next().unwrap_or_default().trim().to_string(),
        tint: Some(tint),
        f0: Some(f0),
        ..MaterialEntry::default()
    };
    let colour = |k: &str, v: &str| -> Result<[f32; 3], String> {
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
    };
    let num = |k: &str, v: &str| -> Result<f32, String> {
        v.trim()
            .parse::<f32>()
            .map_err(|_| format!("{k}='{v}' is not a number"))
    };
    for kv in parts {
        let (k, v) = kv
            .split_once('=')
            .ok_or_else(|| format!("'{kv}' in '{spec}' is not key=value"))?;
        match k.trim() {
            "tint" | "colour" | "color" => e.tint = Some(colour(k, v)?),
            "f0" => e.f0 = Some(num(k, v)?),
            "dc" => e.dc = Some(colour(k, v)?),
            "sc" => e.sc = Some(colour(k, v)?),
            "specular" => e.specular = Some(colour(k, v)?),
            "lobe" => e.lobe = Some(v.trim().to_string()),
            "exponent" | "phong" => {
                e.exponent = Some(num(k, v)?);
                if k.trim() == "phong" {
                    e.lobe = Some("phong".into());
                }
            }
            "roughness" | "ggx" => {
                e.roughness = Some(num(k, v)?);
                if k.trim() == "ggx" {
                    e.lobe = Some("ggx".into());
                }
            }
            "ambient" => e.ambient = Some(num(k, v)?),
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
    material_of(&e)
}

fn parse_object(s: &str, level: Option<u32>) -> Result<MeshSource, CliError> {
    if let Ok(b) = s.parse::<Builtin>() {
        let l = level.unwrap_or(b.default_tessellation());
        if !(1..=4096).contains(&l) {
            return Err(bad("--tessellation", format!("{l} is outside 1..=4096")));
        }
        // Counted before anything is built: the teapot at 4096 would be 2³⁰ triangles.
        let triangles = b.triangle_count(l);
        if triangles > MAX_TRIANGLES {
            return Err(bad(
                "--tessellation",
                format!(
                    "{l} makes the {name} {triangles} triangles; at most {MAX_TRIANGLES} are \
                     allowed (the {name} up to tessellation {})",
                    b.max_tessellation(MAX_TRIANGLES),
                    name = b.name()
                ),
            ));
        }
        return Ok(MeshSource::Builtin(b, l));
    }
    let p = PathBuf::from(s);
    let ext = p
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    match ext.as_deref() {
        Some("glb" | "gltf" | "obj") => Ok(MeshSource::File(p)),
        _ => Err(bad(
            "--object",
            format!(
                "'{s}' is neither a built-in ({}) nor a .glb/.gltf/.obj file",
                UnknownName::new::<Builtin>(s).list()
            ),
        )),
    }
}

impl RenderPlan {
    fn new(a: &RenderArgs) -> Result<RenderPlan, CliError> {
        let input = InputPlan::new(&a.input_args)?;
        let indexing = Indexing::from_name(&a.mode).ok_or_else(|| {
            let known: Vec<String> = Indexing::all()
                .map(|m| format!("{}|{}", m.number(), m.name()))
                .collect();
            let known = known.join(", ");
            bad(
                "--mode",
                format!("unknown mode '{}' (known: {known})", a.mode),
            )
        })?;
        let attach = a
            .attach
            .parse::<Attach>()
            .map_err(|e| bad("--attach", e.to_string()))?;
        let filter = environment_filter(&a.filter).map_err(|e| bad("--filter", e.to_string()))?;
        let tone = a
            .tone
            .parse::<Tone>()
            .map_err(|e| bad("--tone", e.to_string()))?;
        let tint = parse_colour("--tint", &a.tint)?;
        if !(0.0..=1.0).contains(&a.f0) {
            return Err(bad("--f0", format!("{} is outside [0, 1]", a.f0)));
        }
        let material = parse_material(&a.material, tint, a.f0).map_err(|e| bad("--material", e))?;
        let (w, h) = parse_size(&a.size)?;
        if !(1..=16).contains(&a.ss) {
            return Err(bad("--ss", format!("{} is outside 1..=16", a.ss)));
        }
        let eye = parse_point("--eye", &a.eye)?;
        let target = parse_point("--target", &a.target)?;
        let up = parse_vec3("--up", &a.up)?;
        let lens = match a.ortho {
            Some(hh) => Lens::Orthographic { half_height: hh },
            None => Lens::Perspective { fov_y_deg: a.fov },
        };
        let camera = Camera {
            eye,
            target,
            up,
            lens,
            near: a.near,
            far: a.far,
            width: w,
            height: h,
        };
        camera.validate().map_err(|e| bad("camera", e))?;
        let source = parse_object(&a.object, a.tessellation)?;
        let normalize = matches!(source, MeshSource::File(_));
        let objects = vec![ObjectPlan {
            source,
            model: Mat4::IDENTITY,
            normalize,
            material,
        }];
        let env_as = match &a.env_as {
            Some(s) => {
                let spec = ProjSpec::parse(s).map_err(|e| bad("--env-as", e))?;
                let size = a.env_size.unwrap_or(512);
                if !(1..=8192).contains(&size) {
                    return Err(bad("--env-size", format!("{size} is outside 1..=8192")));
                }
                Some((spec, size))
            }
            None => None,
        };
        let output = PathBuf::from(&a.output);
        let format = Format::from_path(&output).ok_or_else(|| {
            bad(
                "--output",
                format!(
                    "'{}': the extension must be .png, .jpg, .exr or .hdr",
                    a.output
                ),
            )
        })?;
        if matches!(format, Format::Ktx2 | Format::Dds | Format::Webp) {
            return Err(bad(
                "--output",
                format!("'{}': render writes .png, .jpg, .exr or .hdr", a.output),
            ));
        }
        if let Some(parent) = output.parent().filter(|p| !p.as_os_str().is_empty()) {
            if !parent.is_dir() {
                return Err(CliError::request(format!(
                    "--output: the folder '{}' does not exist",
                    parent.display()
                )));
            }
        }
        if !(1..=3600).contains(&a.turntable) {
            return Err(bad(
                "--turntable",
                format!("{} is outside 1..=3600", a.turntable),
            ));
        }
        let mut plan = RenderPlan {
            objects,
            env_file: a.env.clone(),
            input,
            env_as,
            attach,
            filter,
            intensity: 1.0,
            background: !a.no_background,
            camera,
            settings: Settings {
                indexing,
                supersample: a.ss,
                aovs: a.aovs || a.diagnostics,
                motion_from: None,
                cull_hidden_faces: true,
            },
            exposure: a.exposure,
            tone,
            output,
            format,
            frames: a.turntable,
            diagnostics: a.diagnostics,
            fisheye: match a.fisheye {
                Some(fov) => {
                    let lens = a
                        .fisheye_lens
                        .parse::<mirrorball_core::Lens>()
                        .map_err(|e| bad("--fisheye-lens", e.to_string()))?;
                    if !(fov.is_finite()
                        && fov > 0.0
                        && fov.to_radians() / 2.0 <= lens.max_half_fov())
                    {
                        return Err(bad(
                            "--fisheye",
                            format!(
                                "a {} lens covers (0°, {:.0}°], not {fov}°",
                                a.fisheye_lens,
                                2.0 * lens.max_half_fov().to_degrees()
                            ),
                        ));
                    }
                    if a.aovs || a.diagnostics {
                        return Err(CliError::request(
                            "--fisheye: the diagnostic channels and diagram are made for the cube views, not the fisheye; drop --aovs/--diagnostics",
                        ));
                    }
                    Some((lens, fov))
                }
                None => None,
            },
            pan_blur: match a.pan_blur {
                Some(d) if d.is_finite() && d.abs() < 180.0 => Some(d.to_radians()),
                Some(d) => return Err(bad("--pan-blur", format!("{d}° is outside (−180°, 180°)"))),
                None => None,
            },
            quiet: a.quiet,
        };
        if let Some(scene) = &a.scene {
            let flags = FlagValues::of(&plan);
            apply_scene_file(&mut plan, Path::new(scene))?;
            flags.win_over_the_scene(&mut plan, &a.given);
            plan.camera.validate().map_err(|e| bad("camera", e))?;
        }
        let needs_env =
            plan.background || plan.objects.iter().any(|o| o.material.uses_environment());
        if needs_env && plan.env_file.is_none() {
            return Err(CliError::request(match &a.scene {
                Some(scene) => format!(
                    "{scene}: no environment map: give `environment.file` in the scene or \
                     --env (or use materials that need none, cheap-chrome or diffuse, with \
                     `background = false`)"
                ),
                None => "--env: an environment map is needed (or use --material cheap-chrome \
                         or diffuse with --no-background)"
                    .to_string(),
            }));
        }
        // Each built-in is within the budget; so must they be together (a scene can list
        // any number).
        let triangles: u64 = plan
            .objects
            .iter()
            .map(|o| match o.source {
                MeshSource::Builtin(b, l) => b.triangle_count(l),
                MeshSource::File(_) => 0,
            })
            .sum();
        if triangles > MAX_TRIANGLES {
            return Err(CliError::request(format!(
                "{}the built-in meshes make {triangles} triangles in all; at most \
                 {MAX_TRIANGLES} are allowed: lower their tessellations",
                a.scene
                    .as_ref()
                    .map(|s| format!("{s}: "))
                    .unwrap_or_default(),
            )));
        }
        let (w, h) = (plan.camera.width, plan.camera.height);
        budget::check(
            &format!(
                "{}the render's images ({w}×{h} pixels{}{}{})",
                a.scene
                    .as_ref()
                    .map(|s| format!("{s}: "))
                    .unwrap_or_default(),
                if plan.frames > 1 {
                    format!(", {} frames", plan.frames)
                } else {
                    String::new()
                },
                if plan.settings.aovs {
                    ", diagnostic channels"
                } else {
                    ""
                },
                if plan.fisheye.is_some() {
                    ", fisheye"
                } else {
                    ""
                },
            ),
            0,
            plan.image_bytes(),
            "a smaller --size or fewer --turntable frames",
        )?;
        Ok(plan)
    }

    /// About how many bytes the plan's images take at their peak: every frame's colour
    /// (RGBA `f32`) is kept until all are written, and so is its tone-mapped copy for an
    /// animated PNG; the diagnostic channels are four RGB `f32` images made in bands and
    /// then copied (twice their size); a fisheye frame is made from a cube of faces half
    /// its width (each face rendered as RGBA, then kept as RGB) and is square; writing
    /// copies one frame. Meshes and the environment are not counted.
    fn image_bytes(&self) -> u64 {
        let (w, h) = (self.camera.width as u64, self.camera.height as u64);
        let frames = self.frames as u64;
        let (pixels, scratch) = match self.fisheye {
            Some(_) => {
                let face = (w / 2).max(16);
                (w * w, 6 * face * face * (16 + 12) + w * w * 12)
            }
            None => (w * h, 0),
        };
        let mut per_frame = pixels * 16;
        if self.settings.aovs {
            per_frame += pixels * 4 * 12 * 2;
        }
        if frames > 1 && self.format == Format::Png {
            per_frame += pixels * 16;
        }
        per_frame
            .saturating_mul(frames)
            .saturating_add(scratch)
            .saturating_add(pixels * 16)
    }
}

/// What the flags made of the plan, kept while a scene file is applied so that the flags
/// given on the command line can win over it afterwards.
struct FlagValues {
    camera: Camera,
    objects: Vec<ObjectPlan>,
    env_file: Option<String>,
    from: Option<ProjSpec>,
    layout: Option<mirrorball_core::Layout>,
    attach: Attach,
    filter: Filter,
    settings: Settings,
    background: bool,
}

impl FlagValues {
    fn of(plan: &RenderPlan) -> FlagValues {
        FlagValues {
            camera: plan.camera,
            objects: plan.objects.clone(),
            env_file: plan.env_file.clone(),
            from: plan.input.from.clone(),
            layout: plan.input.layout,
            attach: plan.attach,
            filter: plan.filter,
            settings: plan.settings,
            background: plan.background,
        }
    }

    /// Puts back into `plan` what each flag in `given` (clap's ids) set.
    fn win_over_the_scene(self, plan: &mut RenderPlan, given: &[String]) {
        let g = |id: &str| given.iter().any(|x| x == id);
        let (c, f) = (&mut plan.camera, &self.camera);
        if g("eye") {
            c.eye = f.eye;
        }
        if g("target") {
            c.target = f.target;
        }
        if g("up") {
            c.up = f.up;
        }
        if g("fov") || g("ortho") {
            c.lens = f.lens;
        }
        if g("near") {
            c.near = f.near;
        }
        if g("far") {
            c.far = f.far;
        }
        if g("size") {
            (c.width, c.height) = (f.width, f.height);
        }
        if g("object") || g("tessellation") {
            plan.objects = self.objects.clone();
        }
        if g("material") || g("tint") || g("f0") {
            let m = self.objects[0].material.clone();
            plan.objects.iter_mut().for_each(|o| o.material = m.clone());
        }
        if g("env") {
            plan.env_file = self.env_file;
        }
        if g("from") {
            plan.input.from = self.from;
        }
        if g("in_layout") {
            plan.input.layout = self.layout;
        }
        if g("attach") {
            plan.attach = self.attach;
        }
        if g("filter") {
            plan.filter = self.filter;
        }
        if g("mode") {
            plan.settings.indexing = self.settings.indexing;
        }
        if g("ss") {
            plan.settings.supersample = self.settings.supersample;
        }
        if g("no_background") {
            plan.background = self.background;
        }
    }
}

// ---------------------------------------------------------------------------------------
// Scene files (JSON).

/// A scene file: see `docs/render-scene.md` and `examples/scenes/`.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    #[serde(default)]
    meshes: Vec<MeshEntry>,
    camera: Option<CameraEntry>,
    environment: Option<EnvEntry>,
    /// Default material of meshes that name none.
    material: Option<MaterialEntry>,
    /// Indexing mode.
    indexing: Option<String>,
    supersample: Option<u32>,
    background: Option<bool>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct MeshEntry {
    /// A built-in name or a file (relative to the scene file).
    mesh: String,
    tessellation: Option<u32>,
    /// Column-major 4×4 (as glTF stores matrices), or absent for the identity.
    model: Option<[f32; 16]>,
    /// Centre and scale a file's mesh to unit size first (default true for files).
    normalize: Option<bool>,
    material: Option<MaterialEntry>,
}

#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
struct MaterialEntry {
    kind: String,
    /// Mirror tint; base colour of fresnel, diffuse and phong-map.
    tint: Option<[f32; 3]>,
    f0: Option<f32>,
    /// Greene: diffuse and specular reflectance.
    dc: Option<[f32; 3]>,
    sc: Option<[f32; 3]>,
    /// Greene: `phong` or `ggx`.
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

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct CameraEntry {
    eye: [f32; 3],
    target: [f32; 3],
    up: Option<[f32; 3]>,
    /// Vertical field of view in degrees (perspective).
    fov: Option<f32>,
    /// Half height of an orthographic view (makes the camera orthographic).
    ortho_half_height: Option<f32>,
    near: Option<f32>,
    far: Option<f32>,
    width: Option<u32>,
    height: Option<u32>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct EnvEntry {
    /// The map's file (relative to the scene file).
    file: String,
    /// Its projection, as `--from` spells it (guessed when absent).
    projection: Option<String>,
    /// `world` or `eye`.
    attach: Option<String>,
    /// `nearest`, `bilinear`, `trilinear` or `ewa`.
    filter: Option<String>,
    intensity: Option<f32>,
}

/// The material a scene file's (or a `--material` spec's) entry describes, every value
/// checked.
fn material_of(e: &MaterialEntry) -> Result<Material, String> {
    let tint = e.tint.unwrap_or([1.0; 3]);
    let f0 = e.f0.unwrap_or(0.04);
    let name = e.kind.to_ascii_lowercase();
    let colour = |k: &str, c: [f32; 3]| -> Result<[f32; 3], String> {
        if c.iter().all(|v| v.is_finite() && *v >= 0.0) {
            Ok(c)
        } else {
            Err(format!("{k} {c:?} has a negative or non-finite channel"))
        }
    };
    let tint = colour("tint", tint)?;
    if !(0.0..=1.0).contains(&f0) {
        return Err(format!("f0 {f0} is outside [0, 1]"));
    }
    let allowed: &[&str] = match name.as_str() {
        "mirror" | "chrome" | "fresnel" | "varnish" | "plastic" | "cheap-chrome" | "ramp"
        | "diffuse" | "matte" => &[],
        "greene" => &["dc", "sc", "lobe", "exponent", "roughness"],
        "phong-map" | "phongmap" => &["specular", "exponent", "light", "ambient"],
        _ => {
            return Err(format!(
                "unknown material '{}' (known: mirror, fresnel, cheap-chrome, diffuse, greene, phong-map)",
                e.kind
            ))
        }
    };
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
        if set && !allowed.contains(&key) {
            return Err(format!("'{key}' does not apply to material '{}'", e.kind));
        }
    }
    Ok(match name.as_str() {
        "mirror" | "chrome" => Material::Mirror { tint },
        "fresnel" | "varnish" | "plastic" => Material::Fresnel { f0, base: tint },
        "cheap-chrome" | "ramp" => Material::CheapChrome {
            ramp: Ramp::chrome(),
        },
        "diffuse" | "matte" => Material::diffuse(tint),
        "greene" => {
            let lobe_name = e.lobe.clone().unwrap_or_else(|| {
                if e.roughness.is_some() {
                    "ggx".into()
                } else {
                    "phong".into()
                }
            });
            let lobe = match lobe_name.to_ascii_lowercase().as_str() {
                "phong" => {
                    if e.roughness.is_some() {
                        return Err(
                            "'roughness' is for the ggx lobe; phong takes 'exponent'".into()
                        );
                    }
                    SpecularLobe::Phong {
                        exponent: e.exponent.unwrap_or(32.0) as f64,
                    }
                }
                "ggx" => {
                    if e.exponent.is_some() {
                        return Err(
                            "'exponent' is for the phong lobe; ggx takes 'roughness'".into()
                        );
                    }
                    SpecularLobe::Ggx {
                        roughness: e.roughness.unwrap_or(0.3) as f64,
                    }
                }
                other => return Err(format!("lobe '{other}' is not phong or ggx")),
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
            Material::Greene {
                dc: colour("dc", e.dc.unwrap_or([0.2; 3]))?,
                sc: colour("sc", e.sc.unwrap_or([0.8; 3]))?,
                lobe,
            }
        }
        _ => {
            // phong-map
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
            Material::PhongMap {
                colour: if e.tint.is_some() { tint } else { [0.5; 3] },
                specular: colour("specular", e.specular.unwrap_or([1.0; 3]))?,
                exponent,
                light,
                ambient,
            }
        }
    })
}

/// Reads a scene file and lets it override the flags' defaults.
fn apply_scene_file(plan: &mut RenderPlan, path: &Path) -> Result<(), CliError> {
    let name = path.display();
    let text = std::fs::read_to_string(path)
        .map_err(|e| CliError::new(Fault::of_io(e.kind()), format!("{name}: cannot read: {e}")))?;
    let is_toml = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("toml"));
    let sf: SceneFile = if is_toml {
        toml::from_str(&text)
            .map_err(|e| CliError::input(format!("{name}: not a valid TOML scene: {e}")))?
    } else {
        serde_json::from_str(&text)
            .map_err(|e| CliError::input(format!("{name}: not a valid JSON scene: {e}")))?
    };
    let base = path.parent().unwrap_or(Path::new("."));
    let rel = |f: &str| -> String {
        let p = Path::new(f);
        if p.is_absolute() {
            f.to_string()
        } else {
            base.join(p).to_string_lossy().into_owned()
        }
    };
    let err = |e: String| CliError::input(format!("{name}: {e}"));
    let default_material = match &sf.material {
        Some(m) => material_of(m).map_err(err)?,
        None => plan
            .objects
            .first()
            .map(|o| o.material.clone())
            .unwrap_or_else(Material::mirror),
    };
    if !sf.meshes.is_empty() {
        let mut objects = Vec::new();
        for (i, m) in sf.meshes.iter().enumerate() {
            let source = match Builtin::from_name(&m.mesh) {
                Some(_) => parse_object(&m.mesh, m.tessellation),
                None => parse_object(&rel(&m.mesh), None),
            }
            .map_err(|e| CliError::input(format!("{name}: meshes[{i}]: {}", e.message)))?;
            let model = m
                .model
                .map(|c| Mat4::from_cols_array(&c))
                .unwrap_or(Mat4::IDENTITY);
            if !model.is_finite() || model.determinant() == 0.0 {
                return Err(err(format!("meshes[{i}]: the model matrix is singular")));
            }
            let material = match &m.material {
                Some(e) => material_of(e).map_err(|e| err(format!("meshes[{i}]: {e}")))?,
                None => default_material.clone(),
            };
            objects.push(ObjectPlan {
                normalize: m.normalize.unwrap_or(matches!(source, MeshSource::File(_))),
                source,
                model,
                material,
            });
        }
        plan.objects = objects;
    } else if sf.material.is_some() {
        for o in &mut plan.objects {
            o.material = default_material.clone();
        }
    }
    if let Some(c) = &sf.camera {
        let lens = match (c.ortho_half_height, c.fov) {
            (Some(h), _) => Lens::Orthographic { half_height: h },
            (None, Some(f)) => Lens::Perspective { fov_y_deg: f },
            (None, None) => plan.camera.lens,
        };
        plan.camera = Camera {
            eye: Vec3::from_array(c.eye),
            target: Vec3::from_array(c.target),
            up: c.up.map(Vec3::from_array).unwrap_or(Vec3::Y),
            lens,
            near: c.near.unwrap_or(plan.camera.near),
            far: c.far.unwrap_or(plan.camera.far),
            width: c.width.unwrap_or(plan.camera.width),
            height: c.height.unwrap_or(plan.camera.height),
        };
        // The bounds of --size.
        for (key, side) in [("width", c.width), ("height", c.height)] {
            if let Some(n) = side.filter(|n| !(1..=16384).contains(n)) {
                return Err(err(format!("camera.{key} {n} is outside 1..=16384")));
            }
        }
        plan.camera
            .validate()
            .map_err(|e| err(format!("camera: {e}")))?;
    }
    if let Some(e) = &sf.environment {
        plan.env_file = Some(rel(&e.file));
        if let Some(p) = &e.projection {
            plan.input.from =
                Some(ProjSpec::parse(p).map_err(|x| err(format!("environment.projection: {x}")))?);
        }
        if let Some(a) = &e.attach {
            plan.attach = a
                .parse::<Attach>()
                .map_err(|e| err(format!("environment.attach: {e}")))?;
        }
        if let Some(f) = &e.filter {
            plan.filter =
                environment_filter(f).map_err(|e| err(format!("environment.filter: {e}")))?;
        }
        if let Some(i) = e.intensity {
            if !(i.is_finite() && i >= 0.0) {
                return Err(err("environment.intensity must be ≥ 0".into()));
            }
            plan.intensity = i;
        }
    }
    if let Some(m) = &sf.indexing {
        plan.settings.indexing =
            Indexing::from_name(m).ok_or_else(|| err(format!("indexing: unknown mode '{m}'")))?;
    }
    if let Some(s) = sf.supersample {
        if !(1..=16).contains(&s) {
            return Err(err(format!("supersample {s} is outside 1..=16")));
        }
        plan.settings.supersample = s;
    }
    if let Some(b) = sf.background {
        plan.background = b;
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------
// Work.

fn load_object(o: &ObjectPlan) -> Result<Object, CliError> {
    let (mesh, fit) = match &o.source {
        MeshSource::Builtin(b, l) => (b.mesh(*l), Mat4::IDENTITY),
        MeshSource::File(p) => {
            let m: Mesh = mirrorball_render::load::load_mesh(p)?;
            let fit = if o.normalize {
                m.normalizing_transform()
            } else {
                Mat4::IDENTITY
            };
            (m, fit)
        }
    };
    Ok(Object {
        mesh: Arc::new(mesh),
        model: o.model * fit,
        material: o.material.clone(),
    })
}

/// `out.png` → `out-{tag}.exr`.
fn sibling(path: &Path, tag: &str, ext: &str) -> PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "render".into());
    path.with_file_name(format!("{stem}-{tag}.{ext}"))
}

fn write(path: &Path, img: &Image, format: Format, plan: &RenderPlan) -> Result<(), CliError> {
    let img = match format {
        Format::Png | Format::Jpeg => tone::to_display(img, plan.exposure, plan.tone),
        _ => {
            let mut i = img.clone();
            let k = plan.exposure.exp2();
            if k != 1.0 {
                for px in i.data_mut().chunks_exact_mut(4) {
                    for v in &mut px[..3] {
                        *v *= k;
                    }
                }
            }
            i
        }
    };
    let img = if format == Format::Jpeg || format == Format::Hdr {
        img.with_channels(3)
    } else {
        img
    };
    mirrorball_io::write_image(path, &img, &WriteOptions::default())?;
    Ok(())
}

/// Every file the render reads and writes, checked so that no output is an input or
/// another output.
fn files(plan: &RenderPlan, a: &RenderArgs) -> Files {
    let mut f = Files::new();
    if let Some(e) = &plan.env_file {
        f.input_arg("the environment", e);
    }
    if let Some(s) = &a.scene {
        f.input("the scene", s);
    }
    for o in &plan.objects {
        if let MeshSource::File(p) = &o.source {
            f.input("the mesh", p);
        }
    }
    let frames = plan.frames;
    for i in 0..frames {
        let path = if frames > 1 {
            sibling(&plan.output, &format!("{i:04}"), ext_of(plan.format))
        } else {
            plan.output.clone()
        };
        if plan.diagnostics {
            f.output("the diagnostics", sibling(&path, "diag", "png"));
        }
        if a.aovs {
            for tag in ["st", "reflect", "normal", "depth"] {
                f.output("a diagnostic channel", sibling(&path, tag, "exr"));
            }
        }
        f.output("the output", path);
    }
    if frames > 1 && plan.format == Format::Png {
        f.output("the animation", sibling(&plan.output, "turntable", "png"));
    }
    f
}

pub fn run(a: RenderArgs) -> Result<(), CliError> {
    let plan = RenderPlan::new(&a)?;
    files(&plan, &a).check()?;
    let environment = match &plan.env_file {
        Some(f) => {
            let src = load::load(
                f,
                plan.input.from.as_ref(),
                plan.input.layout,
                &mirrorball_io::Limits::default(),
            )?;
            let mut env = src.env;
            if !plan.input.keep_invalid {
                env.sanitize();
            }
            if !plan.quiet {
                eprintln!(
                    "environment: {} {}x{} ({})",
                    env.projection().name(),
                    env.width(),
                    env.height(),
                    src.decided
                );
            }
            let env: EnvMap = match &plan.env_as {
                Some((spec, size)) => {
                    let p = spec
                        .build(None)
                        .map_err(|e| CliError::request(format!("--env-as: {e}")))?;
                    let (w, h) = p.layer_extent(*size);
                    budget::check(
                        &format!("--env-as {} {w}x{h}x{}", p.name(), p.layer_count()),
                        0,
                        budget::f32_texels(
                            w as u64 * h as u64 * p.layer_count() as u64,
                            env.channels() as u64,
                        ),
                        "a smaller --env-size",
                    )?;
                    if !plan.quiet {
                        eprintln!("environment converted to {} {w}x{h}", p.name());
                    }
                    resample(&env, p, *size, &ResampleOptions::default())
                }
                None => env,
            };
            Some(Environment {
                map: Arc::new(env),
                attach: plan.attach,
                filter: plan.filter,
                intensity: plan.intensity,
                cache: Default::default(),
            })
        }
        None => None,
    };
    let objects = plan
        .objects
        .iter()
        .map(load_object)
        .collect::<Result<Vec<_>, _>>()?;
    let tris: usize = objects.iter().map(|o| o.mesh.triangles.len()).sum();
    let scene = Scene {
        objects,
        environment,
        background: plan.background,
    };
    let frames = plan.frames;
    let label = if frames > 1 { "frames" } else { "render" };
    let started = std::time::Instant::now();
    // Progress in pixel rows, every frame's.
    let rows = plan.camera.height as u64;
    let results = with_progress(label, frames as u64 * rows, plan.quiet, |counter| {
        (0..frames)
            .map(|i| {
                let angle = std::f32::consts::TAU * i as f32 / frames as f32;
                let cam = plan.camera.orbited(angle);
                let settings = Settings {
                    motion_from: plan.pan_blur.map(|p| cam.panned(p)),
                    ..plan.settings
                };
                match plan.fisheye {
                    Some((lens, fov)) => mirrorball_render::capture::render_fisheye(
                        &scene,
                        cam.eye,
                        cam.target,
                        cam.up,
                        lens,
                        fov,
                        cam.width,
                        (cam.width / 2).max(16),
                        &settings,
                    )
                    .map(|img| {
                        counter.fetch_add(rows, Ordering::Relaxed);
                        mirrorball_render::Frame {
                            color: with_alpha(&img),
                            aovs: None,
                        }
                    }),
                    None => {
                        mirrorball_render::render_with_progress(&scene, &cam, &settings, &counter)
                    }
                }
                .map_err(CliError::from)
            })
            .collect::<Vec<_>>()
    });
    let secs = started.elapsed().as_secs_f64();
    let mut anim: Vec<Image> = Vec::new();
    for (i, f) in results.into_iter().enumerate() {
        let f = f?;
        if frames > 1 && plan.format == Format::Png {
            anim.push(tone::to_display(&f.color, plan.exposure, plan.tone));
        }
        let path = if frames > 1 {
            sibling(&plan.output, &format!("{i:04}"), ext_of(plan.format))
        } else {
            plan.output.clone()
        };
        write(&path, &f.color, plan.format, &plan)?;
        if !plan.quiet {
            eprintln!("wrote {}", path.display());
        }
        if plan.diagnostics {
            let angle = std::f32::consts::TAU * i as f32 / frames as f32;
            let cam = plan.camera.orbited(angle);
            let d = mirrorball_render::texture_space_diagram(&scene, &cam, &plan.settings, &f, 512)
                .map_err(|e| CliError::from(e).context("--diagnostics"))?;
            let p = sibling(&path, "diag", "png");
            mirrorball_io::write_image(&p, &d, &WriteOptions::default())?;
            if !plan.quiet {
                eprintln!("wrote {}", p.display());
            }
        }
        if let Some(aovs) = f.aovs.as_ref().filter(|_| a.aovs) {
            let opts = WriteOptions {
                precision: Some(Precision::Float),
                ..WriteOptions::default()
            };
            for (tag, img) in [
                ("st", &aovs.st_face),
                ("reflect", &aovs.reflected),
                ("normal", &aovs.normal),
                ("depth", &aovs.depth),
            ] {
                let p = sibling(&path, tag, "exr");
                mirrorball_io::write_image(&p, img, &opts)?;
                if !plan.quiet {
                    eprintln!("wrote {}", p.display());
                }
            }
        }
    }
    if !anim.is_empty() {
        let p = sibling(&plan.output, "turntable", "png");
        mirrorball_io::write_apng(&p, &anim, 24)?;
        if !plan.quiet {
            eprintln!(
                "wrote {} (animated PNG, {} frames)",
                p.display(),
                anim.len()
            );
        }
    }
    if !plan.quiet {
        let (w, h) = (plan.camera.width, plan.camera.height);
        eprintln!(
            "{frames} frame(s) {w}x{h}, {tris} triangles, mode {}, {}x{} samples per pixel: {:.3} s ({:.1} frames/s)",
            plan.settings.indexing.name(),
            plan.settings.supersample,
            plan.settings.supersample,
            secs,
            frames as f64 / secs.max(1e-9)
        );
    }
    Ok(())
}

fn ext_of(f: Format) -> &'static str {
    match f {
        Format::Exr => "exr",
        Format::Hdr => "hdr",
        Format::Jpeg => "jpg",
        _ => "png",
    }
}

/// An RGB picture as RGBA with alpha 1.
fn with_alpha(img: &Image) -> Image {
    img.with_channels(4)
}
