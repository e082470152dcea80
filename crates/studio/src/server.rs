//! The routes, on 127.0.0.1 only, every request through the [`Guard`].
//!
//! | route | what |
//! | --- | --- |
//! | `GET /` | the page (`?view=viewport`: the viewport alone, at the camera's size) |
//! | `GET /web/NAME` | the page's scripts and shaders, embedded in the binary |
//! | `GET /api/state` | what is loaded, as JSON ([`State::describe`]) |
//! | `GET /api/environment?projection=native\|SPEC&size=N&precision=half\|float&mips=0\|1&limit=N` | the environment's texels, with its mip chain for `mips=1` ([`texture`]); resampled smaller where its padded atlas would be over `limit` texels on a side (the page's GPU's `MAX_TEXTURE_SIZE`), the header's `fitted` saying so |
//! | `GET /api/mesh/I?tessellation=N` | object `I` in world space ([`geometry`]); a built-in tessellated `N` (`state::MAX_TRIANGLES` at most) |
//! | `GET /api/grid?projection=SPEC&n=N` | directions with the core's texture coordinates ([`grid`]) |
//! | `POST /api/directions?projection=native\|SPEC` | the core's direction of each `(u, v, layer)` of the body, in the map `/api/environment` sends for the same `projection` ([`grid::directions`]) |
//! | `GET /api/analysis?projection=native\|SPEC&size=N&fov=DEG&aspect=A&forward=X,Y,Z&up=X,Y,Z` | the projection of that map measured and drawn by the analysis crate (`analyze_projection`: what `mirrorball analyze --projection P --size N` writes of it), and the share of its texels the camera's frustum sees |
//! | `GET /api/lighting?size=N&mapping=M` | the environment prefiltered: a GGX cube chain and SH9 ([`lighting`]), the last one kept |
//! | `GET /api/lighting/progress` | `{"done", "total", "busy"}`: rows of the prefilter running |
//! | `GET /api/export?what=map\|chain&format=EXT&projection=…&size=N` | a file to download, written by the [`Host`]: the map (as loaded, or converted as `/api/environment` converts it) or the last prefiltered chain |
//! | `POST /api/upload?name=FILE` | a file to read (the body, at most the upload limit): a scene, an environment or a mesh; a scene may name the files held for it |
//! | `POST /api/upload?name=FILE&alongside=1` | a file held, unread, for the scene uploaded next (the files picked or dropped with it; all of them together at most the upload limit); any other upload lets them go |
//! | `POST /api/object?name=scene\|BUILTIN\|BUNDLED\|OPENED&tessellation=N` | shows one object in place of the scene's (a built-in, a mesh the [`Host`] bundles, or the mesh file opened last), or the scene's own again |

use crate::guard::Guard;
use crate::state::{gpu_kind, ObjectChoice, State};
use crate::{geometry, grid, lighting, texture, web, Error, Export, Host, EXPORT_FORMATS};
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::{DefaultBodyLimit, Path as UrlPath, Query, Request, State as Shared};
use axum::http::{header, HeaderValue, StatusCode};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use mirrorball_core::projection::ProjectionSpec;
use mirrorball_core::{resample, Choice, EnvMap, ResampleOptions};
use mirrorball_render::Builtin;
use serde::Deserialize;
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

/// How to start the studio.
#[derive(Clone, Debug)]
pub struct Studio {
    /// The port on 127.0.0.1 (0: any free one).
    pub port: u16,
    /// The largest upload, in bytes.
    pub upload_limit: usize,
    /// The largest conversion the page may ask for (face edge, width or diameter).
    pub max_size: u32,
}

impl Default for Studio {
    fn default() -> Self {
        Studio {
            port: 0,
            upload_limit: 256 << 20,
            max_size: 4096,
        }
    }
}

