//! The per-vertex indexing studies.
use crate::util::close;
use glam::DVec3;
use mirrorball_analysis::cone::{cone_region, greene_cone};
use mirrorball_analysis::geom::reflect;
use mirrorball_analysis::indexing::{LineStudy, MapSpec, QuadStudy, SphereStudy, VertexIndexing};
use mirrorball_core::ProjectionKind as K;
use std::f64::consts::PI;

#[test]
fn reflection_is_the_mirror_direction() {
    let i = DVec3::new(1.0, -1.0, 0.0).normalize();
    let r = reflect(i, DVec3::Y);
    assert!((r - DVec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-15);
}

#[test]
fn line_study_is_exact_at_the_ends_and_for_a_centred_viewer() {
    let l = LineStudy::ZIMMONS;
    assert!(l.error_at(-8.3, -10.0) < 1e-9 && l.error_at(-8.3, 10.0) < 1e-9);
    // Viewer above the middle: the interpolated vector is parallel to the exact one, since
    // (x, 1)/√(x² + 1) interpolated between ±10 is ∝ (x, 1).
    for x in [-7.0, -1.0, 3.0, 9.5] {
        assert!(l.error_at(0.0, x) < 1e-9, "{x}");
    }
    // The stated set-up's worst cases (Zimmons prints 2.61° and 2.60751°).
    let w = l.worst(-8.3);
    assert!(
        (w.degrees - 118.36).abs() < 0.01 && (w.at[0] + 5.06).abs() < 0.01,
        "{w:?}"
    );
    // Symmetry: a mirrored viewer gives the mirrored worst case.
    let m = l.worst(8.3);
    close(m.degrees, w.degrees, 1e-9, "symmetric");
    close(m.at[0], -w.at[0], 1e-6, "mirrored");
    // More segments, less error (roughly quadratically in the segment length).
    let e4 = LineStudy { segments: 4, ..l }.worst(-8.3).degrees;
    let e64 = LineStudy { segments: 64, ..l }.worst(-8.3).degrees;
    assert!(e4 < w.degrees && e64 < 0.5, "{e4} {e64}");
}

#[test]
fn a_flat_quad_seen_from_above_its_centre_is_exact_under_vector_indexing() {
    let q = QuadStudy {
        half: 10.0,
        cells: 1,
        height: 1.0,
        samples: 8,
    };
    let maps = [MapSpec {
        projection: K::Cube.default_projection(),
        size: 64,
        indexing: VertexIndexing::Vector,
    }];
    let (res, _) = q.run(&[0.0, -5.0], &maps);
    assert!(res[0].worst.degrees < 1e-9, "{:?}", res[0].worst);
    assert!(res[1].worst.degrees > 1.0);
    assert!(
        res[0].samples > 0
            && res[0].maps[0].samples + res[0].maps[0].seam_samples == res[0].samples
    );
}

#[test]
fn a_finer_sphere_has_smaller_errors() {
    let maps = [
        MapSpec {
            projection: K::Sphere.default_projection(),
            size: 256,
            indexing: VertexIndexing::Texgen,
        },
        MapSpec {
            projection: K::Paraboloid.default_projection(),
            size: 256,
            indexing: VertexIndexing::Vector,
        },
    ];
    let coarse = SphereStudy {
        stacks: 8,
        slices: 16,
        distance: 3.0,
        azimuth_deg: 11.25,
        samples: 8,
    };
    let fine = SphereStudy {
        stacks: 32,
        slices: 64,
        ..coarse
    };
    let (c, _) = coarse.run(&[30.0], &maps);
    let (f, _) = fine.run(&[30.0], &maps);
    assert!(
        f[0].worst.degrees < c[0].worst.degrees / 4.0,
        "{} {}",
        f[0].worst.degrees,
        c[0].worst.degrees
    );
    assert!(f[0].mean_degrees < c[0].mean_degrees);
    // Only the visible half is sampled, and every sample has a reflection.
    assert!(c[0].samples > 0);
}

#[test]
fn greene_cone_on_the_cube_is_five_polygons() {
    let cone = greene_cone();
    close(
        cone.solid_angle(),
        3.0 / 8.0 * 4.0 * PI,
        1e-12,
        "3/8 of the world",
    );
    let r = cone_region(&K::Cube.default_projection(), 64, &cone);
    assert_eq!(r.pieces, 5);
    assert!(r.max_edge_bend_texels < 1e-9, "{}", r.max_edge_bend_texels);
    close(r.solid_angle, cone.solid_angle(), 1e-2, "texels inside");
    let m = cone_region(&K::Mercator.default_projection(), 128, &cone);
    assert_eq!(m.pieces, 1);
    assert!(m.max_edge_bend_texels > 1.0);
}
