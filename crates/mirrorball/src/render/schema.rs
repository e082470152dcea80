//! Scene files (`docs/render-scene.md`, `examples/scenes/`): JSON or TOML, one schema, read
//! into the plan; the flags given on the command line then win over what the file set.

use super::plan::{parse_object, MeshSource, ObjectPlan, RenderPlan};
use crate::error::Error;
use crate::materials::{material_of, MaterialEntry};
use crate::spec::{bad, ProjSpec};
use mirrorball_core::glam::{Mat4, Vec3};
use mirrorball_core::{Choice, Fault};
use mirrorball_render::{
    environment_filter, Attach, Builtin, Camera, CameraLens, Filter, Indexing, Material, Settings,
};
use serde::Deserialize;
use std::path::Path;

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

/// Applies the scene file at `path` to the plan of the flags, then puts back what the flags
/// in `given` (clap's ids) set.
pub fn apply(plan: &mut RenderPlan, path: &Path, given: &[String]) -> Result<(), Error> {
    let flags = FlagValues::of(plan);
    let scene = Scene::read(path)?;
    scene.apply(plan)?;
    flags.win_over_the_scene(plan, given);
    plan.camera.validate().map_err(|e| bad("camera", e))
}

/// The scene file at `path` as JSON that means the same wherever it is written: the file
/// checked as `render` reads it, then its environment's file and each mesh that is not a
/// built-in made absolute (they are relative to the scene file's folder). The studio
/// exports the scene from it.
pub fn portable(path: &Path) -> Result<serde_json::Value, Error> {
    let scene = Scene::read(path)?;
    let mut v = scene.as_json()?;
    map_files(&mut v, |f| -> Result<String, Error> {
        let p = scene.relative(f);
        Ok(std::path::absolute(&p).map_or(p, |a| a.to_string_lossy().into_owned()))
    })?;
    Ok(v)
}

/// The scene file at `path` as JSON, checked as `render` reads it (its messages), the files
/// it names as it wrote them.
pub fn as_written(path: &Path) -> Result<serde_json::Value, Error> {
    Scene::read(path)?.as_json()
}

/// Replaces each file a scene (as JSON) names, the environment's and each mesh that is not
/// a built-in, by what `to` makes of it.
pub fn map_files<E>(
    v: &mut serde_json::Value,
    mut to: impl FnMut(&str) -> Result<String, E>,
) -> Result<(), E> {
    if let Some(file) = v.pointer("/environment/file").and_then(|f| f.as_str()) {
        let file = to(file)?;
        v["environment"]["file"] = file.into();
    }
    if let Some(meshes) = v.get_mut("meshes").and_then(|m| m.as_array_mut()) {
        for m in meshes {
            if let Some(name) = m.get("mesh").and_then(|n| n.as_str()) {
                if Builtin::from_name(name).is_none() {
                    let file = to(name)?;
                    m["mesh"] = file.into();
                }
            }
        }
    }
    Ok(())
}

/// Whether `path` names a TOML scene (else JSON).
fn is_toml(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
}

/// A scene file read, with what its messages and relative paths need.
struct Scene<'a> {
    file: SceneFile,
    path: &'a Path,
}

