//! `cargo bench -p mirrorball-filter`: prefiltering a 6×512² cube.
//!
//! The source is the bundled `sky.exr` (a sun holding 60% of the energy: the hard case for
//! importance sampling; `MB_ENV=studio.exr` picks another bundled HDR) resampled to a
//! 6×512² float cube. Timed, each from the cube in
//! memory to the result in memory:
//!
//! * `ggx_chain_6x512`: the whole GGX chain, 10 levels (512² … 1², roughness
//!   `level/9`), preparation (working cube, bright split, pyramid) included;
//! * `sh9_6x512`: nine spherical-harmonic coefficients with exact texel solid angles;
//! * `irradiance_6x32_from_6x512`: an exact (moment hierarchy) 6×32² irradiance map,
//!   preparation included;
//! * `irradiance_sh9_6x32_from_6x512`: the same map from SH9.
//!
//! Accuracy against brute force is measured by `examples/accuracy.rs` (see BENCHMARKS.md).

use criterion::{criterion_group, criterion_main, Criterion};
use mirrorball_core::{resample, EnvMap, ProjectionKind, ResampleOptions};
use mirrorball_filter::irradiance::irradiance_map_sh;
use mirrorball_filter::sh::{project, Window};
use mirrorball_filter::{
    chain_lobes, Lobe, LobeKind, PrefilterOptions, Prefilterer, RoughnessMapping,
};
use std::hint::black_box;

fn source(name: String) -> EnvMap {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/env")
        .join(name);
    let l = mirrorball_io::read(&p, &Default::default()).expect("bundled asset");
    let mut env = EnvMap::new(ProjectionKind::LatLong.default_projection(), l.layers).unwrap();
    env.sanitize();
    resample(
        &env,
        ProjectionKind::Cube.default_projection(),
        512,
        &ResampleOptions::default(),
    )
}

fn bench(c: &mut Criterion) {
    let cube = source(std::env::var("MB_ENV").unwrap_or_else(|_| "sky.exr".into()));
    let out = ProjectionKind::Cube.default_projection();
    let lobes = chain_lobes(LobeKind::Ggx, &RoughnessMapping::Linear, 10);

    let mut g = c.benchmark_group("prefilter");
    g.sample_size(10);
    g.bench_function("ggx_chain_6x512", |b| {
        b.iter(|| {
            let pf = Prefilterer::new(&cube, PrefilterOptions::default());
            black_box(pf.render_chain(&lobes, out, 512))
        })
    });
    g.bench_function("irradiance_6x32_from_6x512", |b| {
        b.iter(|| {
            let pf = Prefilterer::new(&cube, PrefilterOptions::default());
            black_box(pf.render(&Lobe::Lambert, out, 32))
        })
    });
    g.finish();

    let mut g = c.benchmark_group("sh");
    g.sample_size(30);
    g.bench_function("sh9_6x512", |b| b.iter(|| black_box(project(&cube))));
    g.bench_function("irradiance_sh9_6x32_from_6x512", |b| {
        b.iter(|| black_box(irradiance_map_sh(&project(&cube), Window::None, out, 32)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
