//! A port of OpenEXR's `src/lib/OpenEXR/ImfEnvmap.cpp`, written here as the reference for
//! OpenEXR's environment-map conventions: the *forward* functions
//! `LatLongMap::direction(dataWindow, pixelPosition)` and `CubeMap::direction(face,
//! dataWindow, positionInFace)` with `CubeMap::pixelPosition` (mirrorball's reader uses the
//! inverse ones), and a writer of files tagged as OpenEXR's tools tag them. Shared by the io
//! and cli test binaries (through `#[path]`).
#![allow(dead_code)]

use mirrorball_core::glam::{DVec2, DVec3};
use mirrorball_core::Image;
use std::f64::consts::PI;
use std::path::Path;

/// `LatLongMap::direction(dataWindow, pixelPosition)` for a data window `(0, 0)–(w−1, h−1)`.
pub fn imf_latlong_direction(w: u32, h: u32, x: f64, y: f64) -> DVec3 {
    let latitude = if h > 1 {
        -PI * (y / (h as f64 - 1.0) - 0.5)
    } else {
        0.0
    };
    let longitude = if w > 1 {
        -2.0 * PI * (x / (w as f64 - 1.0) - 0.5)
    } else {
        0.0
    };
    DVec3::new(
        longitude.sin() * latitude.cos(),
        latitude.sin(),
        longitude.cos() * latitude.cos(),
    )
}

/// `CubeMap::direction(face, dataWindow, positionInFace)` for faces of edge `s`.
pub fn imf_cube_direction(face: usize, s: u32, pif: DVec2) -> DVec3 {
    let pos = if s > 1 {
        DVec2::new(
            pif.x / (s as f64 - 1.0) * 2.0 - 1.0,
            pif.y / (s as f64 - 1.0) * 2.0 - 1.0,
        )
    } else {
        DVec2::ZERO
    };
    match face {
        0 => DVec3::new(1.0, pos.x, pos.y),
        1 => DVec3::new(-1.0, pos.x, pos.y),
        2 => DVec3::new(pos.x, 1.0, pos.y),
        3 => DVec3::new(pos.x, -1.0, pos.y),
        4 => DVec3::new(pos.x, pos.y, 1.0),
        _ => DVec3::new(pos.x, pos.y, -1.0),
    }
}

/// `CubeMap::pixelPosition(face, dataWindow, positionInFace)` (`dataWindowForFace`: x from
/// 0, y from `face·s`).
pub fn imf_cube_pixel_position(face: usize, s: u32, pif: DVec2) -> DVec2 {
    let (min_x, max_x) = (0.0, s as f64 - 1.0);
    let min_y = face as f64 * s as f64;
    let max_y = min_y + s as f64 - 1.0;
    match face {
        0 => DVec2::new(min_x + pif.y, max_y - pif.x),
        1 => DVec2::new(max_x - pif.y, max_y - pif.x),
        2 => DVec2::new(min_x + pif.x, max_y - pif.y),
        3 => DVec2::new(min_x + pif.x, min_y + pif.y),
        4 => DVec2::new(max_x - pif.x, max_y - pif.y),
        _ => DVec2::new(min_x + pif.x, max_y - pif.y),
    }
}

/// Writes `img` as an OpenEXR file tagged as OpenEXR's tools tag environment maps.
pub fn write_tagged(path: &Path, img: &Image, envmap: exr::meta::attribute::EnvironmentMap) {
    use exr::prelude::*;
    let attributes = LayerAttributes {
        environment_map: Some(envmap),
        ..LayerAttributes::default()
    };
    let w = img.width() as usize;
    let data = img.data().to_vec();
    let channels = SpecificChannels::rgb(move |p: Vec2<usize>| {
        let i = (p.y() * w + p.x()) * 3;
        (data[i], data[i + 1], data[i + 2])
    });
    let size = (img.width() as usize, img.height() as usize);
    let layer = Layer::new(size, attributes, Encoding::SMALL_LOSSLESS, channels);
    exr::image::Image::from_layer(layer)
        .write()
        .to_file(path)
        .unwrap();
}