/// A studio serving in the background.
pub struct Running {
    /// The URL to open, with the token.
    pub url: String,
    pub port: u16,
    pub token: String,
    stop: Option<tokio::sync::oneshot::Sender<()>>,
    thread: Option<std::thread::JoinHandle<Result<(), Error>>>,
}

impl Running {
    /// Serves until the process ends (or the server fails).
    pub fn wait(mut self) -> Result<(), Error> {
        match self.thread.take().map(|t| t.join()) {
            Some(Ok(r)) => r,
            Some(Err(_)) => Err(Error::system("the server thread panicked")),
            None => Ok(()),
        }
    }

    /// Stops serving and waits for the server to finish.
    pub fn stop(mut self) {
        if let Some(s) = self.stop.take() {
            let _ = s.send(());
        }
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// What every handler shares.
struct App {
    host: Arc<dyn Host>,
    state: Mutex<State>,
    guard: Guard,
    options: Studio,
    /// The files uploaded `alongside=1`, by name, for the next upload.
    held: Mutex<Vec<(String, Vec<u8>)>>,
    /// The last conversion asked for, by its query.
    converted: Mutex<Option<(String, Arc<EnvMap>)>>,
    /// The last prefiltered lighting (and its payload), by its request, and the running
    /// one's progress.
    lit: Mutex<Option<(String, Lit)>>,
    lit_progress: Progress,
}

/// Rows done of the prefilter running, of how many.
#[derive(Default)]
struct Progress {
    done: Arc<AtomicU64>,
    total: AtomicU64,
    busy: AtomicBool,
}

/// A prefiltered chain and its payload for the page.
type Lit = (Arc<lighting::Lighting>, Arc<Vec<u8>>);

type AppState = Arc<App>;

impl Studio {
    /// Reads `files` (a scene and/or an environment, in order) through `host`, binds the
    /// port and serves in a thread of its own. A file that cannot be read, or a port that
    /// cannot be bound, is an error before anything is served.
    pub fn start(&self, host: Arc<dyn Host>, files: &[PathBuf]) -> Result<Running, Error> {
        let mut state = State::new(host.default_scene());
        state.bundled = host.bundled_meshes();
        for f in files {
            state.apply(host.open(f)?);
        }
        let listen = format!("cannot listen on 127.0.0.1:{}", self.port);
        let listener = std::net::TcpListener::bind(("127.0.0.1", self.port))
            .map_err(|e| Error::io(&listen, &e))?;
        let port = listener
            .local_addr()
            .map_err(|e| Error::io(&listen, &e))?
            .port();
        listener
            .set_nonblocking(true)
            .map_err(|e| Error::io(&listen, &e))?;
        let token = crate::guard::new_token()?;
        let url = format!("http://127.0.0.1:{port}/?token={token}");
        let app = Arc::new(App {
            host,
            state: Mutex::new(state),
            guard: Guard {
                port,
                token: token.clone(),
            },
            options: self.clone(),
            held: Mutex::new(Vec::new()),
            converted: Mutex::new(None),
            lit: Mutex::new(None),
            lit_progress: Progress::default(),
        });
        let (stop, stopped) = tokio::sync::oneshot::channel::<()>();
        let thread = std::thread::Builder::new()
            .name("studio".into())
            .spawn(move || serve(app, listener, stopped))
            .map_err(|e| Error::io("cannot start the server thread", &e))?;
        Ok(Running {
            url,
            port,
            token,
            stop: Some(stop),
            thread: Some(thread),
        })
    }
}

/// Serves `listener` until `stopped`.
fn serve(
    app: AppState,
    listener: std::net::TcpListener,
    stopped: tokio::sync::oneshot::Receiver<()>,
) -> Result<(), Error> {
    let serving = "cannot serve";
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_io()
        .build()
        .map_err(|e| Error::io(serving, &e))?;
    rt.block_on(async move {
        let listener =
            tokio::net::TcpListener::from_std(listener).map_err(|e| Error::io(serving, &e))?;
        let limit = app.options.upload_limit;
        let router = Router::new()
            .route("/", get(index))
            .route("/web/{*name}", get(asset))
            .route("/api/state", get(state))
            .route("/api/environment", get(environment))
            .route("/api/mesh/{i}", get(mesh))
            .route("/api/grid", get(grid_of))
            .route(
                "/api/directions",
                post(directions_of).layer(DefaultBodyLimit::max(12 * grid::MAX_LOOKUPS)),
            )
            .route("/api/analysis", get(analysis_of))
            .route("/api/lighting", get(lighting_of))
            .route("/api/lighting/progress", get(lighting_progress))
            .route("/api/export", get(export))
            .route("/api/object", post(object))
            .route(
                "/api/upload",
                post(upload).layer(DefaultBodyLimit::max(limit)),
            )
            .layer(middleware::from_fn_with_state(app.clone(), guarded))
            .with_state(app);
        axum::serve(listener, router)
            .with_graceful_shutdown(async {
                let _ = stopped.await;
            })
            .await
            .map_err(|e| Error::io(serving, &e))
    })
}

/// Refuses what the guard refuses; marks every answer as not to be cached or sniffed.
async fn guarded(Shared(app): Shared<AppState>, req: Request, next: Next) -> Response {
    if let Err((status, why)) = app.guard.check(req.headers(), req.uri().query()) {
        return (status, why).into_response();
    }
    let mut r = next.run(req).await;
    let h = r.headers_mut();
    h.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    h.insert(
        "x-content-type-options",
        HeaderValue::from_static("nosniff"),
    );
    h.insert("referrer-policy", HeaderValue::from_static("no-referrer"));
    h.insert("x-frame-options", HeaderValue::from_static("DENY"));
    r
}

fn bad(status: StatusCode, message: impl Into<String>) -> Response {
    (status, Json(serde_json::json!({ "error": message.into() }))).into_response()
}

fn binary(bytes: Vec<u8>) -> Response {
    ([(header::CONTENT_TYPE, "application/octet-stream")], bytes).into_response()
}

async fn index() -> Response {
    web::get("index.html").map_or_else(|| bad(StatusCode::NOT_FOUND, "no page"), web::respond)
}

async fn asset(UrlPath(name): UrlPath<String>) -> Response {
    web::get(&name).map_or_else(
        || bad(StatusCode::NOT_FOUND, format!("no {name}")),
        web::respond,
    )
}

async fn state(Shared(app): Shared<AppState>) -> Response {
    let s = app.state.lock().expect("state");
    Json(s.describe()).into_response()
}

#[derive(Deserialize)]
struct EnvQuery {
    projection: Option<String>,
    size: Option<u32>,
    precision: Option<String>,
    mips: Option<String>,
    /// The largest texture edge the page's GPU takes (`GL_MAX_TEXTURE_SIZE`).
    limit: Option<u32>,
}

async fn environment(Shared(app): Shared<AppState>, Query(q): Query<EnvQuery>) -> Response {
    let precision = match q
        .precision
        .as_deref()
        .unwrap_or("half")
        .parse::<texture::Precision>()
    {
        Ok(p) => p,
        Err(e) => return bad(StatusCode::BAD_REQUEST, format!("precision: {e}")),
    };
    let mips = match q.mips.as_deref().unwrap_or("0") {
        "0" => false,
        "1" => true,
        m => {
            return bad(
                StatusCode::BAD_REQUEST,
                format!("mips: '{m}' is not 0 or 1"),
            )
        }
    };
    let map = {
        let s = app.state.lock().expect("state");
        match &s.view.scene.environment {
            Some(e) => e.map.clone(),
            None => return bad(StatusCode::NOT_FOUND, "no environment is loaded"),
        }
    };
    let projection = q.projection.unwrap_or_else(|| "native".into());
    let work = tokio::task::spawn_blocking(move || -> Result<Vec<u8>, (StatusCode, String)> {
        let map = if projection != "native" {
            convert(&app, &map, &projection, q.size)?
        } else {
            map
        };
        // A projection without a shader (the dual fisheye), loaded or asked for, is drawn
        // from the exact lat-long conversion of that map; the header's kind says so.
        let map = if gpu_kind(map.projection()).is_none() {
            convert(&app, &map, "latlong", q.size)?
        } else {
            map
        };
        let (map, fitted) = match q.limit {
            Some(limit) => fit(&app, map, limit, mips)?,
            None => (map, None),
        };
        Ok(if mips {
            texture::encode_mips(&map, precision, fitted)
        } else {
            texture::encode(&map, precision, fitted)
        })
    });
    match work.await {
        Ok(Ok(b)) => binary(b),
        Ok(Err((s, m))) => bad(s, m),
        Err(e) => bad(StatusCode::INTERNAL_SERVER_ERROR, e.to_string()),
    }
}

/// `map` as a GPU whose textures are at most `limit` texels on a side takes it: itself
/// when its padded atlas (with the chain, for `mips`) fits, else resampled by the core
/// (antialiased, as `convert` shrinks) to the largest size of its projection whose atlas
/// fits, with what was done for the page to say.
fn fit(
    app: &App,
    map: Arc<EnvMap>,
    limit: u32,
    mips: bool,
) -> Result<(Arc<EnvMap>, Option<texture::Fitted>), (StatusCode, String)> {
    let from = (map.width(), map.height());
    let (aw, ah) = texture::atlas_extent(from, mips);
    if aw <= limit && ah <= limit {
        return Ok((map, None));
    }
    let size =
        texture::fitting_size(map.projection(), map.width(), limit, mips).ok_or_else(|| {
            (
                StatusCode::BAD_REQUEST,
                format!(
                    "limit: no {} map fits textures of {limit} texels",
                    map.projection().name()
                ),
            )
        })?;
    let spec = map.projection().to_string();
    let fitted = convert(app, &map, &spec, Some(size))?;
    Ok((fitted, Some(texture::Fitted { from, limit })))
}

/// `map` in the projection `spec` at `size` (default: the core's resolution match), the
/// last one kept.
fn convert(
    app: &App,
    map: &Arc<EnvMap>,
    spec: &str,
    size: Option<u32>,
) -> Result<Arc<EnvMap>, (StatusCode, String)> {
    let req = |m: String| (StatusCode::BAD_REQUEST, m);
    let p = ProjectionSpec::parse(spec)
        .and_then(|s| s.build(None))
        .map_err(|e| req(format!("projection: {e}")))?;
    let size = size.unwrap_or_else(|| map.width().max(map.height()).min(app.options.max_size));
    if !(1..=app.options.max_size).contains(&size) {
        return Err(req(format!(
            "size {size} is outside 1..={}",
            app.options.max_size
        )));
    }
    let key = format!("{:p} {p} {size}", Arc::as_ptr(map));
    if let Some((k, m)) = app.converted.lock().expect("cache").as_ref() {
        if *k == key {
            return Ok(m.clone());
        }
    }
    let out = Arc::new(resample(map, p, size, &ResampleOptions::default()));
    *app.converted.lock().expect("cache") = Some((key, out.clone()));
    Ok(out)
}

#[derive(Deserialize)]
struct LightingQuery {
    size: Option<u32>,
    mapping: Option<String>,
}

/// The environment prefiltered, on a blocking thread (the server keeps answering, the page
/// keeps drawing); one prefilter at a time, the last result kept.
async fn lighting_of(Shared(app): Shared<AppState>, Query(q): Query<LightingQuery>) -> Response {
    let (size, mapping) = match lighting::request(q.size, q.mapping.as_deref()) {
        Ok(r) => r,
        Err(e) => return bad(StatusCode::BAD_REQUEST, e),
    };
    let map = {
        let s = app.state.lock().expect("state");
        match &s.view.scene.environment {
            Some(e) => e.map.clone(),
            None => return bad(StatusCode::NOT_FOUND, "no environment is loaded"),
        }
    };
    let key = format!("{:p} {size} {}", Arc::as_ptr(&map), mapping.name());
    if let Some((k, (_, b))) = app.lit.lock().expect("lit").as_ref() {
        if *k == key {
            return binary(b.to_vec());
        }
    }
    let p = &app.lit_progress;
    if p.busy.swap(true, Ordering::SeqCst) {
        return bad(
            StatusCode::CONFLICT,
            "a prefilter is already running: ask again when it is done",
        );
    }
    p.done.store(0, Ordering::SeqCst);
    p.total
        .store(lighting::work(&map, size, &mapping), Ordering::SeqCst);
    let done = p.done.clone();
    let work = tokio::task::spawn_blocking(move || {
        let l = lighting::prefilter(&map, size, mapping, done);
        let b = lighting::encode(&l);
        (Arc::new(l), Arc::new(b))
    })
    .await;
    p.busy.store(false, Ordering::SeqCst);
    match work {
        Ok((l, b)) => {
            *app.lit.lock().expect("lit") = Some((key, (l, b.clone())));
            binary(b.to_vec())
        }
        Err(e) => bad(StatusCode::INTERNAL_SERVER_ERROR, e.to_string()),
    }
}

async fn lighting_progress(Shared(app): Shared<AppState>) -> Response {
    let p = &app.lit_progress;
    Json(serde_json::json!({
        "done": p.done.load(Ordering::SeqCst),
        "total": p.total.load(Ordering::SeqCst),
        "busy": p.busy.load(Ordering::SeqCst),
    }))
    .into_response()
}

#[derive(Deserialize)]
struct ExportQuery {
    what: Option<String>,
    format: Option<String>,
    projection: Option<String>,
    size: Option<u32>,
}

/// A file to download: the map (converted as the page shows it) or the last prefiltered
/// chain, in the container asked for, written by the host on a blocking thread.
async fn export(Shared(app): Shared<AppState>, Query(q): Query<ExportQuery>) -> Response {
    let format = q
        .format
        .unwrap_or_else(|| "exr".into())
        .to_ascii_lowercase();
    if !EXPORT_FORMATS.contains(&format.as_str()) {
        return bad(
            StatusCode::BAD_REQUEST,
            format!(
                "format '{format}' is not one of {}",
                EXPORT_FORMATS.join(", ")
            ),
        );
    }
    let what = q.what.unwrap_or_else(|| "map".into());
    let map = {
        let s = app.state.lock().expect("state");
        match &s.view.scene.environment {
            Some(e) => e.map.clone(),
            None => return bad(StatusCode::NOT_FOUND, "no environment is loaded"),
        }
    };
    let (name, work) = match what.as_str() {
        "map" => {
            let projection = q.projection.unwrap_or_else(|| "native".into());
            let shown: String = projection
                .chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() || c == '-' {
                        c
                    } else {
                        '_'
                    }
                })
                .collect();
            let name = format!("environment-{shown}.{format}");
            let host = app.host.clone();
            let work = tokio::task::spawn_blocking(move || {
                let map = if projection == "native" {
                    map
                } else {
                    convert(&app, &map, &projection, q.size)?
                };
                host.export(Export::Map(&map), &format)
                    .map_err(|e| (e.status(), e.message))
            });
            (name, work)
        }
        "chain" => {
            if !matches!(format.as_str(), "ktx2" | "dds") {
                return bad(
                    StatusCode::BAD_REQUEST,
                    format!("format '{format}': a chain is one file only as ktx2 or dds (`mirrorball prefilter` writes the others one file a level)"),
                );
            }
            let lit = app.lit.lock().expect("lit").clone();
            let Some((_, (l, _))) =
                lit.filter(|(k, _)| k.starts_with(&format!("{:p} ", Arc::as_ptr(&map))))
            else {
                return bad(
                    StatusCode::NOT_FOUND,
                    "no prefiltered chain of this environment yet: choose the prefiltered GGX material first",
                );
            };
            let name = format!("ggx-{}-{}.{format}", l.size, l.mapping.name());
            let host = app.host.clone();
            let work = tokio::task::spawn_blocking(move || {
                host.export(Export::Chain(&l.chain), &format)
                    .map_err(|e| (e.status(), e.message))
            });
            (name, work)
        }
        w => {
            return bad(
                StatusCode::BAD_REQUEST,
                format!("what '{w}' is not map or chain"),
            )
        }
    };
    match work.await {
        Ok(Ok(bytes)) => {
            let disposition = format!("attachment; filename=\"{name}\"");
            let mut r = binary(bytes);
            if let Ok(v) = HeaderValue::from_str(&disposition) {
                r.headers_mut().insert(header::CONTENT_DISPOSITION, v);
            }
            r
        }
        Ok(Err((s, m))) => bad(s, m),
        Err(e) => bad(StatusCode::INTERNAL_SERVER_ERROR, e.to_string()),
    }
}

