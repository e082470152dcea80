//! Files in memory: `read_bytes` and `write_bytes` against the path forms (one decoder and
//! one encoder per format, so the same pictures and the same bytes), and hostile buffers.

use crate::hostile::corpus;
use mirrorball_core::Image;
use mirrorball_core::{Layout, ProjectionKind, Stereo};
use mirrorball_io::{
    read, read_bytes, write_bytes, write_cube, write_image, ExrCompression, Fault, Format, Hint,
    Limits, Loaded, MapInfo, Precision, WriteOptions,
};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Every seed of the corpus, one folder a format.
fn seeds() -> Vec<PathBuf> {
    let mut out = Vec::new();
    for dir in std::fs::read_dir(corpus()).unwrap() {
        for f in std::fs::read_dir(dir.unwrap().path()).unwrap() {
            let p = f.unwrap().path();
            if p.is_file() {
                out.push(p);
            }
        }
    }
    out.sort();
    assert!(out.len() >= 15, "{out:?}");
    out
}

fn assert_same(a: &Loaded, b: &Loaded, what: &str) {
    assert_eq!(a.format, b.format, "{what}");
    assert_eq!(a.description, b.description, "{what}");
    assert_eq!(a.declared, b.declared, "{what}");
    assert_eq!(a.recorded, b.recorded, "{what}");
    assert_eq!(a.invalid(), b.invalid(), "{what}");
    assert_eq!(a.layers.len(), b.layers.len(), "{what}");
    for (x, y) in a.layers.iter().zip(&b.layers) {
        assert_eq!(
            (x.width(), x.height(), x.channels()),
            (y.width(), y.height(), y.channels())
        );
        let same = x
            .data()
            .iter()
            .zip(y.data())
            .all(|(p, q)| p.to_bits() == q.to_bits());
        assert!(same, "{what}: texels differ");
    }
}

#[test]
fn every_seed_reads_the_same_from_bytes_as_from_its_file() {
    let limits = Limits::default();
    for path in seeds() {
        let bytes = std::fs::read(&path).unwrap();
        let name = path.file_name().unwrap().to_str().unwrap();
        let from_file = read(&path, &limits).unwrap();
        for hint in [
            Hint::Name(name),
            Hint::Content,
            Hint::Format(from_file.format),
        ] {
            let from_bytes = read_bytes(&bytes, hint, &limits)
                .unwrap_or_else(|e| panic!("{}: {hint:?}: {e}", path.display()));
            assert_same(
                &from_file,
                &from_bytes,
                &format!("{} {hint:?}", path.display()),
            );
        }
    }
}

/// A picture with some texels above 1 and a record of its projection.
fn picture(channels: usize) -> Image {
    let mut img = Image::new(16, 8, channels);
    for (i, v) in img.data_mut().iter_mut().enumerate() {
        *v = ((i * 37) % 101) as f32 / 25.0;
    }
    img
}

fn declared() -> Option<MapInfo> {
    Some(MapInfo {
        projection: ProjectionKind::LatLong.default_projection(),
        layout: None,
        stereo: Stereo::Mono,
    })
}

#[test]
fn bytes_written_are_the_files_written_and_read_back_the_same() {
    let dir = tempfile::tempdir().unwrap();
    let limits = Limits::default();
    let flat = [
        ("zip.exr", None, ExrCompression::Zip, 3),
        ("none.exr", Some(Precision::Float), ExrCompression::None, 4),
        ("piz.exr", None, ExrCompression::Piz, 3),
        ("a.hdr", None, ExrCompression::Zip, 3),
        ("a.png", None, ExrCompression::Zip, 4),
        ("b.png", Some(Precision::U16), ExrCompression::Zip, 3),
        ("a.jpg", None, ExrCompression::Zip, 3),
    ];
    for (name, precision, exr_compression, channels) in flat {
        let opts = WriteOptions {
            precision,
            exr_compression,
            declared: declared(),
            ..WriteOptions::default()
        };
        let img = picture(channels);
        let path = dir.path().join(name);
        write_image(&path, &img, &opts).unwrap();
        let bytes = write_bytes(&[vec![img]], Hint::Name(name), &opts).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), bytes, "{name}");
        let back = read_bytes(&bytes, Hint::Content, &limits).unwrap();
        assert_same(&read(&path, &limits).unwrap(), &back, name);
        // And again, bytes → map → bytes → map, where the coding loses nothing more the
        // second time (JPEG's does).
        if name.ends_with(".jpg") {
            continue;
        }
        let again = write_bytes(&[back.layers], Hint::Name(name), &opts).unwrap();
        let back2 = read_bytes(&again, Hint::Name(name), &limits).unwrap();
        assert_same(&read(&path, &limits).unwrap(), &back2, name);
    }
    let levels: Vec<Vec<Image>> = [8u32, 4, 2, 1]
        .iter()
        .map(|&n| {
            (0..6)
                .map(|f| {
                    let mut img = Image::new(n, n, 3);
                    img.data_mut().iter_mut().enumerate().for_each(|(i, v)| {
                        *v = (i + f) as f32 / 7.0;
                    });
                    img
                })
                .collect()
        })
        .collect();
    for (name, format) in [("c.ktx2", Format::Ktx2), ("c.dds", Format::Dds)] {
        let opts = WriteOptions {
            declared: Some(MapInfo {
                projection: ProjectionKind::Cube.default_projection(),
                layout: Some(Layout::Separate),
                stereo: Stereo::Mono,
            }),
            ..WriteOptions::default()
        };
        let path = dir.path().join(name);
        write_cube(&path, &levels, &opts).unwrap();
        let bytes = write_bytes(&levels, Hint::Format(format), &opts).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), bytes, "{name}");
        let back = read_bytes(&bytes, Hint::Content, &limits).unwrap();
        assert_same(&read(&path, &limits).unwrap(), &back, name);
        assert_eq!(back.layers.len(), 6);
    }
    // One picture a flat file; the content names no format to write.
    let two = vec![vec![picture(3), picture(3)]];
    let e = write_bytes(&two, Hint::Format(Format::Png), &WriteOptions::default()).unwrap_err();
    assert_eq!(e.fault(), Fault::Request, "{e}");
    let e = write_bytes(&two, Hint::Content, &WriteOptions::default()).unwrap_err();
    assert_eq!(e.fault(), Fault::Request, "{e}");
    let e = write_bytes(
        &[vec![picture(3)]],
        Hint::Format(Format::Webp),
        &WriteOptions::default(),
    )
    .unwrap_err();
    assert_eq!(e.fault(), Fault::Request, "{e}");
}

