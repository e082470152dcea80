//! The page's files, embedded in the binary: no build step, no network.

use axum::http::header;
use axum::response::{IntoResponse, Response};

/// `(name, content type, contents)` of every file under `web/`.
const FILES: &[(&str, &str, &str)] = &[
    (
        "index.html",
        "text/html; charset=utf-8",
        include_str!("../web/index.html"),
    ),
    (
        "studio.js",
        "text/javascript; charset=utf-8",
        include_str!("../web/studio.js"),
    ),
    (
        "gl.js",
        "text/javascript; charset=utf-8",
        include_str!("../web/gl.js"),
    ),
    (
        "glsl/latlong.glsl",
        "text/plain; charset=utf-8",
        include_str!("../web/glsl/latlong.glsl"),
    ),
    (
        "glsl/cube.glsl",
        "text/plain; charset=utf-8",
        include_str!("../web/glsl/cube.glsl"),
    ),
    (
        "glsl/radial.glsl",
        "text/plain; charset=utf-8",
        include_str!("../web/glsl/radial.glsl"),
    ),
    (
        "glsl/sphere.glsl",
        "text/plain; charset=utf-8",
        include_str!("../web/glsl/sphere.glsl"),
    ),
    (
        "glsl/paraboloid.glsl",
        "text/plain; charset=utf-8",
        include_str!("../web/glsl/paraboloid.glsl"),
    ),
    (
        "glsl/bilinear.glsl",
        "text/plain; charset=utf-8",
        include_str!("../web/glsl/bilinear.glsl"),
    ),
    (
        "glsl/display.glsl",
        "text/plain; charset=utf-8",
        include_str!("../web/glsl/display.glsl"),
    ),
    (
        "glsl/texgen.glsl",
        "text/plain; charset=utf-8",
        include_str!("../web/glsl/texgen.glsl"),
    ),
    (
        "glsl/viewport.vert",
        "text/plain; charset=utf-8",
        include_str!("../web/glsl/viewport.vert"),
    ),
    (
        "glsl/viewport.frag",
        "text/plain; charset=utf-8",
        include_str!("../web/glsl/viewport.frag"),
    ),
];

/// The embedded file `name`.
pub(crate) fn get(name: &str) -> Option<(&'static str, &'static str)> {
    FILES
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|&(_, t, c)| (t, c))
}

/// The file as a response.
pub(crate) fn respond((content_type, contents): (&'static str, &'static str)) -> Response {
    ([(header::CONTENT_TYPE, content_type)], contents).into_response()
}