#[derive(Deserialize)]
struct MeshQuery {
    tessellation: Option<u32>,
}

/// Refuses a tessellation of built-in `b` past [`crate::state::MAX_TRIANGLES`].
fn tessellation(b: Builtin, level: u32) -> Result<(), String> {
    let max = b.max_tessellation(crate::state::MAX_TRIANGLES);
    if (1..=max).contains(&level) {
        return Ok(());
    }
    Err(format!(
        "tessellation: {level} is outside 1..={max} for the {} (at most {} triangles)",
        b.name(),
        crate::state::MAX_TRIANGLES
    ))
}

async fn mesh(
    Shared(app): Shared<AppState>,
    UrlPath(i): UrlPath<usize>,
    Query(q): Query<MeshQuery>,
) -> Response {
    let (object, builtin) = {
        let s = app.state.lock().expect("state");
        (
            s.view.scene.objects.get(i).cloned(),
            s.view.builtins.get(i).copied().flatten(),
        )
    };
    let object = match (object, q.tessellation) {
        (Some(mut o), Some(level)) => {
            let Some((b, _)) = builtin else {
                return bad(
                    StatusCode::BAD_REQUEST,
                    format!("tessellation: object {i} is a mesh file, not a built-in"),
                );
            };
            if let Err(m) = tessellation(b, level) {
                return bad(StatusCode::BAD_REQUEST, m);
            }
            o.mesh = Arc::new(b.mesh(level));
            Some(o)
        }
        (o, _) => o,
    };
    match object {
        Some(o) => match tokio::task::spawn_blocking(move || geometry::encode(&o)).await {
            Ok(b) => binary(b),
            Err(e) => bad(StatusCode::INTERNAL_SERVER_ERROR, e.to_string()),
        },
        None => bad(StatusCode::NOT_FOUND, format!("no object {i}")),
    }
}