#[test]
fn empty_truncated_and_garbage_buffers_are_input_faults_naming_the_format() {
    let limits = Limits::default();
    // Every format but glTF's, which names other files and is refused from bytes.
    let readable = Format::ALL.into_iter().filter(|f| *f != Format::GltfIbl);
    let garbage: Vec<u8> = (0..4096u32)
        .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
        .collect();
    for format in readable {
        for bytes in [&[][..], &garbage[..], &garbage[..7]] {
            let e = read_bytes(bytes, Hint::Format(format), &limits).expect_err("refused");
            assert_eq!(e.fault(), Fault::Input, "{format:?}: {e}");
            assert!(e.to_string().contains(format.name()), "{format:?}: {e}");
        }
    }
    // Every seed cut short: refused as the input's fault (or, where the cut leaves a whole
    // picture, read), never a panic.
    for path in seeds() {
        let bytes = std::fs::read(&path).unwrap();
        let format = Format::from_path(&path).unwrap();
        for cut in [bytes.len() / 2, bytes.len() - 1, 16, 3] {
            if let Err(e) = read_bytes(&bytes[..cut], Hint::Format(format), &limits) {
                assert_eq!(
                    e.fault(),
                    Fault::Input,
                    "{} cut at {cut}: {e}",
                    path.display()
                );
                assert!(e.to_string().contains(format.name()), "{e}");
            }
        }
    }
    // Content that is no known signature.
    let e = read_bytes(b"hello, world", Hint::Content, &limits).unwrap_err();
    assert_eq!(e.fault(), Fault::Input, "{e}");
    // A glTF light names other files.
    let e = read_bytes(b"{}", Hint::Name("light.gltf"), &limits).unwrap_err();
    assert_eq!(e.fault(), Fault::Request, "{e}");
}

#[test]
fn an_absurd_declared_size_is_refused_before_allocating() {
    let limits = Limits::default();
    // A PNG seed whose IHDR says 16384×16384 (within the limits), CRC fixed: the bytes'
    // length bounds it, as a file's does.
    let mut png = std::fs::read(corpus().join("png/rgb8.png")).unwrap();
    png[16..20].copy_from_slice(&16384u32.to_be_bytes());
    png[20..24].copy_from_slice(&16384u32.to_be_bytes());
    let crc = crate::hostile::crc32(&png[12..29]);
    png[29..33].copy_from_slice(&crc.to_be_bytes());
    let start = Instant::now();
    let e = read_bytes(&png, Hint::Format(Format::Png), &limits).unwrap_err();
    assert!(start.elapsed() < Duration::from_millis(500));
    assert_eq!(e.fault(), Fault::Input);
    assert!(
        e.problem().contains("16384×16384") && e.problem().contains("holds at most"),
        "{e}"
    );
    // Beyond the limits themselves.
    png[16..20].copy_from_slice(&100_000u32.to_be_bytes());
    let crc = crate::hostile::crc32(&png[12..29]);
    png[29..33].copy_from_slice(&crc.to_be_bytes());
    let e = read_bytes(&png, Hint::Format(Format::Png), &limits).unwrap_err();
    assert_eq!(e.fault(), Fault::Input, "{e}");
    // A Radiance header declaring more scan lines than the bytes hold.
    let hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 60000 +X 16\n\x01\x02\x03\x04";
    let e = read_bytes(hdr, Hint::Content, &limits).unwrap_err();
    assert!(e.problem().contains("60000 scan lines"), "{e}");
    assert!(e.to_string().starts_with("Radiance HDR data"), "{e}");
}

/// A one-channel picture (core's images may be one plane) is
/// refused by every writer, to a file or to bytes, flat or cube: the request's fault, the
/// file named, nothing written, no panic.
#[test]
fn one_channel_pictures_are_refused_by_every_writer() {
    let dir = tempfile::tempdir().unwrap();
    {
        let c = 1;
        for name in ["a.exr", "a.hdr", "a.png", "a.jpg"] {
            let path = dir.path().join(name);
            let e = write_image(&path, &picture(c), &WriteOptions::default()).unwrap_err();
            assert_eq!(e.fault(), mirrorball_core::Fault::Request, "{name}");
            assert!(
                e.to_string().contains(name) && e.to_string().contains("channel"),
                "{e}"
            );
            assert!(!path.exists(), "{name}");
            assert!(write_bytes(
                &[vec![picture(c)]],
                Hint::Name(name),
                &WriteOptions::default()
            )
            .is_err());
        }
        for name in ["a.ktx2", "a.dds"] {
            let faces: Vec<Image> = (0..6).map(|_| Image::new(4, 4, c)).collect();
            let e = write_bytes(&[faces], Hint::Name(name), &WriteOptions::default()).unwrap_err();
            assert_eq!(e.fault(), mirrorball_core::Fault::Request, "{name}");
        }
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}
