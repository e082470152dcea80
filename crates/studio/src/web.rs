//! The page's files, embedded in the binary: no build step, no network.

use axum::http::header;
use axum::response::{IntoResponse, Response};

const HTML: &str = "text/html; charset=utf-8";
const JS: &str = "text/javascript; charset=utf-8";
const GLSL: &str = "text/plain; charset=utf-8";

/// Every file under `web/`, `(path there, contents)` (build.rs lists the folder).
const FILES: &[(&str, &str)] = include!(concat!(env!("OUT_DIR"), "/web_files.rs"));

/// The embedded file `name`: its content type and contents.
pub(crate) fn get(name: &str) -> Option<(&'static str, &'static str)> {
    let (_, contents) = FILES.iter().find(|(n, _)| *n == name)?;
    let content_type = match name.rsplit('.').next() {
        Some("html") => HTML,
        Some("js") => JS,
        _ => GLSL,
    };
    Some((content_type, contents))
}

/// The file as a response.
pub(crate) fn respond((content_type, contents): (&'static str, &'static str)) -> Response {
    ([(header::CONTENT_TYPE, content_type)], contents).into_response()
}

/// The viewport's shader of projection kind `name` (the core's name), if it has one.
pub(crate) fn projection_shader(name: &str) -> Option<&'static str> {
    get(&format!("glsl/projections/{name}.glsl")).map(|(_, c)| c)
}

#[cfg(test)]
mod tests {
    use super::FILES;
    use mirrorball_core::ProjectionKind;

    #[test]
    fn every_projection_shader_is_a_kinds_and_every_need_is_a_file() {
        let mut shaders = 0;
        for (name, contents) in FILES {
            if let Some(kind) = name
                .strip_prefix("glsl/projections/")
                .and_then(|n| n.strip_suffix(".glsl"))
            {
                shaders += 1;
                assert!(
                    ProjectionKind::ALL.iter().any(|k| k.name() == kind),
                    "web/{name} names no projection of the core's table"
                );
            }
            if name.ends_with(".glsl") {
                for line in contents.lines() {
                    let Some(needs) = line.strip_prefix("// needs:") else {
                        continue;
                    };
                    for need in needs.split_whitespace() {
                        assert!(
                            super::get(&format!("glsl/{need}.glsl")).is_some(),
                            "web/{name} needs {need}.glsl, which is not under web/glsl"
                        );
                    }
                }
            }
        }
        assert!(shaders >= 19, "{shaders} projection shaders embedded");
    }
}
