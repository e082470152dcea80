//! The request's checks before any work, and a bake's files landing together.

use crate::common::{bake, direction_coded};
use mirrorball_bake::{Bake, BakeOptions, Engine, ENGINES};
use mirrorball_core::{Axis, AxisMap, Fault};
use mirrorball_io::Encoding;

fn refused(engine: Engine, opts: BakeOptions) -> String {
    let e = Bake::new(engine, opts).expect_err("refused");
    assert_eq!(e.fault, Fault::Request);
    e.message
}

#[test]
fn bad_requests_are_refused_before_any_work() {
    for size in [0, 100, 32768] {
        let m = refused(
            Engine::Ktx2,
            BakeOptions {
                size,
                ..Default::default()
            },
        );
        assert!(m.contains("power of two"), "{m}");
    }
    let m = refused(
        Engine::Filament,
        BakeOptions {
            encoding: Some(Encoding::Bc6hUnsigned),
            ..Default::default()
        },
    );
    assert!(
        m.contains("filament does not load bc6h") && m.contains("b10g11r11"),
        "{m}"
    );
    let m = refused(
        Engine::Unity,
        BakeOptions {
            zstd: Some(3),
            ..Default::default()
        },
    );
    assert!(m.contains("Zstandard"), "{m}");
    for e in ENGINES {
        if e.describe().encodings.is_empty() {
            assert!(refused(e, BakeOptions::default()).contains("not written yet"));
        }
    }
    // BC6H unsigned of a map with negative values: refused after reading, before any
    // prefiltering.
    let bake = Bake::new(Engine::Unreal, BakeOptions::default()).unwrap();
    let mut env = direction_coded(64);
    env.layers_mut()[0].data_mut()[5] = -0.25;
    let e = bake.check(&env).unwrap_err();
    assert!(e.message.contains("negative"), "{}", e.message);
    let signed = Bake::new(
        Engine::Unreal,
        BakeOptions {
            encoding: Some(Encoding::Bc6hSigned),
            ..Default::default()
        },
    )
    .unwrap();
    assert!(signed.check(&env).is_ok());
}

#[test]
fn the_files_of_a_bake_land_together_or_not_at_all() {
    let dir = tempfile::tempdir().unwrap();
    // The last file's temporary name taken by a folder: the files before it are written,
    // its own write fails.
    let blocker = format!(".README.md.{}.tmp", std::process::id());
    std::fs::create_dir(dir.path().join(&blocker)).unwrap();
    std::fs::write(dir.path().join("specular.ktx2"), b"old").unwrap();
    let bake = Bake::new(
        Engine::Ktx2,
        BakeOptions {
            size: 8,
            ..Default::default()
        },
    )
    .unwrap();
    let lighting = bake.lighting(&direction_coded(64), Default::default());
    assert!(bake.write(&lighting, dir.path()).is_err());
    let mut left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(
        left,
        [blocker.as_str(), "specular.ktx2"],
        "no new file, no temporary"
    );
    assert_eq!(
        std::fs::read(dir.path().join("specular.ktx2")).unwrap(),
        b"old"
    );
    // An existing folder keeps what it held; a fresh one is made and holds the four files.
    let fresh = dir.path().join("fresh");
    let blocked = tempfile::tempdir().unwrap();
    let inner = blocked.path().join("out");
    std::fs::create_dir(&inner).unwrap();
    std::fs::create_dir(inner.join(&blocker)).unwrap();
    assert!(bake.write(&lighting, &inner).is_err());
    assert_eq!(std::fs::read_dir(&inner).unwrap().count(), 1);
    assert!(bake.write(&lighting, &fresh).is_ok());
    let mut made: Vec<String> = std::fs::read_dir(&fresh)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    made.sort();
    let mut want = bake.file_names();
    want.push(mirrorball_io::RECORD.to_string());
    want.sort();
    assert_eq!(
        made, want,
        "the engine's files, README.md and the folder's record"
    );
}

#[test]
fn each_engine_has_one_orientation_and_its_readme_names_its_api() {
    assert_eq!(Engine::Unity.orientation(), AxisMap::mirror(Axis::Z));
    assert_eq!(Engine::Three.orientation(), AxisMap::mirror(Axis::X));
    assert_eq!(Engine::Bevy.orientation(), AxisMap::mirror(Axis::Z));
    assert!(Engine::Unreal.orientation().mirrors());
    assert!(Engine::Filament.orientation().is_identity());
    assert!(Engine::Ktx2.orientation().is_identity());
    for (engine, api) in [
        (Engine::Filament, "IndirectLight::Builder()"),
        (Engine::Unity, "customBakedTexture"),
        (Engine::Unreal, "SetCubemap"),
        (Engine::Ktx2, "ktxTexture2_CreateFromNamedFile"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        bake(engine, 4, None, dir.path());
        let readme = std::fs::read_to_string(dir.path().join("README.md")).unwrap();
        assert!(readme.contains(api), "{engine}: {readme}");
        assert!(readme.contains(engine.describe().rule), "{engine}");
    }
}
