//! `mirrorball studio`: the viewport in a browser, served by `mirrorball_studio` on
//! 127.0.0.1. Files are read here, as `render` reads scenes and `convert` reads
//! environments, so that the page shows the CLI's messages; the URL (with its token) is the
//! first line of standard output.

use crate::error::CliError;
use crate::load;
use crate::save::{self, SaveOptions};
use clap::Args;
use mirrorball::prefilter::outputs;
use mirrorball::render::RenderRequest;
use mirrorball_io::WriteOptions;
use mirrorball_studio::{Error as StudioError, Export, Host, Opened, SceneView, Studio};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;

#[derive(Args, Debug)]
pub struct StudioArgs {
    /// A scene file (.json or .toml, as `render` reads it), an environment map (any file
    /// `convert` reads) and/or a mesh (.obj, .glb, .gltf) shown in place of the scene's objects.
    files: Vec<String>,
    /// Port on 127.0.0.1 (0: any free one).
    #[arg(long, default_value_t = 0)]
    port: u16,
    /// Do not open the browser (the URL is printed either way).
    #[arg(long)]
    no_open: bool,
    /// The largest file the page may upload, in MiB.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u64).range(1..=65536))]
    max_upload: u64,
}

pub fn run(a: StudioArgs) -> Result<(), CliError> {
    let files: Vec<PathBuf> = a.files.iter().map(PathBuf::from).collect();
    let scenes = files.iter().filter(|f| is_scene(f)).count();
    if scenes > 1 {
        return Err(CliError::request("studio: give at most one scene file"));
    }
    // The scene first, then the environment laid on it.
    let mut ordered = files.clone();
    ordered.sort_by_key(|f| !is_scene(f));
    let studio = Studio {
        port: a.port,
        upload_limit: (a.max_upload << 20) as usize,
        ..Studio::default()
    };
    let running = studio
        .start(Arc::new(CliHost), &ordered)
        .map_err(|e| CliError::new(e.fault, e.message))?;
    let mut out = std::io::stdout();
    let _ = writeln!(out, "{}", running.url);
    let _ = out.flush();
    eprintln!(
        "mirrorball studio: serving on 127.0.0.1:{} (Ctrl-C stops it)",
        running.port
    );
    if !a.no_open {
        mirrorball_studio::open_browser(&running.url);
    }
    running
        .wait()
        .map_err(|e| CliError::new(e.fault, e.message))
}

/// The library's error as the studio's: whose fault it is and the I/O error's kind kept,
/// so the page is answered by cause.
fn as_studio(e: CliError) -> StudioError {
    let kind = e.io_kind();
    StudioError::new(e.fault, e.message).with_io_kind(kind)
}

/// [`as_studio`], `shown` (a path of this process's own) called `name` in the message.
fn studio_error(e: CliError, shown: &str, name: &str) -> StudioError {
    let message = e.message.replace(shown, name);
    StudioError {
        message,
        ..as_studio(e)
    }
}

fn is_scene(p: &Path) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("json") || e.eq_ignore_ascii_case("toml"))
}

/// The scene `render` would draw with `scene` (or its defaults) at one sample a pixel (the
/// viewport's).
fn scene_view(scene: Option<&Path>) -> Result<SceneView, CliError> {
    let mut request = RenderRequest {
        ss: 1,
        given: vec!["ss".into()],
        ..RenderRequest::default()
    };
    match scene {
        Some(s) => request.scene = Some(s.to_string_lossy().into_owned()),
        // A mirror wants an environment: the scene waiting for one is planned with a
        // material that needs none, then made a mirror.
        None => {
            request.material = "cheap-chrome".into();
            request.no_background = true;
        }
    }
    let (mut scene_data, camera, settings, exposure, tone, builtins) =
        mirrorball::render::studio_scene(&request)?;
    if scene.is_none() {
        scene_data.background = true;
        for o in &mut scene_data.objects {
            o.material = mirrorball_render::Material::mirror();
        }
    }
    Ok(SceneView {
        name: scene.map_or("a mirror sphere".into(), |s| s.display().to_string()),
        scene: scene_data,
        camera,
        settings,
        exposure,
        tone,
        source: scene
            .map(mirrorball::render::schema::portable)
            .transpose()?,
        builtins,
    })
}

