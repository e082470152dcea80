//! What a bake leaves in its folder, for every engine of the table: file names that are the
//! engine's own (never the source's), a README that names only files the bake wrote (and
//! every one of them), the folder's record and the background's size.

use crate::common::{bake, direction_coded};
use mirrorball_bake::{
    background_face_for, Bake, BakeOptions, Lighting, ENGINES, MAX_BACKGROUND, MIN_BACKGROUND,
    README,
};
use mirrorball_core::{EnvMap, Image, ProjectionKind};
use std::collections::BTreeSet;
use std::path::Path;

/// `path`'s files and those of its folders, relative to it (`/` between folders).
fn listing(path: &Path) -> BTreeSet<String> {
    fn walk(dir: &Path, prefix: &str, out: &mut BTreeSet<String>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let e = e.unwrap();
            let name = format!("{prefix}{}", e.file_name().to_string_lossy());
            if e.file_type().unwrap().is_dir() {
                walk(&e.path(), &format!("{name}/"), out);
            } else {
                out.insert(name);
            }
        }
    }
    let mut out = BTreeSet::new();
    walk(path, "", &mut out);
    out
}

/// The words of `text` that name a file of a kind some bake writes (an extension of any
/// engine's files, from the table): each a path as the README gives it.
fn file_words(text: &str, extensions: &BTreeSet<String>) -> Vec<String> {
    text.split(|c: char| !(c.is_ascii_alphanumeric() || "_./{}-".contains(c)))
        .map(|w| w.trim_end_matches('.').trim_start_matches("./"))
        .filter(|w| {
            w.rsplit_once('.')
                .is_some_and(|(stem, ext)| !stem.is_empty() && extensions.contains(ext))
        })
        .map(String::from)
        .collect()
}

#[test]
fn every_readme_names_exactly_the_files_its_bake_wrote() {
    let opts = BakeOptions {
        size: 16,
        ..Default::default()
    };
    let extensions: BTreeSet<String> = ENGINES
        .iter()
        .flat_map(|e| e.file_names(&opts))
        .chain([README.to_string()])
        .filter_map(|n| n.rsplit_once('.').map(|(_, x)| x.to_string()))
        .collect();
    assert!(extensions.contains("hdr") && extensions.contains("ktx"));
    for engine in ENGINES {
        let dir = tempfile::tempdir().unwrap();
        let (_, _, files) = bake(engine, 16, None, dir.path());
        let readme = std::fs::read_to_string(dir.path().join(README)).unwrap();
        let on_disk = listing(dir.path());
        for word in file_words(&readme, &extensions) {
            assert!(
                on_disk.contains(&word) && word != mirrorball_io::RECORD,
                "{engine}: README names {word}, which the bake did not write ({on_disk:?})"
            );
        }
        // And every file written is in the README, by its path in the folder.
        for f in &files {
            let rel = f.strip_prefix(dir.path()).unwrap().to_string_lossy();
            if rel != README {
                assert!(readme.contains(&*rel), "{engine}: README lacks {rel}");
            }
        }
    }
    // The check sees a wrong path: three's faces named without their folder.
    assert_eq!(
        file_words(
            "load('px.hdr'), then 'cube/nx.hdr'; see env.wesl",
            &extensions
        ),
        ["px.hdr", "cube/nx.hdr"]
    );
}

#[test]
fn file_names_are_the_engines_own_whatever_the_source() {
    for engine in ENGINES {
        let named = |source: &str| {
            engine.file_names(&BakeOptions {
                size: 64,
                source: source.into(),
                ..Default::default()
            })
        };
        let names = named("/maps/meadow.exr");
        assert_eq!(names, named("other_{face}.hdr"), "{engine}");
        for n in &names {
            assert!(!n.contains("meadow"), "{engine}: {n}");
        }
        // And they are what the bake writes.
        let dir = tempfile::tempdir().unwrap();
        let (baked, _, files) = bake(engine, 64, None, dir.path());
        let mut want: BTreeSet<String> = baked.file_names().into_iter().collect();
        assert_eq!(files.len(), want.len(), "{engine}");
        want.insert(mirrorball_io::RECORD.to_string());
        assert_eq!(listing(dir.path()), want, "{engine}");
    }
}

/// A lat-long of `width` (2:1) with a constant colour.
fn flat(width: u32) -> EnvMap {
    EnvMap::from_fn(
        ProjectionKind::LatLong.default_projection(),
        width,
        3,
        |_| [1.0, 0.5, 0.25, 1.0],
    )
}

#[test]
fn the_background_keeps_the_sources_resolution_within_bounds() {
    // Six faces of f² hold as many texels as a w × w/2 lat-long when f = w/√12 (0.29w),
    // rounded to a power of two: 1024 wide gives 256², 2048 wide 512².
    assert_eq!(background_face_for(&flat(1024)), 256);
    assert_eq!(background_face_for(&flat(2048)), 512);
    assert_eq!(background_face_for(&flat(32)), MIN_BACKGROUND);
    // A narrow fisheye holds many texels per steradian: capped.
    let narrow = mirrorball_core::projection::ProjectionSpec::parse("fisheye:fov=10")
        .unwrap()
        .build(None)
        .unwrap();
    let narrow = EnvMap::new(narrow, vec![Image::new(512, 512, 3)]).unwrap();
    assert!(narrow.natural_size(ProjectionKind::Cube) > MAX_BACKGROUND);
    assert_eq!(background_face_for(&narrow), MAX_BACKGROUND);
}

#[test]
fn the_background_follows_the_source_or_the_request_never_the_chain() {
    for engine in ENGINES {
        let mut b = Bake::new(
            engine,
            BakeOptions {
                size: 16,
                ..Default::default()
            },
        )
        .unwrap();
        let takes = engine.describe().background.is_some();
        assert_eq!(b.spec.background_face.is_some(), takes, "{engine}");
        b.fit(&flat(1024));
        assert_eq!(b.spec.background_face, takes.then_some(256), "{engine}");
        let asked = Bake::new(
            engine,
            BakeOptions {
                size: 16,
                background_size: Some(32),
                ..Default::default()
            },
        );
        if !takes {
            let e = asked.unwrap_err();
            assert!(e.message.contains("no background"), "{}", e.message);
            continue;
        }
        let mut asked = asked.unwrap();
        asked.fit(&flat(1024));
        assert_eq!(asked.spec.background_face, Some(32), "{engine}");
        let lighting: Lighting = asked.lighting(&direction_coded(128), Default::default());
        let sky = lighting.background.expect("a background");
        assert_eq!((sky.width(), sky.layers().len()), (32, 6), "{engine}");
        for bad in [0, 48, 2 * mirrorball_bake::MAX_SIZE] {
            let e = Bake::new(
                engine,
                BakeOptions {
                    background_size: Some(bad),
                    ..Default::default()
                },
            )
            .unwrap_err();
            assert!(
                e.message.contains("power of two"),
                "{engine}: {}",
                e.message
            );
        }
    }
}
