//! Conversion quality on the bundled HDRs must not drop: lat-long → projection → lat-long,
//! log-domain PSNR over what the projection covers, at the source's texel budget. The
//! floors are the values recorded in BENCHMARKS.md minus 0.5 dB
//! (`cargo run --release -p mirrorball-cli --example quality` prints them).
use crate::util::asset;
use mirrorball_core::metrics::log_psnr_where;
use mirrorball_core::{
    resample, EnvMap, Outside, ProjectionKind, ResampleOptions, WorldProjection,
};

fn edge_for_budget(kind: ProjectionKind, budget: f64) -> u32 {
    let p = kind.default_projection();
    let (w, h) = p.layer_extent(1024);
    let per = w as f64 * h as f64 * p.layer_count() as f64;
    (1024.0 * (budget / per).sqrt()).round() as u32
}

/// Recorded log-PSNR (dB) at 1× budget: city, venice, studio, sky.
const RECORDED: [(ProjectionKind, [f64; 4]); 19] = [
    (ProjectionKind::Cube, [43.76, 41.30, 39.36, 43.91]),
    (ProjectionKind::Sphere, [40.88, 35.12, 38.93, 42.85]),
    (ProjectionKind::Paraboloid, [43.00, 40.31, 39.89, 43.96]),
    (ProjectionKind::ContinuousCube, [44.82, 42.65, 39.95, 43.66]),
    (ProjectionKind::Mercator, [42.05, 38.93, 38.85, 44.22]),
    (ProjectionKind::Angular, [41.29, 39.25, 38.47, 42.57]),
    (ProjectionKind::Fisheye, [44.93, 41.91, 45.44, 40.97]),
    (ProjectionKind::Octahedral, [44.56, 41.81, 39.12, 43.27]),
    (
        ProjectionKind::EqualAreaOctahedral,
        [44.45, 41.34, 39.11, 43.68],
    ),
    (ProjectionKind::Cylindrical, [45.38, 41.46, 39.36, 51.78]),
    (
        ProjectionKind::CylindricalEqualArea,
        [44.64, 42.02, 39.10, 43.80],
    ),
    (ProjectionKind::HalfEquirect, [45.68, 42.70, 46.27, 40.97]),
    (ProjectionKind::Hammer, [43.51, 41.95, 39.29, 44.30]),
    (ProjectionKind::Sinusoidal, [44.88, 47.24, 41.81, 44.86]),
    (ProjectionKind::Perspective, [40.15, 38.35, 50.74, 42.54]),
    (ProjectionKind::Pannini, [44.27, 39.20, 47.27, 43.15]),
    (ProjectionKind::Eac, [45.05, 42.89, 40.11, 43.60]),
    (ProjectionKind::DualFisheye, [43.90, 42.39, 39.30, 43.44]),
    (ProjectionKind::Tetrahedron, [42.83, 42.08, 38.36, 42.61]),
];

/// Recorded log-PSNR (dB) at 4× budget for the newer projections (measured by this test's
/// own output, opt-level 2): city, venice, studio, sky.
/// A new projection is one row here and one in [`RECORDED`].
const RECORDED_4X: [(ProjectionKind, [f64; 4]); 10] = [
    (ProjectionKind::Cylindrical, [45.71, 42.18, 38.72, 51.48]),
    (
        ProjectionKind::CylindricalEqualArea,
        [46.50, 43.62, 39.72, 43.88],
    ),
    (ProjectionKind::HalfEquirect, [45.65, 42.08, 46.20, 40.98]),
    (ProjectionKind::Hammer, [46.43, 43.58, 40.47, 44.25]),
    (ProjectionKind::Sinusoidal, [46.30, 44.07, 39.42, 44.00]),
    (ProjectionKind::Perspective, [39.80, 38.07, 50.48, 42.29]),
    (ProjectionKind::Pannini, [44.02, 38.83, 47.10, 42.87]),
    (ProjectionKind::Eac, [46.64, 43.77, 39.75, 43.90]),
    (ProjectionKind::DualFisheye, [47.29, 44.05, 39.79, 44.72]),
    (ProjectionKind::Tetrahedron, [46.29, 44.02, 40.24, 43.71]),
];

#[test]
fn round_trip_quality_does_not_drop() {
    for (i, name) in ["city", "venice", "studio", "sky"].iter().enumerate() {
        let loaded =
            mirrorball_io::read(&asset(&format!("{name}.exr")), &Default::default()).unwrap();
        let mut src =
            EnvMap::new(ProjectionKind::LatLong.default_projection(), loaded.layers).unwrap();
        src.sanitize();
        let budget = (src.width() * src.height()) as f64;
        // The identity conversion is exact.
        let same = resample(
            &src,
            *src.projection(),
            src.width(),
            &ResampleOptions::default(),
        );
        assert!(log_psnr_where(&src, &same, |_| true).unwrap() > 120.0);
        let sizes = RECORDED.iter().map(|r| (1.0, r));
        for (times, (kind, floors)) in sizes.chain(RECORDED_4X.iter().map(|r| (4.0, r))) {
            let p = kind.default_projection();
            // The projection's own quality: texels outside a disk or an outline filled from
            // the rim, as for a map a renderer samples, so that reading back near the rim
            // measures the projection, not the black surround a camera's frame has.
            let forward = ResampleOptions {
                outside: Some(Outside::Rim),
                ..ResampleOptions::default()
            };
            let out = resample(&src, p, edge_for_budget(*kind, budget * times), &forward);
            let back = resample(
                &out,
                *src.projection(),
                src.width(),
                &ResampleOptions::default(),
            );
            let psnr = log_psnr_where(&src, &back, |d| p.dir_to_uv(d).is_some()).unwrap();
            eprintln!("{name} via {kind} at {times}×: {psnr:.2} dB");
            assert!(
                psnr >= floors[i] - 0.5,
                "{name} via {kind} at {times}×: {psnr:.2} dB < recorded {:.2}",
                floors[i]
            );
        }
    }
}