/// A new folder of this process's own under the system's temporary folder, named for
/// `purpose` and a fresh token (so that no other process can have made it): the caller
/// removes it.
fn private_dir(purpose: &str) -> Result<PathBuf, StudioError> {
    let dir = std::env::temp_dir().join(format!(
        "mirrorball-studio-{purpose}-{}-{}",
        std::process::id(),
        mirrorball_studio::guard::new_token()?
    ));
    std::fs::create_dir(&dir).map_err(|e| StudioError::io("cannot make a private folder", &e))?;
    Ok(dir)
}

/// Reads files as the CLI's commands do.
struct CliHost;

impl CliHost {
    /// The environment map at `path`, called `name` in messages.
    fn environment(path: &Path, name: &str) -> Result<Opened, StudioError> {
        let shown = path.display().to_string();
        let src = load::load(&shown, None, None, &mirrorball_io::Limits::default())
            .map_err(|e| studio_error(e, &shown, name))?;
        Ok(CliHost::shown_environment(src, name))
    }

    /// The environment map uploaded as `name`, read from its bytes as `load` reads a file.
    fn uploaded_environment(name: &str, bytes: &[u8]) -> Result<Opened, StudioError> {
        let src = load::from_bytes(name, bytes, None, None, &mirrorball_io::Limits::default())
            .map_err(|e| studio_error(e, name, name))?;
        Ok(CliHost::shown_environment(src, name))
    }

    fn shown_environment(src: load::Source, name: &str) -> Opened {
        let mut map = src.env;
        map.sanitize();
        Opened::Environment {
            name: name.to_string(),
            map: Box::new(map),
        }
    }

    /// The mesh file at `path`, called `name` in messages (as `render` reads mesh files).
    fn mesh(path: &Path, name: &str) -> Result<mirrorball_render::Mesh, StudioError> {
        let shown = path.display().to_string();
        mirrorball_render::load_mesh(path)
            .map_err(|e| studio_error(CliError::from(e), &shown, name))
    }

    /// The mesh uploaded as `name` (its extension says the format), read from its bytes as
    /// `render` reads mesh files.
    fn mesh_bytes(name: &str, bytes: &[u8]) -> Result<mirrorball_render::Mesh, StudioError> {
        mirrorball_render::load_mesh_bytes(name, bytes)
            .map_err(|e| studio_error(CliError::from(e), name, name))
    }
}

/// `e`, a failure to store `name`'s upload.
fn cannot_store(name: &str, e: StudioError) -> StudioError {
    e.context(format!("{name}: cannot store the upload"))
}

impl CliHost {
    /// The uploaded scene `name` (`bytes`, a scene file of extension `ext`), read as `render`
    /// reads it, the files it names being only these (the studio reads no path a page
    /// names): a file uploaded `alongside` it, by its file name, or the bunny the binary
    /// bundles (a path ending in `assets/meshes/bunny.obj`). They are written with the scene
    /// into a folder of its own, the scene's paths made theirs, and the folder removed once
    /// read. The scene exports with its paths as it wrote them.
    fn uploaded_scene(
        name: &str,
        ext: &str,
        bytes: &[u8],
        alongside: &[(String, Vec<u8>)],
    ) -> Result<Opened, StudioError> {
        let dir = private_dir("scene").map_err(|e| cannot_store(name, e))?;
        let result = CliHost::scene_in(&dir, name, ext, bytes, alongside);
        let _ = std::fs::remove_dir_all(&dir);
        result
    }

