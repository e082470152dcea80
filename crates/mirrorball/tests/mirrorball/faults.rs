//! Whose fault each kind of failure is, as every front end reads it (exit status, HTTP
//! status, Python exception): a bad setting is the request's, a bad file the input's, a
//! folder that cannot be written the system's.

use mirrorball::core::{EnvMap, Image, ProjectionKind};
use mirrorball::io::{Limits, WriteOptions};
use mirrorball::{budget, load, materials, save, size, Fault, ProjSpec, SaveOptions};

fn opts() -> SaveOptions {
    SaveOptions {
        layout: None,
        write: WriteOptions::default(),
        mips: false,
        keep_invalid: false,
    }
}

fn latlong() -> EnvMap {
    let p = ProjectionKind::LatLong.default_projection();
    EnvMap::new(p, vec![Image::new(16, 8, 3)]).unwrap()
}

#[test]
fn bad_setting_values_are_the_requests_fault() {
    assert_eq!(size::parse("12x").unwrap_err().fault, Fault::Request);
    assert_eq!(
        budget::parse_bytes("lots").unwrap_err().fault,
        Fault::Request
    );
    let e = materials::parse_material("no-such-material", [1.0; 3], 0.04).unwrap_err();
    assert_eq!(e.fault, Fault::Request, "{e}");
    let e = ProjSpec::parse("fisheye:fov=400").unwrap_err();
    assert_eq!(e.fault, Fault::Request, "{e}");
    let e = mirrorball::spec::parse_dir("sideways").unwrap_err();
    assert_eq!(e.fault, Fault::Request, "{e}");
    // Converted into the library's error, the fault is kept.
    assert_eq!(mirrorball::Error::from(e).fault, Fault::Request);
}

#[test]
fn a_truncated_file_is_the_inputs_fault() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sky.exr");
    let out = path.to_str().unwrap();
    save(&latlong(), out, &opts()).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    let e = load(out, None, None, &Limits::default()).err().unwrap();
    assert_eq!(e.fault, Fault::Input, "{e}");
    let e = load::from_bytes("sky.exr", &bytes[..40], None, None, &Limits::default())
        .err()
        .unwrap();
    assert_eq!(e.fault, Fault::Input, "{e}");
}

#[test]
fn a_folder_that_cannot_be_written_is_the_systems_fault() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing").join("sky.exr");
    let e = save(&latlong(), missing.to_str().unwrap(), &opts())
        .err()
        .unwrap();
    assert_eq!(e.fault, Fault::System, "{e}");
    assert_eq!(e.io_kind(), Some(std::io::ErrorKind::NotFound), "{e}");
    // A read-only folder (where permissions apply: not to root).
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let ro = dir.path().join("ro");
        std::fs::create_dir(&ro).unwrap();
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
        let probe = std::fs::write(ro.join("probe"), b"x");
        if probe.is_err() {
            let e = save(&latlong(), ro.join("sky.png").to_str().unwrap(), &opts())
                .err()
                .unwrap();
            assert_eq!(e.fault, Fault::System, "{e}");
            assert_eq!(e.io_kind(), Some(std::io::ErrorKind::PermissionDenied));
        }
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
}
