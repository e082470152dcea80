//! `RenderArgs → RenderPlan`: every flag parsed and checked, the output's folder and format
//! checked, the scene file applied (the flags given on the command line winning over it),
//! the meshes' triangles and the images' memory counted, before anything is loaded.

use super::material::parse_material;
use super::schema;
use crate::budget;
use crate::commands::InputPlan;
use crate::error::CliError;
use crate::spec::{bad, parse_dir, ProjSpec};
use crate::RenderArgs;
use mirrorball_core::glam::{Mat4, Vec3};
use mirrorball_core::{Choice, UnknownName, WorldProjection};
use mirrorball_io::Format;
use mirrorball_render::mesh::MAX_TRIANGLES;
use mirrorball_render::tone::Tone;
use mirrorball_render::{
    environment_filter, Attach, Builtin, Camera, CameraLens, Filter, Indexing, Material, Settings,
};
use std::path::{Path, PathBuf};

/// Where a mesh comes from.
#[derive(Clone, Debug)]
pub(super) enum MeshSource {
    Builtin(Builtin, u32),
    File(PathBuf),
}

/// One object to load.
#[derive(Clone, Debug)]
pub(super) struct ObjectPlan {
    pub source: MeshSource,
    pub model: Mat4,
    /// Centre the file's mesh and scale it to unit size before `model`.
    pub normalize: bool,
    pub material: Material,
}

