//! Every storage of the range table (`mirrorball_encode::range`) written by every writer
//! that writes it, with a value four times its largest: read back, nothing is infinite or
//! NaN, nothing is past the largest value, and a value inside the range comes back as it
//! went in (to the storage's precision).

use mirrorball_core::{Choice, Image};
use mirrorball_io::{
    read, write_cube, write_dds, write_image, write_ktx1, write_ktx2, CubeWrite, Encoding, Format,
    Limits, Precision, Storage, WriteOptions,
};
use std::path::Path;

/// An 8×8 face of 1.0 whose last 4×4 block is at half of `storage`'s largest value, but
/// for texel (5, 5) at four times it (the largest `f32` for float): a block of its own, so
/// that BC6H's endpoints can span it.
fn sunny(storage: Storage) -> Image {
    let max = storage.range().max;
    let mut img = Image::new(8, 8, 3);
    img.data_mut().fill(1.0);
    for y in 4..8 {
        for x in 4..8 {
            img.set(x, y, &max.map(|m| m / 2.0));
        }
    }
    img.set(
        5,
        5,
        &max.map(|m| if m < f32::MAX / 4.0 { 4.0 * m } else { m }),
    );
    img
}

/// `layers` read back from `path` hold `storage`'s values: finite, within the range, the
/// bright texel at the range's end and the half-bright one as it was (within `tol`).
fn check(path: &Path, storage: Storage, layers: &[Image]) {
    let max = storage.range().max;
    let tol = match storage {
        Storage::Texels(Encoding::Rgba16F | Encoding::Rgba32F) => 1e-3,
        // JPEG's blocks blur the step from 1 to ½.
        Storage::Display8 if path.extension().is_some_and(|e| e == "jpg") => 0.25,
        Storage::Display8 | Storage::Display16 => 0.01,
        _ => 0.05,
    };
    let what = format!("{} ({storage:?})", path.display());
    let back = read(path, &Limits::default()).unwrap().layers;
    assert!(!back.is_empty(), "{what}");
    for img in &back {
        for px in img.data().chunks_exact(img.channels()) {
            for k in 0..3 {
                assert!(px[k].is_finite() && px[k] <= max[k], "{what}: {}", px[k]);
            }
        }
    }
    // Flat files hold the picture as it was written; cube containers its first face.
    let (got, src) = (&back[0], &layers[0]);
    for x in [5, 6] {
        for (k, &m) in max.iter().enumerate() {
            let want = src.get(x, x)[k].min(m);
            let g = got.get(x, x)[k];
            assert!(
                (g - want).abs() <= want * tol,
                "{what}: texel {x}, {g} for {want}"
            );
        }
    }
}

/// The flat formats' writers, each with every precision it takes.
const FLAT: &[(&str, &[Option<Precision>])] = &[
    (
        "exr",
        &[None, Some(Precision::Half), Some(Precision::Float)],
    ),
    ("hdr", &[None]),
    ("png", &[None, Some(Precision::U8), Some(Precision::U16)]),
    ("jpg", &[None, Some(Precision::U8)]),
];

#[test]
fn every_storage_is_written_within_its_range_by_every_writer() {
    let dir = tempfile::tempdir().unwrap();
    let mut seen = Vec::new();
    for (ext, precisions) in FLAT {
        for &precision in *precisions {
            let path = dir.path().join(format!("f{}.{ext}", seen.len()));
            let storage = Format::from_path(&path).unwrap().storage(precision);
            let img = sunny(storage);
            let opts = WriteOptions {
                precision,
                ..Default::default()
            };
            write_image(&path, &img, &opts).unwrap();
            check(&path, storage, &[img]);
            seen.push(storage);
        }
    }
    for &(e, _) in Encoding::NAMES {
        let storage = Storage::Texels(e);
        let face = sunny(storage);
        let levels = vec![vec![face; 6]];
        let how = CubeWrite {
            encoding: e,
            ..Default::default()
        };
        let k2 = dir.path().join(format!("{}.ktx2", e.name()));
        write_ktx2(&k2, &levels, &how).unwrap();
        check(&k2, storage, &levels[0]);
        // DDS has no RGBD/RGBM; KTX1 (Filament's) only B10G11R11 and the floats: their
        // writers refuse the others (tested in `encoded.rs`), and encode as KTX2 does.
        let dds = dir.path().join(format!("{}.dds", e.name()));
        if write_dds(&dds, &levels, &how).is_ok() {
            check(&dds, storage, &levels[0]);
        }
        let _ = write_ktx1(&dir.path().join(format!("{}.ktx", e.name())), &levels, &how);
        seen.push(storage);
    }
    // write_cube's precisions are RGBA16F's and RGBA32F's storage.
    for p in [Precision::Half, Precision::Float] {
        let path = dir.path().join(format!("c{p}.ktx2"));
        let storage = Format::Ktx2.storage(Some(p));
        let levels = vec![vec![sunny(storage); 6]];
        let opts = WriteOptions {
            precision: Some(p),
            ..Default::default()
        };
        write_cube(&path, &levels, &opts).unwrap();
        check(&path, storage, &levels[0]);
    }
    for s in Storage::all() {
        assert!(
            seen.contains(&s),
            "{s:?} is written by no writer tested here"
        );
    }
}
