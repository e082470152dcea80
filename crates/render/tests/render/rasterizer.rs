//! The rasteriser's rules: every sample of a shared edge drawn once, depth order,
//! near-plane clipping keeps perspective-correct weights.

use glam::{Vec3, Vec4};
use mirrorball_render::raster::{rasterize, NO_HIT};

#[test]
fn two_triangles_of_a_square_cover_each_sample_once() {
    // A square from (0.1, 0.1) to (0.7, 0.9) of a 40×30 grid in NDC, split along its
    // diagonal; with the top-left rule the two halves tile it with no gap and no overlap.
    let (w, h) = (40u32, 30u32);
    let to_ndc = |x: f32, y: f32| Vec4::new(2.0 * x - 1.0, 1.0 - 2.0 * y, 0.0, 1.0);
    let clip = vec![
        to_ndc(0.1, 0.1),
        to_ndc(0.7, 0.1),
        to_ndc(0.7, 0.9),
        to_ndc(0.1, 0.9),
    ];
    let both = rasterize(&clip, &[[0, 1, 2], [0, 2, 3]], w, h);
    let a = rasterize(&clip, &[[0, 1, 2]], w, h);
    let b = rasterize(&clip, &[[0, 2, 3]], w, h);
    let count = |v: &mirrorball_render::raster::VisBuffer| {
        v.samples.iter().filter(|s| s.tri != NO_HIT).count()
    };
    // Sample centres inside [4, 28) × [3, 27): x+½ in (4, 28), y+½ in (3, 27).
    let expect = (28 - 4) * (27 - 3);
    assert_eq!(count(&both), expect);
    assert_eq!(count(&a) + count(&b), expect);
}

#[test]
fn nearer_triangle_wins_whatever_the_order() {
    let clip_near = [
        Vec4::new(-1.0, -1.0, -0.5, 1.0),
        Vec4::new(3.0, -1.0, -0.5, 1.0),
        Vec4::new(-1.0, 3.0, -0.5, 1.0),
    ];
    let clip_far = clip_near.map(|c| Vec4::new(c.x, c.y, 0.5, 1.0));
    let clip: Vec<Vec4> = clip_near.iter().chain(clip_far.iter()).copied().collect();
    for order in [[[0, 1, 2], [3, 4, 5]], [[3, 4, 5], [0, 1, 2]]] {
        let v = rasterize(&clip, &order, 8, 8);
        assert!(v
            .samples
            .iter()
            .all(|s| s.tri == order.iter().position(|t| t[0] == 0).unwrap() as u32));
    }
}

#[test]
fn near_clipping_keeps_perspective_correct_weights() {
    // A triangle crossing the near plane: its visible part's weights must be those of the
    // unclipped triangle. Eye-space triangle, projected with a GL perspective matrix.
    let cam =
        mirrorball_render::Camera::perspective(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 90.0, 16, 16);
    let m = cam.projection();
    let eye = [
        Vec3::new(-1.0, -0.5, 1.0),
        Vec3::new(1.0, -0.5, -3.0),
        Vec3::new(0.0, 1.0, -3.0),
    ];
    let clip: Vec<Vec4> = eye.iter().map(|p| m * p.extend(1.0)).collect();
    let v = rasterize(&clip, &[[0, 1, 2]], 16, 16);
    let mut n = 0;
    for (i, s) in v.samples.iter().enumerate() {
        if s.tri == NO_HIT {
            continue;
        }
        n += 1;
        let (x, y) = ((i % 16) as f32 + 0.5, (i / 16) as f32 + 0.5);
        let b = s.weights();
        let p = eye[0] * b.x + eye[1] * b.y + eye[2] * b.z;
        // The eye-space point must project to the sample centre.
        let c = m * p.extend(1.0);
        let sx = (c.x / c.w + 1.0) * 8.0;
        let sy = (1.0 - c.y / c.w) * 8.0;
        assert!(
            (sx - x).abs() < 1e-3 && (sy - y).abs() < 1e-3,
            "sample {x},{y} -> {sx},{sy}"
        );
        assert!(p.z < -cam.near * 0.999);
    }
    assert!(n > 20);
}