async fn grid_of(Query(q): Query<HashMap<String, String>>) -> Response {
    let spec = q.get("projection").map_or("latlong", String::as_str);
    let p = match ProjectionSpec::parse(spec).and_then(|s| s.build(None)) {
        Ok(p) => p,
        Err(e) => return bad(StatusCode::BAD_REQUEST, format!("projection: {e}")),
    };
    let n = match q.get("n").map(|n| n.parse::<u32>()) {
        None => 64,
        Some(Ok(n)) if (1..=grid::MAX_N).contains(&n) => n,
        Some(_) => {
            return bad(
                StatusCode::BAD_REQUEST,
                format!("n must be 1..={}", grid::MAX_N),
            )
        }
    };
    match tokio::task::spawn_blocking(move || grid::encode(&p, n)).await {
        Ok(b) => binary(b),
        Err(e) => bad(StatusCode::INTERNAL_SERVER_ERROR, e.to_string()),
    }
}

/// The projection of the map `/api/environment` sends for the same `projection` query.
fn shown_projection(
    app: &App,
    q: &HashMap<String, String>,
) -> Result<mirrorball_core::Projection, (StatusCode, String)> {
    let spec = q.get("projection").map_or("native", String::as_str);
    if spec == "native" {
        let s = app.state.lock().expect("state");
        match &s.view.scene.environment {
            Some(e) if gpu_kind(e.map.projection()).is_some() => Ok(*e.map.projection()),
            Some(_) => Ok(mirrorball_core::ProjectionKind::LatLong.default_projection()),
            None => Err((StatusCode::NOT_FOUND, "no environment is loaded".into())),
        }
    } else {
        ProjectionSpec::parse(spec)
            .and_then(|s| s.build(None))
            .map_err(|e| (StatusCode::BAD_REQUEST, format!("projection: {e}")))
    }
}

