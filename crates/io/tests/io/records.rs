//! What files record about their map: the projection and layout written into EXR
//! attributes, Radiance header lines, PNG text chunks, a JPEG comment and KTX2 key/value
//! data, and read back.

use mirrorball_core::glam::DVec3;
use mirrorball_core::projection::ProjectionSpec;
use mirrorball_core::{Fisheye, Frame, Image, Layout, Lens, Projection, ProjectionKind};
use mirrorball_io::{read, write_cube, write_image, MapInfo, WriteOptions, LAYOUT_KEY};
use std::path::Path;

fn declared(info: MapInfo) -> WriteOptions {
    WriteOptions {
        declared: Some(info),
        ..WriteOptions::default()
    }
}

fn picture(w: u32, h: u32) -> Image {
    let mut img = Image::new(w, h, 3);
    for y in 0..h {
        for x in 0..w {
            img.set(x, y, &[x as f32 / w as f32, y as f32 / h as f32, 0.5]);
        }
    }
    img
}

#[test]
fn every_flat_container_with_text_gives_back_what_it_recorded() {
    let dir = tempfile::tempdir().unwrap();
    let fisheye: Projection = Fisheye::new(
        Frame::looking_along(DVec3::new(0.0, 1.0, 0.0)).unwrap(),
        Lens::Equisolid,
        190.0,
    )
    .unwrap()
    .into();
    let paraboloid = ProjectionKind::Paraboloid.default_projection();
    for (info, (w, h)) in [
        (
            MapInfo {
                projection: fisheye,
                layout: None,
                stereo: Default::default(),
            },
            (16, 16),
        ),
        (
            MapInfo {
                projection: paraboloid,
                layout: Some(Layout::VerticalStrip),
                stereo: Default::default(),
            },
            (8, 16),
        ),
    ] {
        for ext in ["exr", "hdr", "png", "jpg"] {
            let path = dir
                .path()
                .join(format!("m-{}.{ext}", info.projection.name()));
            write_image(&path, &picture(w, h), &declared(info)).unwrap();
            let loaded = read(&path, &Default::default()).unwrap();
            let back = loaded
                .recorded
                .unwrap_or_else(|| panic!("{ext}: nothing recorded"))
                .unwrap();
            assert_eq!(
                back.projection.to_string(),
                info.projection.to_string(),
                "{ext}"
            );
            assert_eq!(back.layout, info.layout, "{ext}");
            // The texels are untouched by the text around them.
            assert_eq!(loaded.layers[0].width(), w, "{ext}");
            let want = picture(w, h);
            let (a, b) = (loaded.layers[0].get(w - 1, h - 1), want.get(w - 1, h - 1));
            let tolerance = if ext == "jpg" { 0.05 } else { 0.01 };
            assert!((a[0] - b[0]).abs() < tolerance, "{ext}: {a:?} vs {b:?}");
            if ext == "jpg" {
                // The comment goes after JFIF's APP0, which must follow SOI directly.
                let bytes = std::fs::read(&path).unwrap();
                assert_eq!(bytes[..4], [0xFF, 0xD8, 0xFF, 0xE0]);
            }
        }
    }
}

#[test]
fn a_ktx2_cube_records_its_projection() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("c.ktx2");
    let faces: Vec<Image> = (0..6).map(|_| picture(4, 4)).collect();
    let info = MapInfo {
        projection: ProjectionKind::Cube.default_projection(),
        layout: None,
        stereo: Default::default(),
    };
    write_cube(&path, &[faces], &declared(info)).unwrap();
    let loaded = read(&path, &Default::default()).unwrap();
    assert_eq!(loaded.declared, Some(ProjectionKind::Cube));
    assert_eq!(loaded.recorded.unwrap().unwrap(), info);
    // The KTX2 key/value data stays in key order (a specification requirement).
    let bytes = std::fs::read(&path).unwrap();
    let at = |key: &str| bytes.windows(key.len()).position(|w| w == key.as_bytes());
    assert!(at("KTXorientation") < at("KTXwriter"));
    assert!(at("KTXwriter") < at("mirrorball:projection"));
}

