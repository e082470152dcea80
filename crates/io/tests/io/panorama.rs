//! 360° photos: a lat-long or VR180 PNG or JPEG carries GPano XMP (PNG `iTXt`
//! `XML:com.adobe.xmp`, JPEG `APP1` after the XMP signature), read back here, by the
//! `image` crate's own XMP readers (png's `iTXt` list, zune-jpeg's `APP1` parser) and, where
//! installed, by ExifTool; other projections and stereo pairs carry none.

use mirrorball_core::{Image, Layout, ProjectionKind, Stereo};
use mirrorball_io::{read, read_xmp, write_image, MapInfo, Precision, WriteOptions};
use mirrorball_spherical::gpano;
use mirrorball_spherical::Crop;
use std::io::BufReader;
use std::path::Path;
use std::process::Command;

fn options(kind: ProjectionKind, stereo: Stereo, precision: Option<Precision>) -> WriteOptions {
    WriteOptions {
        declared: Some(MapInfo {
            projection: kind.default_projection(),
            layout: None,
            stereo,
        }),
        precision,
        ..WriteOptions::default()
    }
}

/// The XMP the `image` crate finds in the file.
fn image_crate_xmp(path: &Path) -> Option<String> {
    use image::ImageDecoder;
    let file = BufReader::new(std::fs::File::open(path).unwrap());
    let reader = image::ImageReader::new(file).with_guessed_format().unwrap();
    let mut decoder = reader.into_decoder().unwrap();
    let xmp = decoder.xmp_metadata().unwrap()?;
    Some(String::from_utf8(xmp).unwrap())
}

/// ExifTool's reading of the GPano properties, if ExifTool is installed.
fn exiftool(path: &Path) -> Option<serde_json::Value> {
    let o = Command::new("exiftool")
        .args(["-j", "-n", "-XMP-GPano:all"])
        .arg(path)
        .output()
        .ok()?;
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    Some(v[0].clone())
}

#[test]
fn lat_long_and_vr180_photos_carry_gpano_read_back_three_ways() {
    let dir = tempfile::tempdir().unwrap();
    let have_exiftool = Command::new("exiftool").arg("-ver").output().is_ok();
    if !have_exiftool {
        eprintln!(
            "\n!!!!!!!! ExifTool is not installed, so GPano XMP was NOT checked with it \
             (apt-get install libimage-exiftool-perl) !!!!!!!!\n"
        );
    }
    let cases = [
        (ProjectionKind::LatLong, (64, 32), (64, 32, 0, 0)),
        (ProjectionKind::HalfEquirect, (32, 32), (64, 32, 16, 0)),
    ];
    for (kind, (w, h), (fw, fh, left, top)) in cases {
        for (ext, precision) in [("png", None), ("png", Some(Precision::U16)), ("jpg", None)] {
            let path = dir.path().join(format!("{kind}-{precision:?}.{ext}"));
            let opts = options(kind, Stereo::Mono, precision);
            write_image(&path, &Image::new(w, h, 3), &opts).unwrap();
            let want = Crop {
                full_width: fw,
                full_height: fh,
                width: w,
                height: h,
                left,
                top,
            };
            // Ours.
            let xmp = read_xmp(&path).unwrap().expect("XMP written");
            assert_eq!(gpano::parse(&xmp, w, h), Some(Ok(want)), "{path:?}");
            // The image crate's readers find the same packet.
            assert_eq!(image_crate_xmp(&path).as_deref(), Some(xmp.as_str()));
            // The file still reads, with mirrorball's own record.
            let loaded = read(&path, &Default::default()).unwrap();
            assert_eq!(loaded.recorded.unwrap().unwrap().projection.kind(), kind);
            if let Some(v) = exiftool(&path) {
                assert_eq!(v["ProjectionType"], "equirectangular", "{path:?}: {v}");
                assert_eq!(v["UsePanoramaViewer"], 1, "{v}");
                assert_eq!(v["FullPanoWidthPixels"], fw, "{v}");
                assert_eq!(v["FullPanoHeightPixels"], fh, "{v}");
                assert_eq!(v["CroppedAreaImageWidthPixels"], w, "{v}");
                assert_eq!(v["CroppedAreaImageHeightPixels"], h, "{v}");
                assert_eq!(v["CroppedAreaLeftPixels"], left, "{v}");
                assert_eq!(v["CroppedAreaTopPixels"], top, "{v}");
            }
        }
    }
}

#[test]
fn other_projections_pairs_and_unrecorded_pictures_carry_none() {
    let dir = tempfile::tempdir().unwrap();
    for ext in ["png", "jpg"] {
        let cases = [
            (
                Some(options(ProjectionKind::Sphere, Stereo::Mono, None)),
                (16, 16),
            ),
            (
                Some(options(ProjectionKind::LatLong, Stereo::SideBySide, None)),
                (64, 16),
            ),
            (None, (64, 32)),
        ];
        for (i, (opts, (w, h))) in cases.into_iter().enumerate() {
            let path = dir.path().join(format!("{i}.{ext}"));
            let opts = opts.unwrap_or_default();
            write_image(&path, &Image::new(w, h, 3), &opts).unwrap();
            assert_eq!(read_xmp(&path).unwrap(), None, "{path:?}");
            assert_eq!(image_crate_xmp(&path), None, "{path:?}");
        }
    }
    // A cube cross is not a panorama either.
    let cross = WriteOptions {
        declared: Some(MapInfo {
            projection: ProjectionKind::Cube.default_projection(),
            layout: Some(Layout::HorizontalCross),
            stereo: Stereo::Mono,
        }),
        ..WriteOptions::default()
    };
    let path = dir.path().join("cross.png");
    write_image(&path, &Image::new(64, 48, 3), &cross).unwrap();
    assert_eq!(read_xmp(&path).unwrap(), None);
}