async fn analysis_of(
    Shared(app): Shared<AppState>,
    Query(q): Query<HashMap<String, String>>,
) -> Response {
    let p = match shown_projection(&app, &q) {
        Ok(p) => p,
        Err((status, why)) => return bad(status, why),
    };
    let camera = match crate::analysis::Camera::from_query(&q) {
        Ok(c) => c,
        Err(e) => return bad(e.status(), e.message),
    };
    let size = match crate::analysis::size_of(&p, q.get("size").map(String::as_str)) {
        Ok(n) => n,
        Err(e) => return bad(e.status(), e.message),
    };
    match tokio::task::spawn_blocking(move || crate::analysis::encode(&p, size, &camera)).await {
        Ok(j) => Json(j).into_response(),
        Err(e) => bad(StatusCode::INTERNAL_SERVER_ERROR, e.to_string()),
    }
}

async fn directions_of(
    Shared(app): Shared<AppState>,
    Query(q): Query<HashMap<String, String>>,
    body: Result<Bytes, BytesRejection>,
) -> Response {
    let body = match body {
        Ok(b) => b,
        Err(e) => return bad(e.status(), e.body_text()),
    };
    let p = match shown_projection(&app, &q) {
        // Without a shader (the dual fisheye) the page is sent the lat-long conversion.
        Ok(p) if gpu_kind(&p).is_none() => {
            mirrorball_core::ProjectionKind::LatLong.default_projection()
        }
        Ok(p) => p,
        Err((status, why)) => return bad(status, why),
    };
    match tokio::task::spawn_blocking(move || grid::directions(&p, &body)).await {
        Ok(Ok(b)) => binary(b),
        Ok(Err(e)) => bad(e.status(), e.message),
        Err(e) => bad(StatusCode::INTERNAL_SERVER_ERROR, e.to_string()),
    }
}

