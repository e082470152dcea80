//! Clamping and soft compression report the energy they remove.
use mirrorball_core::{EnvMap, ProjectionKind, WorldProjection};
use mirrorball_filter::{compress, Compression};

#[test]
fn clamp_reports_energy() {
    let mut env = EnvMap::from_fn(ProjectionKind::Cube.default_projection(), 8, 3, |_| {
        [1.0, 1.0, 1.0, 1.0]
    });
    env.layers_mut()[0].set(3, 4, &[300.0, 300.0, 300.0]);
    let om = env.projection().texel_solid_angle(0, 3, 4, 8, 8);
    let total = 4.0 * std::f64::consts::PI + 299.0 * om;
    let r = compress(&mut env, Compression::Clamp { max: 100.0 });
    assert_eq!(r.texels, 1);
    assert_eq!(r.max_before, 300.0);
    assert_eq!(r.max_after, 100.0);
    let removed = 200.0 * om;
    assert!((r.before[0] - total).abs() < 1e-6 * total);
    assert!((r.before[0] - r.after[0] - removed).abs() < 1e-6 * total);
    assert!((r.fraction_removed - removed / total).abs() < 1e-6);
    assert_eq!(env.layers()[0].get(3, 4), &[100.0, 100.0, 100.0]);
}

#[test]
fn soft_keeps_hue_and_order() {
    let mut env = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 16, 3, |d| {
        let v = if d.y > 0.9 { 1000.0 } else { 0.5 };
        [v, 0.5 * v, 0.25 * v, 1.0]
    });
    let r = compress(
        &mut env,
        Compression::Soft {
            knee: 2.0,
            max: 50.0,
        },
    );
    assert!(r.fraction_removed > 0.0 && r.max_after <= 50.0);
    let t = env.layers()[0].get(0, 0);
    assert!((t[1] / t[0] - 0.5).abs() < 1e-6 && (t[2] / t[0] - 0.25).abs() < 1e-6);
    let none = compress(&mut env.clone(), Compression::None);
    assert_eq!(none.texels, 0);
    assert_eq!(none.fraction_removed, 0.0);
}
