//! OpenEXR's environment maps (the `envmap` attribute), converted to mirrorball's
//! conventions, following OpenEXR's `ImfEnvmap.cpp` exactly.
//!
//! OpenEXR places its *pixel centres on the edges*: in a lat-long, pixel column 0 and the last
//! column both lie on the seam and rows 0 and `h − 1` on the poles
//! (`LatLongMap::latLong(dataWindow, pixelPosition)` divides by `max − min`, that is `w − 1`
//! and `h − 1`); in a cube face, the first and last pixels lie on the cube's edges
//! (`CubeMap::faceAndPixelPosition` scales by `sizeOfFace − 1`). mirrorball's texel centres
//! sit half a texel in, so no OpenEXR map is a permutation of mirrorball texels: each
//! mirrorball texel is read at its centre direction's OpenEXR pixel position, bilinearly
//! between the four pixels around it (which always lie in the same face, since OpenEXR's
//! positions span each face edge to edge).
//!
//! - **Lat-long** (`LatLongMap::latLong(direction)` and `pixelPosition`): longitude
//!   `atan2(x, z)` runs from +π at the left to −π at the right, so the centre column looks
//!   along +Z, where mirrorball's looks along −Z: the two differ by half a turn about +Y (a
//!   shift of `u` by ½), besides the grids.
//! - **Cube** (`CubeMap::sizeOfFace`, `faceAndPixelPosition`, `pixelPosition`): one vertical
//!   strip, face `f` (+X −X +Y −Y +Z −Z) in rows `f·s … f·s + s − 1` with
//!   `s = min(w, h/6)`, each face turned and mirrored as `pixelPosition` says; read here
//!   into OpenGL's faces of edge `s`.
//!
//! Pixel positions count from the data window's corner, which is where mirrorball's pictures
//! start.

use mirrorball_core::glam::{DVec2, DVec3};
use mirrorball_core::{CubeMap, Image, LatLong, WorldProjection};
use rayon::prelude::*;
use std::f64::consts::PI;

/// `LatLongMap::pixelPosition(dataWindow, latLong(direction))` for a `w`×`h` picture.
fn latlong_pixel(d: DVec3, w: u32, h: u32) -> DVec2 {
    // latLong(direction): the latitude as asin(y/|d|) (ImfEnvmap switches to acos near the
    // poles for precision; the value is the same), the longitude atan2(x, z).
    let len = d.length();
    let latitude = (d.y / len).clamp(-1.0, 1.0).asin();
    let longitude = if d.x == 0.0 && d.z == 0.0 {
        0.0
    } else {
        d.x.atan2(d.z)
    };
    let x = longitude / (-2.0 * PI) + 0.5;
    let y = latitude / -PI + 0.5;
    DVec2::new(x * (w as f64 - 1.0), y * (h as f64 - 1.0))
}

/// The cube face (OpenEXR's and OpenGL's order) and position in the strip of direction `d`:
/// `CubeMap::faceAndPixelPosition` then `CubeMap::pixelPosition`, for faces of edge `s`.
fn cube_pixel(d: DVec3, s: u32) -> (usize, DVec2) {
    let (ax, ay, az) = (d.x.abs(), d.y.abs(), d.z.abs());
    let k = s as f64 - 1.0;
    let (face, pif) = if ax >= ay && ax >= az {
        let pif = DVec2::new((d.y / ax + 1.0) / 2.0 * k, (d.z / ax + 1.0) / 2.0 * k);
        (if d.x > 0.0 { 0 } else { 1 }, pif)
    } else if ay >= az {
        let pif = DVec2::new((d.x / ay + 1.0) / 2.0 * k, (d.z / ay + 1.0) / 2.0 * k);
        (if d.y > 0.0 { 2 } else { 3 }, pif)
    } else {
        let pif = DVec2::new((d.x / az + 1.0) / 2.0 * k, (d.y / az + 1.0) / 2.0 * k);
        (if d.z > 0.0 { 4 } else { 5 }, pif)
    };
    // pixelPosition: the face's window is x in [0, s − 1], y in [f·s, f·s + s − 1].
    let (min_x, max_x) = (0.0, k);
    let (min_y, max_y) = (face as f64 * s as f64, face as f64 * s as f64 + k);
    let pos = match face {
        0 => DVec2::new(min_x + pif.y, max_y - pif.x),
        1 => DVec2::new(max_x - pif.y, max_y - pif.x),
        2 => DVec2::new(min_x + pif.x, max_y - pif.y),
        3 => DVec2::new(min_x + pif.x, min_y + pif.y),
        4 => DVec2::new(max_x - pif.x, max_y - pif.y),
        _ => DVec2::new(min_x + pif.x, max_y - pif.y),
    };
    (face, pos)
}

/// The texel of `image` at pixel position `p` (pixel centres at integers), bilinearly
/// between the four pixels around it, within the columns `0..w` and rows `y0..y1`.
fn bilinear(image: &Image, p: DVec2, y0: u32, y1: u32, out: &mut [f32]) {
    image.bilinear_clamped((p.x, p.y), (y0, y1), out);
}

/// An OpenEXR lat-long (`envmap = latlong`) as mirrorball's lat-long of the same size: each
/// texel read at its centre direction's OpenEXR pixel position.
pub fn latlong_to_mirrorball(image: &Image) -> Image {
    let (w, h, c) = (image.width(), image.height(), image.channels());
    let mut out = Image::new(w, h, c);
    if w == 0 || h == 0 {
        return out;
    }
    out.data_mut()
        .par_chunks_mut(w as usize * c)
        .enumerate()
        .for_each(|(y, row)| {
            let v = (y as f64 + 0.5) / h as f64;
            for (x, texel) in row.chunks_exact_mut(c).enumerate() {
                let uv = DVec2::new((x as f64 + 0.5) / w as f64, v);
                let d = LatLong
                    .uv_to_dir(0, uv)
                    .expect("lat-long covers its square");
                bilinear(image, latlong_pixel(d, w, h), 0, h, texel);
            }
        });
    out
}

/// An OpenEXR cube map (`envmap = cube`: a vertical strip of six faces of edge
/// `s = min(w, h/6)`) as OpenGL's six faces of edge `s`, in OpenGL's order. The picture
/// of the file `path` (which messages name) too short to hold six faces is the input's
/// fault.
pub fn cube_to_faces(image: &Image, path: &std::path::Path) -> Result<Vec<Image>, crate::Error> {
    let (w, h, c) = (image.width(), image.height(), image.channels());
    let s = w.min(h / 6);
    if s == 0 {
        return Err(crate::Error::input(path, format!(
            "is tagged as an OpenEXR cube map (envmap = cube), but a {w}x{h} picture cannot hold its six faces stacked vertically (N by 6N)"
        )));
    }
    Ok((0..6)
        .into_par_iter()
        .map(|face| {
            let mut out = Image::new(s, s, c);
            for (y, row) in out.data_mut().chunks_exact_mut(s as usize * c).enumerate() {
                for (x, texel) in row.chunks_exact_mut(c).enumerate() {
                    let uv = DVec2::new((x as f64 + 0.5) / s as f64, (y as f64 + 0.5) / s as f64);
                    let d = CubeMap
                        .uv_to_dir(face, uv)
                        .expect("a face covers its square");
                    let (f, p) = cube_pixel(d, s);
                    let y0 = f as u32 * s;
                    bilinear(image, p, y0, y0 + s, texel);
                }
            }
            out
        })
        .collect())
}