async fn upload(
    Shared(app): Shared<AppState>,
    Query(q): Query<HashMap<String, String>>,
    body: Result<Bytes, BytesRejection>,
) -> Response {
    let Some(name) = q.get("name").cloned() else {
        return bad(StatusCode::BAD_REQUEST, "an upload needs ?name=FILE");
    };
    let body = match body {
        Ok(b) => b,
        Err(e) => {
            let message = if e.status() == StatusCode::PAYLOAD_TOO_LARGE {
                format!(
                    "{name}: larger than the upload limit of {} MiB (mirrorball studio --max-upload)",
                    app.options.upload_limit >> 20
                )
            } else {
                format!("{name}: the upload did not arrive whole: {e}")
            };
            app.state.lock().expect("state").error(message.clone());
            return bad(e.status(), message);
        }
    };
    if q.get("alongside").is_some_and(|a| a == "1") {
        let mut held = app.held.lock().expect("held");
        held.retain(|(n, _)| *n != name);
        let total: usize = held.iter().map(|(_, b)| b.len()).sum::<usize>() + body.len();
        if total > app.options.upload_limit {
            held.clear();
            let message = format!(
                "{name}: the files picked together are larger than the upload limit of {} MiB (mirrorball studio --max-upload)",
                app.options.upload_limit >> 20
            );
            app.state.lock().expect("state").error(message.clone());
            return bad(StatusCode::PAYLOAD_TOO_LARGE, message);
        }
        held.push((name, body.to_vec()));
        let names: Vec<&str> = held.iter().map(|(n, _)| n.as_str()).collect();
        return Json(serde_json::json!({ "held": names })).into_response();
    }
    let alongside = std::mem::take(&mut *app.held.lock().expect("held"));
    let host = app.host.clone();
    let read = tokio::task::spawn_blocking(move || {
        let opened = host.upload(&name, &body, &alongside);
        (name, opened)
    })
    .await;
    let mut s = app.state.lock().expect("state");
    match read {
        Ok((_, Ok(opened))) => {
            s.apply(opened);
            Json(s.describe()).into_response()
        }
        Ok((_, Err(e))) => {
            s.error(e.message.clone());
            bad(e.status(), e.message)
        }
        Err(e) => bad(StatusCode::INTERNAL_SERVER_ERROR, e.to_string()),
    }
}