    /// [`CliHost::uploaded_scene`] in the folder `dir`.
    fn scene_in(
        dir: &Path,
        name: &str,
        ext: &str,
        bytes: &[u8],
        alongside: &[(String, Vec<u8>)],
    ) -> Result<Opened, StudioError> {
        let stored =
            |e: std::io::Error| StudioError::io(format!("{name}: cannot store the upload"), &e);
        // Checked as render reads it, with its messages, in the upload's name.
        let written = dir.join(format!("scene.{ext}"));
        std::fs::write(&written, bytes).map_err(stored)?;
        let shown = written.display().to_string();
        let as_written = mirrorball::render::schema::as_written(&written)
            .map_err(|e| studio_error(e, &shown, name))?;
        let files = dir.join("files");
        std::fs::create_dir(&files).map_err(stored)?;
        // What each file the scene names became, to name it as the scene does in messages.
        let mut renamed: Vec<(String, String)> = Vec::new();
        let mut resolved = as_written.clone();
        mirrorball::render::schema::map_files(&mut resolved, |f| -> Result<String, StudioError> {
            let file_name = Path::new(f).file_name().and_then(|n| n.to_str());
            let bytes: &[u8] = match alongside.iter().find(|(n, _)| Some(n.as_str()) == file_name) {
                Some((_, b)) => b,
                None if f.replace('\\', "/").ends_with(BUNNY_PATH) => BUNNY,
                None => {
                    return Err(StudioError::request(format!(
                        "{name}: names the file {f}, which the studio may not read: a scene opened on \
                         the page may name only the built-in objects ({}), the bundled {BUNNY_PATH} \
                         and files picked or dropped together with it (pick or drop {} with the scene, \
                         or open the scene from the command line: mirrorball studio SCENE)",
                        mirrorball_render::Builtin::ALL.map(|b| b.name()).join(", "),
                        file_name.unwrap_or(f),
                    )))
                }
            };
            // Each file in a folder of its own, under its own name (its extension says
            // what it is).
            let sub = files.join(renamed.len().to_string());
            std::fs::create_dir(&sub).map_err(stored)?;
            let path = sub.join(file_name.unwrap_or("file"));
            std::fs::write(&path, bytes).map_err(stored)?;
            let path = path.display().to_string();
            renamed.push((path.clone(), f.to_string()));
            Ok(path)
        })?;
        let scene = dir.join("scene-resolved.json");
        let text = serde_json::to_string(&resolved)
            .map_err(|e| StudioError::system(format!("{name}: {e}")))?;
        std::fs::write(&scene, text).map_err(stored)?;
        let shown_resolved = scene.display().to_string();
        let named = |e: CliError| {
            let mut m = e.message.replace(&shown_resolved, name);
            for (path, f) in &renamed {
                m = m.replace(path, f);
            }
            StudioError::new(e.fault, m).with_io_kind(e.io_kind())
        };
        let mut view = scene_view(Some(&scene)).map_err(named)?;
        view.name = name.to_string();
        view.source = Some(as_written);
        Ok(Opened::Scene(Box::new(view)))
    }
}

/// Where the repository keeps the bundled bunny: an uploaded scene naming a path that ends
/// so is given the bundled one.
const BUNNY_PATH: &str = "assets/meshes/bunny.obj";

/// The Stanford bunny the repository bundles (`assets/meshes/bunny.obj`, CC0 as its README
/// says), offered by the page beside the built-ins.
const BUNNY: &[u8] = include_bytes!("../../../../assets/meshes/bunny.obj");

fn is_mesh(p: &Path) -> bool {
    p.extension().and_then(|e| e.to_str()).is_some_and(|e| {
        ["obj", "glb", "gltf"]
            .iter()
            .any(|m| e.eq_ignore_ascii_case(m))
    })
}

impl Host for CliHost {
    fn open(&self, path: &Path) -> Result<Opened, StudioError> {
        if is_scene(path) {
            let v = scene_view(Some(path)).map_err(as_studio)?;
            return Ok(Opened::Scene(Box::new(v)));
        }
        if is_mesh(path) {
            let name = path.display().to_string();
            return Ok(Opened::Mesh {
                mesh: Box::new(CliHost::mesh(path, &name)?),
                name,
            });
        }
        CliHost::environment(path, &path.display().to_string())
    }

    fn upload(
        &self,
        name: &str,
        bytes: &[u8],
        alongside: &[(String, Vec<u8>)],
    ) -> Result<Opened, StudioError> {
        // Only the name's extension is used where a file is written to a folder of its own.
        let ext = Path::new(name)
            .extension()
            .and_then(|e| e.to_str())
            .filter(|e| e.chars().all(|c| c.is_ascii_alphanumeric()))
            .unwrap_or("bin");
        if is_scene(Path::new(name)) {
            return CliHost::uploaded_scene(name, ext, bytes, alongside);
        }
        if is_mesh(Path::new(name)) {
            return Ok(Opened::Mesh {
                name: name.to_string(),
                mesh: Box::new(CliHost::mesh_bytes(name, bytes)?),
            });
        }
        CliHost::uploaded_environment(name, bytes)
    }

