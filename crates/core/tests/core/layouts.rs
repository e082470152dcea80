//! Layouts: packing round trips, crosses that join up, guesses from the aspect ratio.
use glam::DVec3;
use mirrorball_core::layout::guess;
use mirrorball_core::{EnvMap, Image, Layout, ProjectionKind};

/// A smooth environment whose value says where it looks.
fn env(kind: ProjectionKind, size: u32) -> EnvMap {
    EnvMap::from_fn(kind.default_projection(), size, 3, |d: DVec3| {
        [
            (d.x + 1.0) as f32,
            (d.y + 1.0) as f32,
            (d.z + 1.0) as f32,
            1.0,
        ]
    })
}

#[test]
fn pack_then_unpack_is_the_identity() {
    for kind in [
        ProjectionKind::Cube,
        ProjectionKind::ContinuousCube,
        ProjectionKind::Paraboloid,
    ] {
        let e = env(kind, 8);
        for layout in Layout::ALL {
            if layout == Layout::Separate || !layout.fits(e.layers().len()) {
                assert!(layout.pack(&e).is_none() || e.layers().len() == 1);
                continue;
            }
            let img = layout.pack(&e).unwrap();
            let (c, r) = layout.grid(e.layers().len());
            assert_eq!((img.width(), img.height()), (8 * c, 8 * r));
            let back = layout.unpack(&img, *e.projection()).unwrap();
            assert_eq!(back, e, "{kind} {layout}");
        }
    }
}

/// Across every internal boundary of a cross, neighbouring texels see nearby directions: the
/// jump across a boundary is no larger than between neighbours inside a face.
#[test]
fn crosses_join_up_without_mirroring() {
    let n = 32;
    let e = env(ProjectionKind::Cube, n);
    for layout in [Layout::HorizontalCross, Layout::VerticalCross] {
        let img = layout.pack(&e).unwrap();
        let occupied = |x: u32, y: u32| img.get(x, y).iter().any(|&v| v != 0.0);
        let diff = |a: &[f32], b: &[f32]| {
            a.iter()
                .zip(b)
                .map(|(p, q)| (p - q).abs())
                .fold(0.0f32, f32::max)
        };
        let mut worst_inside = 0.0f32;
        let mut worst_across = 0.0f32;
        for y in 0..img.height() {
            for x in 0..img.width() - 1 {
                if occupied(x, y) && occupied(x + 1, y) {
                    let d = diff(img.get(x, y), img.get(x + 1, y));
                    if (x + 1) % n == 0 {
                        worst_across = worst_across.max(d)
                    } else {
                        worst_inside = worst_inside.max(d)
                    }
                }
            }
        }
        for y in 0..img.height() - 1 {
            for x in 0..img.width() {
                if occupied(x, y) && occupied(x, y + 1) {
                    let d = diff(img.get(x, y), img.get(x, y + 1));
                    if (y + 1) % n == 0 {
                        worst_across = worst_across.max(d)
                    } else {
                        worst_inside = worst_inside.max(d)
                    }
                }
            }
        }
        assert!(
            worst_across < 1.5 * worst_inside,
            "{layout}: across {worst_across} inside {worst_inside}"
        );
    }
}

#[test]
fn unpack_refuses_pictures_that_fit_no_layout() {
    let img = Image::new(100, 60, 3);
    let cube = ProjectionKind::Cube.default_projection();
    let err = Layout::HorizontalCross.unpack(&img, cube).unwrap_err();
    assert!(err.contains("100x60"), "{err}");
    assert!(Layout::from_extent(100, 60, 6).is_none());
    assert!(guess(100, 60, None).is_none());
}

#[test]
fn guesses_follow_the_aspect_ratio_and_declarations() {
    let g = |w, h| guess(w, h, None).map(|g| (g.kind, g.layout));
    assert_eq!(
        g(512, 256),
        Some((ProjectionKind::LatLong, Layout::Separate))
    );
    assert_eq!(
        g(400, 300),
        Some((ProjectionKind::Cube, Layout::HorizontalCross))
    );
    assert_eq!(
        g(300, 400),
        Some((ProjectionKind::Cube, Layout::VerticalCross))
    );
    assert_eq!(
        g(600, 100),
        Some((ProjectionKind::Cube, Layout::HorizontalStrip))
    );
    assert_eq!(
        g(100, 600),
        Some((ProjectionKind::Cube, Layout::VerticalStrip))
    );
    assert_eq!(
        g(256, 256),
        Some((ProjectionKind::Sphere, Layout::Separate))
    );
    let d = guess(128, 768, Some(ProjectionKind::Cube)).unwrap();
    assert_eq!(
        (d.kind, d.layout),
        (ProjectionKind::Cube, Layout::VerticalStrip)
    );
    assert!(d.reason.contains("declares"));
}

#[test]
fn unpacking_an_owned_picture_gives_what_unpacking_a_borrowed_one_gives() {
    use mirrorball_core::{EnvMap, Layout, ProjectionKind};
    let cube = EnvMap::from_fn(ProjectionKind::Cube.default_projection(), 8, 3, |d| {
        [d.x as f32, d.y as f32, d.z as f32, 1.0]
    });
    let ll = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 16, 3, |d| {
        [d.x as f32, 0.5, d.z as f32, 1.0]
    });
    for (env, layout) in [
        (&cube, Layout::HorizontalCross),
        (&cube, Layout::VerticalStrip),
        (&ll, Layout::Separate),
    ] {
        let img = layout.pack(env).expect("packs");
        let borrowed = layout.unpack(&img, *env.projection()).unwrap();
        let owned = layout.unpack_owned(img, *env.projection()).unwrap();
        assert_eq!(owned, borrowed);
        assert_eq!(&owned, env);
    }
}