#[derive(Deserialize)]
struct ObjectQuery {
    name: Option<String>,
    tessellation: Option<u32>,
}

async fn object(Shared(app): Shared<AppState>, Query(q): Query<ObjectQuery>) -> Response {
    let Some(name) = q.name else {
        return bad(
            StatusCode::BAD_REQUEST,
            "object: give ?name=scene, a built-in or a bundled mesh",
        );
    };
    let bundled = app.host.bundled_meshes();
    let opened = app.state.lock().expect("state").opened_object() == Some(name.as_str());
    let choice = if name == "scene" {
        ObjectChoice::Scene
    } else if opened {
        ObjectChoice::Opened
    } else if let Some(b) = Builtin::from_name(&name) {
        let max = b.max_tessellation(crate::state::MAX_TRIANGLES);
        let level = q
            .tessellation
            .unwrap_or_else(|| b.default_tessellation().min(max));
        if let Err(m) = tessellation(b, level) {
            return bad(StatusCode::BAD_REQUEST, m);
        }
        ObjectChoice::Builtin(b, level)
    } else if bundled.contains(&name.as_str()) {
        let host = app.host.clone();
        let read = tokio::task::spawn_blocking(move || {
            let mesh = host.bundled_mesh(&name);
            (name, mesh)
        })
        .await;
        match read {
            Ok((name, Ok(mesh))) => ObjectChoice::Mesh {
                name,
                mesh: std::sync::Arc::new(mesh),
            },
            Ok((_, Err(e))) => return bad(e.status(), e.message),
            Err(e) => return bad(StatusCode::INTERNAL_SERVER_ERROR, e.to_string()),
        }
    } else {
        let s = app.state.lock().expect("state");
        let known = s.object_choices().join(", ");
        return bad(
            StatusCode::BAD_REQUEST,
            format!("object: unknown '{name}' (known: {known})"),
        );
    };
    let mut s = app.state.lock().expect("state");
    s.show_object(choice);
    Json(s.describe()).into_response()
}

/// Opens `url` in the desktop's browser (`xdg-open`, `open`, `start`); failing to is not an
/// error (the URL is printed).
pub fn open_browser(url: &str) {
    let mut cmd = if cfg!(target_os = "macos") {
        std::process::Command::new("open")
    } else if cfg!(windows) {
        let mut c = std::process::Command::new("cmd");
        c.args(["/C", "start", ""]);
        c
    } else {
        std::process::Command::new("xdg-open")
    };
    let _ = cmd
        .arg(url)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn();
}
