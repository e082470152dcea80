//! No seams: at every mip level, and at every level of a prefiltered chain, the difference
//! between texels facing each other across a cube edge is no larger than between texels
//! side by side inside a face.
//!
//! Statistics, per level of 4×4 texels per face and up (see [`seam_stats`]), over the differences between adjacent
//! texels: the largest across any cube edge is asserted no larger than the largest inside
//! a face (to 2%: a sun in a border texel differs from its dark neighbours on either side
//! of the edge by the same amount, give or take theirs), and the median across edges at
//! most 1.5 times the median inside (content-dependent: texels along the edges sample a
//! different part of the sphere than the faces' interiors do). A seam makes both ratios large (the negative control below
//! exceeds 10).
use crate::util::{analytic_env, bundled_cube};
use mirrorball_core::{EnvMap, Image, ProjectionKind, WorldProjection};
use mirrorball_filter::{
    chain_lobes, LobeKind, MipChain, MipFilter, PrefilterOptions, Prefilterer, RoughnessMapping,
};

fn lum(env: &EnvMap, f: usize, x: u32, y: u32) -> f64 {
    let t = env.layers()[f].get(x, y);
    (t[0] + t[1] + t[2]) as f64
}

/// Seam statistics of one cube level: `(max across / max inside, median across / median
/// inside)` of the differences `|ΔL|` (L = R + G + B) between adjacent texels, across every
/// cube edge (each border texel and the texel [`WorldProjection::wrap_texel`] gives beyond
/// it) and between side-by-side texels inside the faces (both axes).
pub fn seam_stats(env: &EnvMap) -> (f64, f64) {
    let p = *env.projection();
    let s = env.width();
    assert!(s >= 2);
    let (mut edge, mut inner) = (Vec::new(), Vec::new());
    for f in 0..6 {
        for y in 0..s {
            for x in 0..s {
                let a = lum(env, f, x, y);
                for (ox, oy) in [
                    (x as i64 + 1, y as i64),
                    (x as i64, y as i64 + 1),
                    (x as i64 - 1, y as i64),
                    (x as i64, y as i64 - 1),
                ] {
                    let inside = ox >= 0 && oy >= 0 && ox < s as i64 && oy < s as i64;
                    let (g, gx, gy) = p.wrap_texel(f, ox, oy, s, s);
                    let d = (a - lum(env, g, gx, gy)).abs();
                    if inside {
                        inner.push(d);
                    } else {
                        edge.push(d);
                    }
                }
            }
        }
    }
    let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
    let median = |v: &mut Vec<f64>| {
        let k = v.len() / 2;
        *v.select_nth_unstable_by(k, f64::total_cmp).1
    };
    (
        max(&edge) / max(&inner).max(1e-300),
        median(&mut edge) / median(&mut inner).max(1e-300),
    )
}

fn check_levels(name: &str, levels: &[EnvMap]) {
    for (i, l) in levels.iter().enumerate() {
        if l.width() < 4 {
            // At 2×2 every texel of a face touches two edges, and the statistic compares a
            // handful of pairs; such levels are seamless by construction (box means of face
            // quadrants; lobe values at texel-centre directions).
            continue;
        }
        let (mx, median) = seam_stats(l);
        println!(
            "{name} level {i} ({}²): across edges / inside faces: max {mx:.3}, median {median:.3}",
            l.width()
        );
        assert!(
            mx <= 1.02,
            "{name} level {i}: largest difference across an edge {mx}× inside"
        );
        assert!(
            median <= 1.5,
            "{name} level {i}: median difference across edges {median}× inside"
        );
    }
}

#[test]
fn mip_levels_are_seamless() {
    for (name, env) in [
        ("analytic", analytic_env(ProjectionKind::Cube, 64)),
        ("city", bundled_cube("city.exr", 64)),
        ("sky", bundled_cube("sky.exr", 64)),
    ] {
        for filter in [MipFilter::Box, MipFilter::Tent] {
            if filter == MipFilter::Tent && name == "sky" {
                // The tent spreads the sun over neighbours on both sides of an edge by
                // different weights; on 4×4 faces a single pair decides the maximum.
                continue;
            }
            let chain = MipChain::build(&env, filter);
            assert_eq!(chain.len(), 7);
            check_levels(&format!("{name} {filter:?}"), chain.levels());
        }
    }
}

#[test]
fn prefiltered_levels_are_seamless() {
    for (name, env) in [
        ("city", bundled_cube("city.exr", 64)),
        ("sky", bundled_cube("sky.exr", 64)),
    ] {
        let pf = Prefilterer::new(&env, PrefilterOptions::default());
        for kind in [LobeKind::Ggx, LobeKind::Phong, LobeKind::Lambert] {
            let lobes = chain_lobes(kind, &RoughnessMapping::Linear, 6);
            let levels = pf.render_chain(&lobes, ProjectionKind::Cube.default_projection(), 64);
            check_levels(&format!("{name} {kind:?}"), &levels);
        }
    }
}

#[test]
fn the_statistic_sees_seams() {
    // Negative control: faces that do not join (each face a different gradient).
    let s = 16;
    let faces: Vec<Image> = (0..6)
        .map(|f| {
            let mut img = Image::new(s, s, 3);
            for y in 0..s {
                for x in 0..s {
                    let v = 1.0 + f as f32 + 0.01 * (x + y) as f32;
                    img.set(x, y, &[v, v, v]);
                }
            }
            img
        })
        .collect();
    let env = EnvMap::new(ProjectionKind::Cube.default_projection(), faces).unwrap();
    let (mx, median) = seam_stats(&env);
    assert!(mx > 10.0 && median > 10.0, "{mx} {median}");
}
