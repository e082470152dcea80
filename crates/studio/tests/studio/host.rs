//! A host for the tests: environments read by `mirrorball-io` (the reader the CLI uses,
//! whose messages it shows), a mirror sphere as the default scene; and a raw HTTP client,
//! so that every header (Host, Origin) is the test's to forge.

use mirrorball_core::glam::{Mat4, Vec3};
use mirrorball_core::{EnvMap, Image, ProjectionKind};
use mirrorball_render::tone::Tone;
use mirrorball_render::{Builtin, Camera, Material, Object, Scene, Settings};
use mirrorball_studio::{Error, Export, Host, Opened, Running, SceneView, Studio};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub struct TestHost;

/// The reader's error as the studio's, `shown` called `name`: its fault and I/O kind kept.
fn studio_error(e: mirrorball_io::Error, shown: &str, name: &str) -> Error {
    Error::new(e.fault(), e.to_string().replace(shown, name)).with_io_kind(e.io_kind())
}

/// The name of an upload the test host fails as a full disk would (a system fault).
pub const FULL_DISK: &str = "full-disk.exr";

impl TestHost {
    fn shown(loaded: mirrorball_io::Loaded, name: &str) -> Result<Opened, Error> {
        let img = loaded
            .layers
            .into_iter()
            .next()
            .ok_or_else(|| Error::input("no picture"))?;
        // The tests' maps are lat-long (the CLI guesses; see crates/cli/src/load.rs).
        let proj = ProjectionKind::LatLong.default_projection();
        let map = EnvMap::new(proj, vec![img]).map_err(|e| Error::input(e.to_string()))?;
        Ok(Opened::Environment {
            name: name.into(),
            map: Box::new(map),
        })
    }
}

impl Host for TestHost {
    fn open(&self, path: &Path) -> Result<Opened, Error> {
        let name = path.display().to_string();
        let loaded = mirrorball_io::read(path, &mirrorball_io::Limits::default())
            .map_err(|e| studio_error(e, &name, &name))?;
        TestHost::shown(loaded, &name)
    }
    fn upload(
        &self,
        name: &str,
        bytes: &[u8],
        _alongside: &[(String, Vec<u8>)],
    ) -> Result<Opened, Error> {
        if name == FULL_DISK {
            let full = std::io::Error::from(std::io::ErrorKind::StorageFull);
            return Err(Error::io(format!("{name}: cannot store the upload"), &full));
        }
        let hint = mirrorball_io::Hint::Name(name);
        let loaded = mirrorball_io::read_bytes(bytes, hint, &mirrorball_io::Limits::default())
            .map_err(|e| studio_error(e, name, name))?;
        TestHost::shown(loaded, name)
    }
    fn default_scene(&self) -> SceneView {
        SceneView {
            name: "a mirror sphere".into(),
            scene: Scene {
                objects: vec![Object {
                    mesh: Arc::new(Builtin::Sphere.mesh(16)),
                    model: Mat4::from_translation(Vec3::new(0.0, 0.5, 0.0)),
                    material: Material::mirror(),
                }],
                environment: None,
                background: true,
            },
            camera: Camera::perspective(Vec3::new(0.0, 0.0, 3.5), Vec3::ZERO, 40.0, 64, 48),
            settings: Settings::default(),
            exposure: 0.0,
            tone: Tone::Clamp,
            source: None,
            builtins: vec![Some((Builtin::Sphere, 16))],
        }
    }
    fn export(&self, what: Export<'_>, format: &str) -> Result<Vec<u8>, Error> {
        let file = format!("export.{format}");
        let hint = mirrorball_io::Hint::Name(&file);
        let opts = mirrorball_io::WriteOptions::default();
        let levels: Vec<Vec<Image>> = match what {
            Export::Map(map) => vec![map.layers().to_vec()],
            Export::Chain(chain) => chain.iter().map(|l| l.layers().to_vec()).collect(),
        };
        mirrorball_io::write_bytes(&levels, hint, &opts).map_err(|e| studio_error(e, &file, &file))
    }
}

/// A lat-long EXR of 16×8 texels in `dir`.
pub fn latlong_exr(dir: &Path) -> PathBuf {
    let mut img = Image::new(16, 8, 3);
    for y in 0..8 {
        for x in 0..16 {
            img.set(x, y, &[x as f32 / 16.0, y as f32 / 8.0, 0.5]);
        }
    }
    let path = dir.join("map.exr");
    mirrorball_io::write_image(&path, &img, &mirrorball_io::WriteOptions::default()).unwrap();
    path
}

/// A studio on a free port, with `files` opened.
pub fn start(files: &[PathBuf]) -> Running {
    let studio = Studio {
        upload_limit: 1 << 20,
        ..Studio::default()
    };
    studio
        .start(Arc::new(TestHost), files)
        .expect("the studio starts")
}

/// An answer: status, headers (lower-case names), body.
pub struct Answer {
    pub status: u16,
    pub headers: Vec<(String, String)>,
    pub body: Vec<u8>,
}

impl Answer {
    pub fn text(&self) -> String {
        String::from_utf8_lossy(&self.body).into_owned()
    }
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }
}

/// Sends `method target` to the server on `port` with exactly `headers` (and a body), and
/// reads the whole answer.
pub fn request(
    port: u16,
    method: &str,
    target: &str,
    headers: &[(&str, &str)],
    body: &[u8],
) -> Answer {
    let mut s = std::net::TcpStream::connect(("127.0.0.1", port)).unwrap();
    let mut head = format!("{method} {target} HTTP/1.1\r\nConnection: close\r\n");
    for (k, v) in headers {
        head.push_str(&format!("{k}: {v}\r\n"));
    }
    if !body.is_empty() || method == "POST" {
        head.push_str(&format!("Content-Length: {}\r\n", body.len()));
    }
    head.push_str("\r\n");
    s.write_all(head.as_bytes()).unwrap();
    // The server may answer (413) before it has read the whole body.
    let _ = s.write_all(body);
    let mut raw = Vec::new();
    let _ = s.read_to_end(&mut raw);
    let split = raw
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .expect("an HTTP answer");
    let head = String::from_utf8_lossy(&raw[..split]).into_owned();
    let mut lines = head.lines();
    let status = lines
        .next()
        .unwrap()
        .split(' ')
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    let headers: Vec<(String, String)> = lines
        .filter_map(|l| l.split_once(':'))
        .map(|(k, v)| (k.trim().to_ascii_lowercase(), v.trim().to_string()))
        .collect();
    let mut body = raw[split + 4..].to_vec();
    if headers
        .iter()
        .any(|(k, v)| k == "transfer-encoding" && v == "chunked")
    {
        body = dechunk(&body);
    }
    Answer {
        status,
        headers,
        body,
    }
}

fn dechunk(mut b: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    loop {
        let nl = b.windows(2).position(|w| w == b"\r\n").unwrap();
        let n = usize::from_str_radix(std::str::from_utf8(&b[..nl]).unwrap().trim(), 16).unwrap();
        if n == 0 {
            return out;
        }
        out.extend_from_slice(&b[nl + 2..nl + 2 + n]);
        b = &b[nl + 2 + n + 2..];
    }
}

/// A request as the studio's own page sends it: its Host, its token header.
pub fn own(r: &Running, method: &str, target: &str, body: &[u8]) -> Answer {
    let host = format!("127.0.0.1:{}", r.port);
    request(
        r.port,
        method,
        target,
        &[("Host", &host), ("X-Mirrorball-Token", &r.token)],
        body,
    )
}
