//! Property-based tests (proptest): the same invariants as `projections.rs`, over inputs
//! proptest chooses and shrinks.
use crate::util::{all_projections, angle};
use glam::{DVec2, DVec3};
use mirrorball_core::{EnvMap, Layout, ProjectionKind, Rotation, WorldProjection};
use proptest::prelude::*;

fn direction() -> impl Strategy<Value = DVec3> {
    (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0)
        .prop_filter("non-zero", |(x, y, z)| x * x + y * y + z * z > 1e-6)
        .prop_map(|(x, y, z)| DVec3::new(x, y, z).normalize())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn every_projection_inverts_exactly(d in direction()) {
        for p in all_projections() {
            if let Some((layer, uv)) = p.dir_to_uv(d) {
                let back = p.uv_to_dir(layer, uv).unwrap();
                prop_assert!(angle(d, back) < 1e-9, "{}: {d} -> {uv} -> {back}", p.name());
            }
        }
    }

    #[test]
    fn rotations_compose_with_their_inverse(yaw in -360.0f64..360.0, pitch in -90.0f64..90.0, roll in -180.0f64..180.0, d in direction()) {
        let r = Rotation::from_euler_deg(yaw, pitch, roll);
        let m = glam::DMat3::from_rotation_y(yaw.to_radians())
            * glam::DMat3::from_rotation_x(pitch.to_radians())
            * glam::DMat3::from_rotation_z(-roll.to_radians());
        // The output at m·d shows the source at d.
        prop_assert!(angle(r.source_of(m * d), d) < 1e-12);
    }

    #[test]
    fn layouts_round_trip_at_any_face_size(n in 1u32..24, kind in prop::sample::select(vec![ProjectionKind::Cube, ProjectionKind::ContinuousCube, ProjectionKind::Paraboloid])) {
        let e = EnvMap::from_fn(kind.default_projection(), n, 4, |d| [d.x as f32, d.y as f32, d.z as f32, 1.0]);
        for layout in Layout::ALL {
            if layout == Layout::Separate || !layout.fits(e.layers().len()) {
                continue;
            }
            let img = layout.pack(&e).unwrap();
            prop_assert_eq!(Layout::from_extent(img.width(), img.height(), e.layers().len()).map(|g| g.1), Some(n));
            prop_assert_eq!(&layout.unpack(&img, *e.projection()).unwrap(), &e);
        }
    }

    #[test]
    fn solid_angles_are_positive_and_bounded(size in 2u32..40) {
        for p in all_projections() {
            let (w, h) = p.layer_extent(size);
            let (x, y) = (w / 2, h / 2);
            let s = p.texel_solid_angle(0, x, y, w, h);
            prop_assert!(s >= 0.0 && s <= p.covered_solid_angle());
            let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
            prop_assert!(p.density(0, uv) >= 0.0);
        }
    }
}