    fn bundled_meshes(&self) -> &'static [&'static str] {
        &["bunny"]
    }

    fn bundled_mesh(&self, name: &str) -> Result<mirrorball_render::Mesh, StudioError> {
        match name {
            "bunny" => CliHost::mesh_bytes("bunny.obj", BUNNY),
            _ => Err(StudioError::request(format!("no bundled mesh {name}"))),
        }
    }

    fn default_scene(&self) -> SceneView {
        scene_view(None).expect("render's defaults make a scene")
    }

    fn export(&self, what: Export<'_>, format: &str) -> Result<Vec<u8>, StudioError> {
        // Made in memory as `convert` and `prefilter` make their outputs.
        let file = format!("export.{format}");
        let (bytes, report) = match what {
            Export::Map(map) => {
                let opts = SaveOptions {
                    layout: None,
                    write: WriteOptions::default(),
                    mips: false,
                    keep_invalid: false,
                };
                save::to_bytes(map, &file, &opts).map_err(as_studio)?
            }
            Export::Chain(chain) => {
                outputs::cube_chain_bytes(&file, chain, &WriteOptions::default(), false)
                    .map_err(as_studio)?
            }
        };
        // Said on the server's terminal: the page downloads the file as it is.
        if let Some(line) = report.line(&file, &[]) {
            eprintln!("{line}");
        }
        Ok(bytes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorball::core::{EnvMap, Image, ProjectionKind};
    use mirrorball_core::Fault;

    fn exr() -> Vec<u8> {
        let p = ProjectionKind::LatLong.default_projection();
        let env = EnvMap::new(p, vec![Image::new(16, 8, 3)]).unwrap();
        let opts = SaveOptions {
            layout: None,
            write: WriteOptions::default(),
            mips: false,
            keep_invalid: false,
        };
        save::to_bytes(&env, "sky.exr", &opts).unwrap().0
    }

    #[test]
    fn uploads_are_read_from_memory_and_refused_by_cause() {
        let bytes = exr();
        match CliHost.upload("sky.exr", &bytes, &[]) {
            Ok(Opened::Environment { name, map }) => {
                assert_eq!(name, "sky.exr");
                assert_eq!((map.width(), map.height()), (16, 8));
            }
            Ok(_) => panic!("not an environment"),
            Err(e) => panic!("{e}"),
        }
        let e = CliHost.upload("cut.exr", &bytes[..60], &[]).err().unwrap();
        assert_eq!((e.fault, e.status().as_u16()), (Fault::Input, 422), "{e}");
        assert!(e.message.starts_with("cut.exr"), "{e}");
        let e = CliHost.upload("notes.txt", b"hello", &[]).err().unwrap();
        assert_eq!(e.status(), 400, "{e}");
    }

    #[test]
    fn exports_are_made_in_memory() {
        let p = ProjectionKind::Cube.default_projection();
        let cube = EnvMap::new(p, (0..6).map(|_| Image::new(8, 8, 3)).collect()).unwrap();
        let bytes = CliHost.export(Export::Map(&cube), "ktx2").unwrap();
        assert_eq!(&bytes[1..7], b"KTX 20");
        let half = EnvMap::new(p, (0..6).map(|_| Image::new(4, 4, 3)).collect()).unwrap();
        let bytes = CliHost
            .export(Export::Chain(&[cube.clone(), half]), "dds")
            .unwrap();
        assert_eq!(&bytes[..4], b"DDS ");
        // A lat-long is no cube: the request's fault.
        let ll = ProjectionKind::LatLong.default_projection();
        let flat = EnvMap::new(ll, vec![Image::new(16, 8, 3)]).unwrap();
        let e = CliHost.export(Export::Map(&flat), "dds").unwrap_err();
        assert_eq!(e.status(), 400, "{e}");
    }
}