#[test]
fn files_without_a_record_say_nothing_and_bad_records_say_what_they_hold() {
    let dir = tempfile::tempdir().unwrap();
    for ext in ["exr", "hdr", "png", "jpg"] {
        let path = dir.path().join(format!("plain.{ext}"));
        write_image(&path, &picture(8, 4), &WriteOptions::default()).unwrap();
        assert!(
            read(&path, &Default::default()).unwrap().recorded.is_none(),
            "{ext}"
        );
    }

    // A record this version cannot read: an error quoting it, not a guess.
    let bad = MapInfo::from_texts(Path::new("f.exr"), "banana:fov=3", None, 8, 8).unwrap_err();
    assert_eq!(bad.fault(), mirrorball_io::Fault::Input);
    assert_eq!(bad.path(), Path::new("f.exr"));
    let bad = bad.to_string();
    assert!(
        bad.contains("mirrorball:projection = 'banana:fov=3'"),
        "{bad}"
    );
    let bad = MapInfo::from_texts(Path::new("f.exr"), "cube", Some("diagonal"), 8, 8)
        .unwrap_err()
        .to_string();
    assert!(
        bad.contains(LAYOUT_KEY) && bad.contains("diagonal"),
        "{bad}"
    );
    // A Mercator record without its limit takes it from the picture's shape.
    let m = MapInfo::from_texts(Path::new("f.exr"), "mercator", None, 200, 100).unwrap();
    let want = ProjectionSpec::parse("mercator")
        .unwrap()
        .build(Some((200, 100)))
        .unwrap();
    assert_eq!(m.projection, want);
}

#[test]
fn an_exr_with_projection_and_layout_is_the_same_bytes_every_time() {
    // Two extra attributes in one of the `exr` crate's hash maps would come out in an order
    // that changes from map to map.
    let dir = tempfile::tempdir().unwrap();
    let info = MapInfo {
        projection: ProjectionKind::Cube.default_projection(),
        layout: Some(Layout::HorizontalCross),
        stereo: Default::default(),
    };
    let img = picture(8, 6);
    let first = dir.path().join("c0.exr");
    write_image(&first, &img, &declared(info)).unwrap();
    let want = std::fs::read(&first).unwrap();
    for i in 1..8 {
        let p = dir.path().join(format!("c{i}.exr"));
        write_image(&p, &img, &declared(info)).unwrap();
        assert!(std::fs::read(&p).unwrap() == want, "write {i} differs");
    }
    let back = read(&first, &Default::default())
        .unwrap()
        .recorded
        .unwrap()
        .unwrap();
    assert_eq!(back, info);
}

#[test]
fn a_stereo_pair_is_recorded_with_its_eyes_layout() {
    let dir = tempfile::tempdir().unwrap();
    let mercator = ProjectionKind::Mercator.default_projection();
    let cube = ProjectionKind::Cube.default_projection();
    for (info, (w, h), text) in [
        (
            MapInfo {
                projection: cube,
                layout: Some(Layout::HorizontalStrip),
                stereo: mirrorball_core::Stereo::TopBottom,
            },
            (24, 8),
            "tb/hstrip",
        ),
        (
            MapInfo {
                projection: mercator,
                layout: Some(Layout::Separate),
                stereo: mirrorball_core::Stereo::SideBySide,
            },
            (32, 16),
            "sbs/separate",
        ),
    ] {
        assert_eq!(info.texts().1.as_deref(), Some(text));
        for ext in ["exr", "hdr", "png", "jpg"] {
            let path = dir.path().join(format!("s.{ext}"));
            write_image(&path, &picture(w, h), &declared(info)).unwrap();
            let back = read(&path, &Default::default())
                .unwrap()
                .recorded
                .unwrap()
                .unwrap();
            assert_eq!(back.stereo, info.stereo, "{ext}");
            assert_eq!(back.layout, info.layout, "{ext}");
            assert_eq!(back.projection.to_string(), info.projection.to_string());
        }
    }
    // A pair that cannot halve is an unreadable record, said by name.
    let e = MapInfo::from_texts(Path::new("f.exr"), "latlong", Some("sbs/separate"), 33, 16)
        .unwrap_err()
        .to_string();
    assert!(e.contains(LAYOUT_KEY) && e.contains("even width"), "{e}");
    let e = MapInfo::from_texts(Path::new("f.exr"), "latlong", Some("3d/separate"), 32, 16)
        .unwrap_err()
        .to_string();
    assert!(e.contains("3d/separate"), "{e}");
}
