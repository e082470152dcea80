//! The page's files, embedded in the binary: no build step, no network.

use axum::http::header;
use axum::response::{IntoResponse, Response};

/// `(name, content type, contents)` of files under `web/`, by their names there.
macro_rules! files {
    ($($name:literal: $kind:literal),* $(,)?) => {
        &[$(($name, $kind, include_str!(concat!("../web/", $name)))),*]
    };
}

const HTML: &str = "text/html; charset=utf-8";
const JS: &str = "text/javascript; charset=utf-8";
const GLSL: &str = "text/plain; charset=utf-8";

/// Every file the page loads.
const FILES: &[(&str, &str, &str)] = files![
    "index.html": "html",
    "studio.js": "js",
    "gl.js": "js",
    "sim.js": "js",
    "analysis.js": "js",
    "glsl/math.glsl": "glsl",
    "panels.js": "js",
    "glsl/latlong.glsl": "glsl",
    "glsl/cubeface.glsl": "glsl",
    "glsl/cube.glsl": "glsl",
    "glsl/continuous_cube.glsl": "glsl",
    "glsl/eac.glsl": "glsl",
    "glsl/mercator.glsl": "glsl",
    "glsl/radial.glsl": "glsl",
    "glsl/lens.glsl": "glsl",
    "glsl/sphere.glsl": "glsl",
    "glsl/paraboloid.glsl": "glsl",
    "glsl/fisheye.glsl": "glsl",
    "glsl/octahedral.glsl": "glsl",
    "glsl/equal_area_octahedral.glsl": "glsl",
    "glsl/cylinder.glsl": "glsl",
    "glsl/hammer.glsl": "glsl",
    "glsl/sinusoidal.glsl": "glsl",
    "glsl/view.glsl": "glsl",
    "glsl/bilinear.glsl": "glsl",
    "glsl/lighting.glsl": "glsl",
    "glsl/display.glsl": "glsl",
    "glsl/interpolate.glsl": "glsl",
    "glsl/cone.glsl": "glsl",
    "glsl/paraboloid_hw.glsl": "glsl",
    "glsl/texgen.glsl": "glsl",
    "glsl/viewport.vert": "glsl",
    "glsl/viewport.frag": "glsl",
    "glsl/sim-record.glsl": "glsl",
    "glsl/sim-surface.frag": "glsl",
    "glsl/sim-map.frag": "glsl",
    "greene.js": "js",
    "glsl/greene-background.frag": "glsl",
    "glsl/greene-object.vert": "glsl",
    "glsl/greene-object.frag": "glsl",
    "glsl/greene-mirror.frag": "glsl",
    "glsl/greene-fisheye-inverse.glsl": "glsl",
    "glsl/greene-omnimax.frag": "glsl",
];

/// The embedded file `name`: its content type and contents.
pub(crate) fn get(name: &str) -> Option<(&'static str, &'static str)> {
    let (_, kind, contents) = FILES.iter().find(|(n, _, _)| *n == name)?;
    let content_type = match *kind {
        "html" => HTML,
        "js" => JS,
        _ => GLSL,
    };
    Some((content_type, contents))
}

/// The file as a response.
pub(crate) fn respond((content_type, contents): (&'static str, &'static str)) -> Response {
    ([(header::CONTENT_TYPE, content_type)], contents).into_response()
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_file_under_web_is_embedded() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("web");
        let mut on_disk = Vec::new();
        for dir in [root.clone(), root.join("glsl")] {
            for e in std::fs::read_dir(&dir).unwrap() {
                let p = e.unwrap().path();
                if p.is_file() {
                    on_disk.push(
                        p.strip_prefix(&root)
                            .unwrap()
                            .to_string_lossy()
                            .replace('\\', "/"),
                    );
                }
            }
        }
        for f in on_disk {
            assert!(super::get(&f).is_some(), "web/{f} is not embedded");
        }
    }
}
