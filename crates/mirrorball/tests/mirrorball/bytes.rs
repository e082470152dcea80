//! `load::from_bytes` and `save::to_bytes` against `load` and `save`: the same file's
//! bytes, and the same map with the same projection and layout decided.

use mirrorball::core::{EnvMap, Image, Layout, ProjectionKind, WorldProjection};
use mirrorball::io::{Limits, WriteOptions};
use mirrorball::{load, save, Fault, SaveOptions};

fn map(kind: ProjectionKind, w: u32, h: u32) -> EnvMap {
    let p = kind.default_projection();
    let layers = (0..p.layer_count())
        .map(|l| {
            let mut img = Image::new(w, h, 3);
            img.data_mut().iter_mut().enumerate().for_each(|(i, v)| {
                *v = ((i * 13 + l * 7) % 50) as f32 / 20.0;
            });
            img
        })
        .collect();
    EnvMap::new(p, layers).unwrap()
}

fn opts(layout: Option<Layout>) -> SaveOptions {
    SaveOptions {
        layout,
        write: WriteOptions::default(),
        mips: false,
        keep_invalid: false,
    }
}

fn assert_same(a: &load::Source, b: &load::Source, what: &str) {
    assert_eq!(a.env.projection(), b.env.projection(), "{what}");
    assert_eq!(a.description, b.description, "{what}");
    assert_eq!(a.decided, b.decided, "{what}");
    assert_eq!(a.env.layers().len(), b.env.layers().len(), "{what}");
    for (x, y) in a.env.layers().iter().zip(b.env.layers()) {
        assert_eq!(x.data(), y.data(), "{what}");
    }
}

#[test]
fn bytes_are_the_file_and_read_back_as_the_file_does() {
    let dir = tempfile::tempdir().unwrap();
    let limits = Limits::default();
    let cases = [
        ("latlong.exr", map(ProjectionKind::LatLong, 32, 16), None),
        ("latlong.hdr", map(ProjectionKind::LatLong, 32, 16), None),
        ("latlong.png", map(ProjectionKind::LatLong, 32, 16), None),
        ("latlong.jpg", map(ProjectionKind::LatLong, 32, 16), None),
        (
            "cross.exr",
            map(ProjectionKind::Cube, 8, 8),
            Some(Layout::HorizontalCross),
        ),
        (
            "strip.png",
            map(ProjectionKind::Cube, 8, 8),
            Some(Layout::HorizontalStrip),
        ),
        ("cube.ktx2", map(ProjectionKind::Cube, 8, 8), None),
        ("cube.dds", map(ProjectionKind::Cube, 8, 8), None),
    ];
    for (name, env, layout) in cases {
        let out = dir.path().join(name);
        let out = out.to_str().unwrap();
        save(&env, out, &opts(layout)).unwrap();
        let (bytes, _) = save::to_bytes(&env, name, &opts(layout)).unwrap();
        assert_eq!(std::fs::read(out).unwrap(), bytes, "{name}");
        let from_file = load(out, None, None, &limits).unwrap();
        // Named as uploaded, and by its content alone (no extension).
        for upload in [name.to_string(), "upload".to_string()] {
            let from_bytes = load::from_bytes(&upload, &bytes, None, None, &limits).unwrap();
            assert_same(&from_file, &from_bytes, &upload);
        }
        // bytes → map → bytes → map, where the coding loses nothing the second time.
        if !name.ends_with(".jpg") {
            let back = load::from_bytes(name, &bytes, None, None, &limits).unwrap();
            let (again, _) = save::to_bytes(&back.env, name, &opts(layout)).unwrap();
            let twice = load::from_bytes(name, &again, None, None, &limits).unwrap();
            assert_same(&from_file, &twice, name);
        }
    }
}

#[test]
fn bad_bytes_and_impossible_requests_say_whose_fault() {
    let limits = Limits::default();
    let e = load::from_bytes("sky.exr", &[], None, None, &limits)
        .err()
        .unwrap();
    assert_eq!(e.fault, Fault::Input, "{e}");
    let e = load::from_bytes("sky.exr", b"v/1\x01 and then nothing", None, None, &limits)
        .err()
        .unwrap();
    assert_eq!(e.fault, Fault::Input, "{e}");
    let e = load::from_bytes("notes.txt", b"hello", None, None, &limits)
        .err()
        .unwrap();
    assert_eq!(e.fault, Fault::Request, "{e}");
    let env = map(ProjectionKind::Cube, 8, 8);
    let e = save::to_bytes(&env, "faces_{face}.png", &opts(None))
        .err()
        .unwrap();
    assert_eq!(e.fault, Fault::Request, "{e}");
    let e = save::to_bytes(&map(ProjectionKind::LatLong, 8, 4), "sky.ktx2", &opts(None))
        .err()
        .unwrap();
    assert_eq!(e.fault, Fault::Request, "{e}");
}
