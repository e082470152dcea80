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
    assert!(err.message.contains("100x60"), "{err}");
    assert_eq!(err.fault, mirrorball_core::Fault::Request);
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

/// Every layout the `Choice` table names, v360's cells and `eac` included.
fn every_layout() -> Vec<Layout> {
    <Layout as mirrorball_core::Choice>::all().collect()
}

/// Every projection × layout pair of the tables: a layout that holds the projection packs
/// a map and unpacks it unchanged; one that does not is refused with a message naming
/// exactly the projections it holds, and `eac` holds EAC alone.
#[test]
fn every_projection_and_layout_pair_round_trips_or_is_refused_naming_the_one_that_fits() {
    let (mut held, mut refused) = (0, 0);
    for kind in ProjectionKind::ALL {
        let e = env(kind, 8);
        let layers = e.layers().len();
        for layout in every_layout() {
            match layout.refusal(kind, "--to") {
                None => {
                    assert!(layout.holds(kind), "{kind} {layout}");
                    held += 1;
                    if layout == Layout::Separate && layers > 1 {
                        // One file a layer: nothing is packed.
                        continue;
                    }
                    let img = layout
                        .pack(&e)
                        .unwrap_or_else(|| panic!("{kind} {layout}: not packed"));
                    let back = layout.unpack(&img, *e.projection()).unwrap();
                    assert_eq!(back, e, "{kind} {layout}");
                }
                Some(why) => {
                    assert!(!layout.holds(kind), "{kind} {layout}");
                    refused += 1;
                    assert!(why.starts_with(layout.name()), "{why}");
                    assert!(why.contains(&format!("a {kind} map")), "{why}");
                    for other in ProjectionKind::ALL {
                        let named = why.contains(&format!("--to {other} "))
                            || why.contains(&format!("--to {other})"))
                            || why.contains(&format!("--to {other},"));
                        assert_eq!(named, layout.holds(other), "{other} in: {why}");
                    }
                }
            }
        }
    }
    assert_eq!(
        Layout::eac().refusal(ProjectionKind::Cube, "--to").unwrap(),
        "eac holds v360's padded equi-angular faces, not a cube map: use --to eac (or another layout)"
    );
    let all: Vec<ProjectionKind> = ProjectionKind::ALL
        .into_iter()
        .filter(|&k| Layout::eac().holds(k))
        .collect();
    assert_eq!(all, [ProjectionKind::Eac]);
    // Six-layer kinds take all but eac (EAC all), the paraboloid separate and the strips,
    // the rest separate only.
    assert_eq!(
        held + refused,
        ProjectionKind::ALL.len() * every_layout().len()
    );
    assert!(refused >= 15 * 8, "{refused}");
}

/// A picture of v360's padded `eac` shape is an EAC frame, not a cube laid out so; a
/// declared cube is never read from it.
#[test]
fn a_padded_eac_frame_is_guessed_as_eac() {
    for n in [8, 64, 512] {
        let (w, h) = Layout::eac().extent(6, n, n);
        let g = guess(w, h, None).unwrap();
        assert_eq!(
            (g.kind, g.layout),
            (ProjectionKind::Eac, Layout::eac()),
            "{w}x{h}"
        );
        assert!(g.reason.contains("eac"), "{}", g.reason);
        assert_ne!(
            Layout::from_extent_of(w, h, ProjectionKind::Cube).map(|l| l.0),
            Some(Layout::eac())
        );
        assert_eq!(
            Layout::from_extent_of(w, h, ProjectionKind::Eac),
            Some((Layout::eac(), n, n))
        );
    }
    // An unpadded 3x2 stays a cube.
    let g = guess(300, 200, None).unwrap();
    assert_eq!(g.kind, ProjectionKind::Cube);
}
