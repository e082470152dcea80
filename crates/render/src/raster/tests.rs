//! The rasteriser's rules: every sample of a shared edge drawn once, depth order,
//! near-plane clipping keeps perspective-correct weights.

use super::*;

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
    let count = |v: &VisBuffer| v.samples.iter().filter(|s| s.tri != NO_HIT).count();
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
    let cam = crate::Camera::perspective(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 90.0, 16, 16);
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

#[test]
fn culling_leaves_out_the_winding_it_names_as_gl_cull_face_does() {
    // In NDC (y up), (−½,−½) → (½,−½) → (0,½) runs counter-clockwise: OpenGL's front face.
    let clip = vec![
        Vec4::new(-0.5, -0.5, 0.0, 1.0),
        Vec4::new(0.5, -0.5, 0.0, 1.0),
        Vec4::new(0.0, 0.5, 0.0, 1.0),
    ];
    let ccw = [[0u32, 1, 2]];
    let cw = [[0u32, 2, 1]];
    let count =
        |tris: &[[u32; 3]], cull: Cull| Binned::new(&clip, tris, 16, 16, 4, |_| cull).setup_count();
    assert_eq!(count(&ccw, Cull::None), 1);
    assert_eq!(count(&cw, Cull::None), 1);
    assert_eq!(count(&ccw, Cull::Clockwise), 1);
    assert_eq!(count(&cw, Cull::Clockwise), 0);
    assert_eq!(count(&ccw, Cull::CounterClockwise), 0);
    assert_eq!(count(&cw, Cull::CounterClockwise), 1);
}

#[test]
fn a_band_buffer_reused_band_after_band_sees_what_a_fresh_one_sees() {
    // Triangles scattered so that neighbouring bands cover disjoint, overlapping and no
    // columns: a buffer reused in any order of bands (as a rendering thread takes them)
    // must hold exactly what a fresh buffer holds, band by band.
    let (w, h, band) = (96u32, 64u32, 8u32);
    let mut clip = Vec::new();
    let mut tris = Vec::new();
    let mut seed = 7u32;
    let mut rnd = || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (seed >> 8) as f32 / (1u32 << 24) as f32
    };
    for _ in 0..12 {
        let (cx, cy, r) = (rnd() * 2.0 - 1.0, rnd() * 2.0 - 1.0, 0.05 + 0.3 * rnd());
        let z = rnd() * 0.8 - 0.4;
        let base = clip.len() as u32;
        for k in 0..3 {
            let a = k as f32 * 2.1 + rnd();
            clip.push(Vec4::new(cx + r * a.cos(), cy + r * a.sin(), z, 1.0));
        }
        tris.push([base, base + 1, base + 2]);
    }
    let binned = Binned::new(&clip, &tris, w, h, band, |_| Cull::None);
    let bands = h.div_ceil(band) as usize;
    let mut reused = BandBuffer::default();
    let mut hits = 0;
    for b in (0..bands).chain((0..bands).rev()).chain([3, 0, 5, 5, 1]) {
        let cols = binned.scan_band(b, &mut reused);
        let mut fresh = BandBuffer::default();
        let fresh_cols = binned.scan_band(b, &mut fresh);
        assert_eq!(cols, fresh_cols);
        assert_eq!(reused.ids(), fresh.ids(), "band {b}");
        assert_eq!(
            reused
                .depth()
                .iter()
                .map(|d| d.to_bits())
                .collect::<Vec<_>>(),
            fresh
                .depth()
                .iter()
                .map(|d| d.to_bits())
                .collect::<Vec<_>>()
        );
        // Outside the columns it names, the band has no hit.
        for (i, &id) in fresh.ids().iter().enumerate() {
            let x = i % w as usize;
            if id != NO_HIT {
                hits += 1;
                assert!(cols.contains(&x));
            }
        }
    }
    assert!(hits > 100);
}
