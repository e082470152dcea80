//! OpenEXR's environment maps read into mirrorball's conventions.
//!
//! The reference is a port of OpenEXR's `src/lib/OpenEXR/ImfEnvmap.cpp` written here: the
//! *forward* functions `LatLongMap::direction(dataWindow, pixelPosition)` and
//! `CubeMap::direction(face, dataWindow, positionInFace)` with `CubeMap::pixelPosition`
//! (the reader uses the inverse ones, `latLong(direction)`/`pixelPosition` and
//! `faceAndPixelPosition`). Each pixel of a direction-coded map stores its own direction as
//! OpenEXR defines it; after reading, each mirrorball texel must hold mirrorball's direction
//! for that texel.

use mirrorball_core::glam::{DVec2, DVec3};
use mirrorball_core::{CubeMap, Image, LatLong, ProjectionKind, WorldProjection};
use mirrorball_io::openexr::{cube_to_faces, latlong_to_mirrorball};
use std::f64::consts::PI;
use std::path::Path;

use crate::imf_envmap::{
    imf_cube_direction, imf_cube_pixel_position, imf_latlong_direction, write_tagged,
};

/// An OpenEXR lat-long whose pixels hold their own unit directions.
fn coded_latlong(w: u32, h: u32) -> Image {
    let mut img = Image::new(w, h, 3);
    for y in 0..h {
        for x in 0..w {
            let d = imf_latlong_direction(w, h, x as f64, y as f64).normalize();
            img.set(x, y, &[d.x as f32, d.y as f32, d.z as f32]);
        }
    }
    img
}

/// An OpenEXR cube strip (`s`×`6s`) whose pixels hold their own unit directions.
fn coded_cube(s: u32) -> Image {
    let mut img = Image::new(s, 6 * s, 3);
    let mut filled = 0;
    for face in 0..6 {
        for j in 0..s {
            for i in 0..s {
                let pif = DVec2::new(i as f64, j as f64);
                let d = imf_cube_direction(face, s, pif).normalize();
                let p = imf_cube_pixel_position(face, s, pif);
                img.set(
                    p.x as u32,
                    p.y as u32,
                    &[d.x as f32, d.y as f32, d.z as f32],
                );
                filled += 1;
            }
        }
    }
    assert_eq!(filled, 6 * s * s);
    img
}

/// The angle (radians) between a texel's stored direction and `want`.
fn angle(texel: &[f32], want: DVec3) -> f64 {
    let got = DVec3::new(texel[0] as f64, texel[1] as f64, texel[2] as f64).normalize();
    got.dot(want.normalize()).clamp(-1.0, 1.0).acos()
}

#[test]
fn an_openexr_latlong_reads_with_each_texel_at_its_own_direction() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (64, 32);
    let path = dir.path().join("latlong.exr");
    write_tagged(
        &path,
        &coded_latlong(w, h),
        exr::meta::attribute::EnvironmentMap::LatitudeLongitude,
    );
    let loaded = mirrorball_io::read(&path, &Default::default()).unwrap();
    assert_eq!(loaded.declared, Some(ProjectionKind::LatLong));
    assert!(loaded.recorded.is_none());
    let raw = &loaded.layers[0];
    let ours = latlong_to_mirrorball(raw);
    let texel = PI / h as f64; // a texel's height, radians
    let (mut worst, mut raw_errors) = (0.0f64, Vec::new());
    for y in 0..h {
        for x in 0..w {
            let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
            let want = LatLong.uv_to_dir(0, uv).unwrap();
            worst = worst.max(angle(ours.get(x, y), want));
            raw_errors.push(angle(raw.get(x, y), want));
        }
    }
    // Bilinear between OpenEXR's pixels leaves a small fraction of a texel; a plain
    // half-width column shift would be up to half a texel off (OpenEXR's pixel centres lie
    // on the seam and the poles), and no conversion half a turn.
    assert!(worst < 0.05 * texel, "worst {:.4} texel", worst / texel);
    raw_errors.sort_by(f64::total_cmp);
    assert!(
        raw_errors[raw_errors.len() / 2] > 1.0,
        "the raw picture is OpenEXR's, not ours"
    );
}

#[test]
fn an_openexr_cube_strip_reads_into_opengl_faces() {
    let dir = tempfile::tempdir().unwrap();
    let s = 16;
    let path = dir.path().join("cube.exr");
    write_tagged(
        &path,
        &coded_cube(s),
        exr::meta::attribute::EnvironmentMap::Cube,
    );
    let loaded = mirrorball_io::read(&path, &Default::default()).unwrap();
    assert_eq!(loaded.declared, Some(ProjectionKind::Cube));
    let faces = cube_to_faces(&loaded.layers[0], Path::new("tagged.exr")).unwrap();
    assert_eq!(faces.len(), 6);
    let texel = (2.0 / s as f64).atan(); // a texel at a face's centre, radians
    let mut worst = 0.0f64;
    for (f, face) in faces.iter().enumerate() {
        assert_eq!((face.width(), face.height()), (s, s));
        for y in 0..s {
            for x in 0..s {
                let uv = DVec2::new((x as f64 + 0.5) / s as f64, (y as f64 + 0.5) / s as f64);
                let want = CubeMap.uv_to_dir(f, uv).unwrap();
                worst = worst.max(angle(face.get(x, y), want));
            }
        }
    }
    assert!(worst < 0.05 * texel, "worst {:.4} texel", worst / texel);

    // Read as OpenGL's vertical strip instead, the faces are far off.
    let mut off = Vec::new();
    for f in 0..6 {
        for y in 0..s {
            for x in 0..s {
                let uv = DVec2::new((x as f64 + 0.5) / s as f64, (y as f64 + 0.5) / s as f64);
                let want = CubeMap.uv_to_dir(f, uv).unwrap();
                off.push(angle(loaded.layers[0].get(x, f as u32 * s + y), want));
            }
        }
    }
    off.sort_by(f64::total_cmp);
    assert!(off[off.len() / 2] > 0.3, "median {}", off[off.len() / 2]);
}

#[test]
fn a_tagged_cube_too_short_for_six_faces_is_refused() {
    let e = cube_to_faces(&Image::new(4, 5, 3), Path::new("short.exr")).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("envmap = cube") && text.contains("4x5"),
        "{e}"
    );
    assert!(text.starts_with("short.exr: "), "{e}");
    assert_eq!(e.fault(), mirrorball_io::Fault::Input);
}