/// Everything `render` will do, checked.
pub(super) struct RenderPlan {
    pub objects: Vec<ObjectPlan>,
    pub env_file: Option<String>,
    pub input: InputPlan,
    pub env_as: Option<(ProjSpec, u32)>,
    pub attach: Attach,
    pub filter: Filter,
    pub intensity: f32,
    pub background: bool,
    pub camera: Camera,
    pub settings: Settings,
    pub exposure: f32,
    pub tone: Tone,
    pub output: PathBuf,
    pub format: Format,
    pub frames: u32,
    /// The scene file, if one was given.
    pub scene: Option<String>,
    /// Write the diagnostic channels as EXRs beside each frame.
    pub aovs: bool,
    /// Write the texture-space diagram beside each frame.
    pub diagnostics: bool,
    /// Fisheye lens and full field of view.
    pub fisheye: Option<(mirrorball_core::Lens, f64)>,
    /// Pan since the previous frame, radians (motion blur).
    pub pan_blur: Option<f32>,
    pub quiet: bool,
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

/// The sides an image written to `output` as `format` may have (the size rule:
/// `crate::size`).
pub(super) fn side_bound(output: &Path, format: Format) -> crate::size::Bound {
    let what = output.display().to_string();
    crate::size::pictures(format, &what, |n| (n as u64, 1))
}

/// `--size WIDTHxHEIGHT` of an image written as `format`: each side within what the
/// container holds and mirrorball reads back, as the size rule says (`crate::size`), and
/// the picture within mirrorball's reading bound.
fn parse_size(s: &str, output: &Path, format: Format) -> Result<(u32, u32), CliError> {
    let not_a_size = || bad("--size", format!("'{s}' is not WIDTHxHEIGHT"));
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(not_a_size)?;
    let (w, h) = (
        crate::size::parse(w).map_err(|_| not_a_size())?,
        crate::size::parse(h).map_err(|_| not_a_size())?,
    );
    let side = side_bound(output, format);
    let check = |v: i64| {
        side.check("--size", v)
            .map_err(|_| side.refusal("--size", s))
    };
    let (w, h) = (check(w)?, check(h)?);
    let most = mirrorball_io::Limits::default().max_texels;
    if w as u64 * h as u64 > most {
        return Err(bad(
            "--size",
            format!(
                "'{s}' is {} pixels; mirrorball reads pictures of at most {most}",
                w as u64 * h as u64
            ),
        ));
    }
    Ok((w, h))
}

/// A built-in's name (at `level`, or its default tessellation) or a mesh file's path.
pub(super) fn parse_object(s: &str, level: Option<u32>) -> Result<MeshSource, CliError> {
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

/// `--mode`, in the words of its message.
fn parse_mode(s: &str) -> Result<Indexing, CliError> {
    Indexing::from_name(s).ok_or_else(|| {
        let known: Vec<String> = Indexing::all()
            .map(|m| format!("{}|{}", m.number(), m.name()))
            .collect();
        let known = known.join(", ");
        bad("--mode", format!("unknown mode '{s}' (known: {known})"))
    })
}

/// `--material` with `--tint` and `--f0` as its defaults.
fn flag_material(a: &RenderArgs) -> Result<Material, CliError> {
    let tint = parse_colour("--tint", &a.tint)?;
    if !(0.0..=1.0).contains(&a.f0) {
        return Err(bad("--f0", format!("{} is outside [0, 1]", a.f0)));
    }
    parse_material(&a.material, tint, a.f0).map_err(|e| bad("--material", e))
}

/// The camera of `--eye`, `--target`, `--up`, `--fov` or `--ortho`, `--near`, `--far`,
/// `w`×`h` pixels.
fn flag_camera(a: &RenderArgs, (width, height): (u32, u32)) -> Result<Camera, CliError> {
    let eye = parse_point("--eye", &a.eye)?;
    let target = parse_point("--target", &a.target)?;
    let up = parse_vec3("--up", &a.up)?;
    let lens = match a.ortho {
        Some(hh) => CameraLens::Orthographic { half_height: hh },
        None => CameraLens::Perspective { fov_y_deg: a.fov },
    };
    let camera = Camera {
        eye,
        target,
        up,
        lens,
        near: a.near,
        far: a.far,
        width,
        height,
    };
    camera.validate().map_err(|e| bad("camera", e))?;
    Ok(camera)
}

/// `--object` (at `--tessellation`) with `material`.
fn flag_object(a: &RenderArgs, material: Material) -> Result<ObjectPlan, CliError> {
    let source = parse_object(&a.object, a.tessellation)?;
    Ok(ObjectPlan {
        normalize: matches!(source, MeshSource::File(_)),
        source,
        model: Mat4::IDENTITY,
        material,
    })
}

/// `--env-as` at `--env-size`.
fn flag_env_as(a: &RenderArgs) -> Result<Option<(ProjSpec, u32)>, CliError> {
    let Some(s) = &a.env_as else {
        return Ok(None);
    };
    let spec = ProjSpec::parse(s).map_err(|e| bad("--env-as", e))?;
    let p = spec.build(None).map_err(|e| bad("--env-as", e))?;
    // Held in memory, not written: within what a map mirrorball reads may be (its layers,
    // each as an EXR picture).
    let bound = crate::size::pictures(Format::Exr, "the --env-as map's layer", |n| {
        let (w, h) = p.layer_extent(n);
        (w as u64, h as u64)
    });
    let size = bound.check("--env-size", a.env_size.unwrap_or(512))?;
    Ok(Some((spec, size)))
}

/// `--output`: its format (one render writes); its folder is checked with every output's
/// (`output::files`).
fn flag_output(a: &RenderArgs) -> Result<(PathBuf, Format), CliError> {
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
    // A tone curve is for the 8-bit containers; a linear .exr/.hdr takes none.
    let given: &[&str] = if a.given.iter().any(|g| g == "tone") {
        &["--tone"]
    } else {
        &[]
    };
    crate::save::check_flags(&a.output, format, given, None)?;
    Ok((output, format))
}

/// `--fisheye` with `--fisheye-lens`: a field of view the lens covers, and no diagnostics.
fn flag_fisheye(a: &RenderArgs) -> Result<Option<(mirrorball_core::Lens, f64)>, CliError> {
    let Some(fov) = a.fisheye else {
        return Ok(None);
    };
    let lens = a
        .fisheye_lens
        .parse::<mirrorball_core::Lens>()
        .map_err(|e| bad("--fisheye-lens", e.to_string()))?;
    lens.fov_range()
        .check("--fisheye", fov)
        .map_err(|e| CliError::request(format!("{e} (the {} lens)", lens.name())))?;
    if a.aovs || a.diagnostics {
        return Err(CliError::request(
            "--fisheye: the diagnostic channels and diagram are made for the cube views, not the fisheye; drop --aovs/--diagnostics",
        ));
    }
    Ok(Some((lens, fov)))
}

/// `--pan-blur`, in radians.
fn flag_pan_blur(a: &RenderArgs) -> Result<Option<f32>, CliError> {
    match a.pan_blur {
        Some(d) if d.is_finite() && d.abs() < 180.0 => Ok(Some(d.to_radians())),
        Some(d) => Err(bad("--pan-blur", format!("{d}° is outside (−180°, 180°)"))),
        None => Ok(None),
    }
}

impl RenderPlan {
    /// The plan of the flags, then of the scene file (if any), checked whole.
    pub fn new(a: &RenderArgs) -> Result<RenderPlan, CliError> {
        let input = crate::commands::input_plan(&a.input_args)?;
        let indexing = parse_mode(&a.mode)?;
        let attach = a
            .attach
            .parse::<Attach>()
            .map_err(|e| bad("--attach", e.to_string()))?;
        let filter = environment_filter(&a.filter).map_err(|e| bad("--filter", e.to_string()))?;
        let tone = a
            .tone
            .parse::<Tone>()
            .map_err(|e| bad("--tone", e.to_string()))?;
        let material = flag_material(a)?;
        let (output, format) = flag_output(a)?;
        let size = parse_size(&a.size, &output, format)?;
        if !(1..=16).contains(&a.ss) {
            return Err(bad("--ss", format!("{} is outside 1..=16", a.ss)));
        }
        let camera = flag_camera(a, size)?;
        let objects = vec![flag_object(a, material)?];
        let env_as = flag_env_as(a)?;
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
            scene: a.scene.clone(),
            aovs: a.aovs,
            diagnostics: a.diagnostics,
            fisheye: flag_fisheye(a)?,
            pan_blur: flag_pan_blur(a)?,
            quiet: a.quiet,
        };
        if let Some(scene) = &a.scene {
            schema::apply(&mut plan, Path::new(scene), &a.given)?;
        }
        plan.check_environment()?;
        plan.check_triangles()?;
        plan.check_memory()?;
        Ok(plan)
    }

    /// `"SCENE: "` before a message about what the scene file may have set, if one was given.
    fn scene_prefix(&self) -> String {
        self.scene
            .as_ref()
            .map(|s| format!("{s}: "))
            .unwrap_or_default()
    }

    /// An environment map, unless nothing reads one.
    fn check_environment(&self) -> Result<(), CliError> {
        let needs_env =
            self.background || self.objects.iter().any(|o| o.material.uses_environment());
        if !needs_env || self.env_file.is_some() {
            return Ok(());
        }
        Err(CliError::request(match &self.scene {
            Some(scene) => format!(
                "{scene}: no environment map: give `environment.file` in the scene or \
                 --env (or use materials that need none, cheap-chrome or diffuse, with \
                 `background = false`)"
            ),
            None => "--env: an environment map is needed (or use --material cheap-chrome \
                     or diffuse with --no-background)"
                .to_string(),
        }))
    }

    /// Each built-in is within the budget; so must they be together (a scene can list any
    /// number).
    fn check_triangles(&self) -> Result<(), CliError> {
        let triangles: u64 = self
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
                self.scene_prefix(),
            )));
        }
        Ok(())
    }

    /// The images within the memory budget.
    fn check_memory(&self) -> Result<(), CliError> {
        let (w, h) = (self.camera.width, self.camera.height);
        let frames = if self.frames > 1 {
            format!(", {} frames", self.frames)
        } else {
            String::new()
        };
        let aovs = if self.settings.aovs {
            ", diagnostic channels"
        } else {
            ""
        };
        let fisheye = if self.fisheye.is_some() {
            ", fisheye"
        } else {
            ""
        };
        budget::check(
            &format!(
                "{}the render's images ({w}×{h} pixels{frames}{aovs}{fisheye})",
                self.scene_prefix()
            ),
            0,
            self.image_bytes(),
            "a smaller --size or fewer --turntable frames",
        )
    }

    /// About how many bytes the plan's images take at their peak: every frame's colour
    /// (RGBA `f32`) is kept until all are written, and so is its tone-mapped copy for an
    /// animated PNG; the diagnostic channels are four RGB `f32` images made in bands and
    /// then copied (twice their size); a fisheye frame is made from a cube of faces half
    /// its width (each face rendered as RGBA, then kept as RGB) and is square; writing
    /// copies one frame, and its encoder holds its buffers. Meshes and the environment are not
    /// counted.
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
        let (pw, ph) = match self.fisheye {
            Some(_) => (w, w),
            None => (w, h),
        };
        let encoder = mirrorball_io::write_buffer_bytes(
            &self.frame_path(0),
            (pw as u32, ph as u32, 4),
            &Default::default(),
        );
        per_frame
            .saturating_mul(frames)
            .saturating_add(scratch)
            .saturating_add(pixels * 16)
            .saturating_add(encoder)
    }
}