impl<'a> Scene<'a> {
    /// Reads and parses `path`, TOML by its extension, else JSON.
    fn read(path: &'a Path) -> Result<Scene<'a>, Error> {
        let name = path.display();
        // A picture's name where the scene goes is the output given without -o.
        let hint = if mirrorball_io::Format::from_path(path).is_some() {
            " (the picture to write is given with -o/--output)"
        } else {
            ""
        };
        let cannot = |fault, why: &dyn std::fmt::Display| {
            Error::new(
                fault,
                format!("{name}: cannot read the scene file: {why}{hint}"),
            )
        };
        // Missing or a directory: said so, as every input file is. An empty file is a
        // scene that says nothing, and what it lacks is said once it is planned.
        let empty = std::fs::metadata(path).is_ok_and(|m| m.is_file() && m.len() == 0);
        if !empty {
            mirrorball_io::Error::check_input(path).map_err(|e| cannot(e.fault(), &e.problem()))?;
        }
        let text = std::fs::read_to_string(path).map_err(|e| cannot(Fault::of_io(e.kind()), &e))?;
        let file: SceneFile = if is_toml(path) {
            toml::from_str(&text)
                .map_err(|e| Error::input(format!("{name}: not a valid TOML scene: {e}")))?
        } else {
            serde_json::from_str(&text)
                .map_err(|e| Error::input(format!("{name}: not a valid JSON scene: {e}")))?
        };
        Ok(Scene { file, path })
    }

    /// The file as JSON (a TOML file's tables as JSON objects).
    fn as_json(&self) -> Result<serde_json::Value, Error> {
        let text = std::fs::read_to_string(self.path)
            .map_err(|e| Error::input(format!("{}: {e}", self.path.display())))?;
        if self.is_toml() {
            toml::from_str(&text).map_err(|e| self.error(e.to_string()))
        } else {
            serde_json::from_str(&text).map_err(|e| self.error(e.to_string()))
        }
    }

    /// Whether the file is TOML (by its extension; else JSON).
    fn is_toml(&self) -> bool {
        is_toml(self.path)
    }

    /// A path the file gives, relative to the file's folder unless absolute.
    fn relative(&self, f: &str) -> String {
        let base = self.path.parent().unwrap_or(Path::new("."));
        let p = Path::new(f);
        if p.is_absolute() {
            f.to_string()
        } else {
            base.join(p).to_string_lossy().into_owned()
        }
    }

    /// The input's fault, in the file's name.
    fn error(&self, e: impl std::fmt::Display) -> Error {
        Error::input(format!("{}: {e}", self.path.display()))
    }

    /// Lets what the file says override the plan's values.
    fn apply(&self, plan: &mut RenderPlan) -> Result<(), Error> {
        let sf = &self.file;
        self.apply_meshes(plan)?;
        if let Some(c) = &sf.camera {
            let side = super::plan::side_bound(&plan.output, plan.format);
            plan.camera = self.camera(c, &plan.camera, &side)?;
        }
        if let Some(e) = &sf.environment {
            self.apply_environment(e, plan)?;
        }
        if let Some(m) = &sf.indexing {
            plan.settings.indexing = Indexing::from_name(m)
                .ok_or_else(|| self.error(format!("indexing: unknown mode '{m}'")))?;
        }
        if let Some(s) = sf.supersample {
            if !(1..=16).contains(&s) {
                return Err(self.error(format!("supersample {s} is outside 1..=16")));
            }
            plan.settings.supersample = s;
        }
        if let Some(b) = sf.background {
            plan.background = b;
        }
        Ok(())
    }

    /// The file's meshes replace the flag's object; its default material replaces the
    /// flag's material.
    fn apply_meshes(&self, plan: &mut RenderPlan) -> Result<(), Error> {
        let sf = &self.file;
        let default_material = match &sf.material {
            Some(m) => material_of(m).map_err(|e| self.error(e))?,
            None => plan
                .objects
                .first()
                .map(|o| o.material.clone())
                .unwrap_or_else(Material::mirror),
        };
        if !sf.meshes.is_empty() {
            plan.objects = (sf.meshes.iter().enumerate())
                .map(|(i, m)| self.object(i, m, &default_material))
                .collect::<Result<_, _>>()?;
        } else if sf.material.is_some() {
            for o in &mut plan.objects {
                o.material = default_material.clone();
            }
        }
        Ok(())
    }

    /// `meshes[i]`.
    fn object(
        &self,
        i: usize,
        m: &MeshEntry,
        default_material: &Material,
    ) -> Result<ObjectPlan, Error> {
        let source = match Builtin::from_name(&m.mesh) {
            Some(_) => parse_object(&m.mesh, m.tessellation),
            None => parse_object(&self.relative(&m.mesh), None),
        }
        .map_err(|e| self.error(format!("meshes[{i}]: {}", e.message)))?;
        let model = m
            .model
            .map(|c| Mat4::from_cols_array(&c))
            .unwrap_or(Mat4::IDENTITY);
        if !model.is_finite() || model.determinant() == 0.0 {
            return Err(self.error(format!("meshes[{i}]: the model matrix is singular")));
        }
        let material = match &m.material {
            Some(e) => material_of(e).map_err(|e| self.error(format!("meshes[{i}]: {e}")))?,
            None => default_material.clone(),
        };
        Ok(ObjectPlan {
            normalize: m.normalize.unwrap_or(matches!(source, MeshSource::File(_))),
            source,
            model,
            material,
        })
    }

    /// The file's camera, with `flags`' lens, clipping distances and size where it gives
    /// none.
    fn camera(
        &self,
        c: &CameraEntry,
        flags: &Camera,
        side: &crate::size::Bound,
    ) -> Result<Camera, Error> {
        let lens = match (c.ortho_half_height, c.fov) {
            (Some(h), _) => CameraLens::Orthographic { half_height: h },
            (None, Some(f)) => CameraLens::Perspective { fov_y_deg: f },
            (None, None) => flags.lens,
        };
        let camera = Camera {
            eye: Vec3::from_array(c.eye),
            target: Vec3::from_array(c.target),
            up: c.up.map(Vec3::from_array).unwrap_or(Vec3::Y),
            lens,
            near: c.near.unwrap_or(flags.near),
            far: c.far.unwrap_or(flags.far),
            width: c.width.unwrap_or(flags.width),
            height: c.height.unwrap_or(flags.height),
        };
        // The bounds of --size.
        for (key, n) in [("width", c.width), ("height", c.height)] {
            if let Some(n) = n {
                side.check(&format!("camera.{key}"), n as i64)
                    .map_err(|e| self.error(e.message))?;
            }
        }
        let most = mirrorball_io::Limits::default().max_texels;
        let pixels = camera.width as u64 * camera.height as u64;
        if pixels > most {
            return Err(self.error(format!(
                "camera.width {} × camera.height {}: {pixels} pixels, more than the {most} a picture mirrorball reads back may have",
                camera.width, camera.height
            )));
        }
        camera
            .validate()
            .map_err(|e| self.error(format!("camera: {e}")))?;
        Ok(camera)
    }

    /// `environment`: the map, its projection, attachment, filter and intensity.
    fn apply_environment(&self, e: &EnvEntry, plan: &mut RenderPlan) -> Result<(), Error> {
        plan.env_file = Some(self.relative(&e.file));
        if let Some(p) = &e.projection {
            plan.input.from = Some(
                ProjSpec::parse(p)
                    .map_err(|x| self.error(format!("environment.projection: {x}")))?,
            );
        }
        if let Some(a) = &e.attach {
            plan.attach = a
                .parse::<Attach>()
                .map_err(|e| self.error(format!("environment.attach: {e}")))?;
        }
        if let Some(f) = &e.filter {
            plan.filter = environment_filter(f)
                .map_err(|e| self.error(format!("environment.filter: {e}")))?;
        }
        if let Some(i) = e.intensity {
            if !(i.is_finite() && i >= 0.0) {
                return Err(self.error("environment.intensity must be ≥ 0"));
            }
            plan.intensity = i;
        }
        Ok(())
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
