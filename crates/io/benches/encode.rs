//! Encoder speed: every texel encoding of a 6×512² cube with its mips (city.exr, each level
//! resampled from the lat-long), and the KTX2 writer with Zstandard.
//! `cargo bench -p mirrorball-io --bench encode`.

use criterion::{criterion_group, criterion_main, Criterion};
use mirrorball_core::{resample, Choice, EnvMap, Image, ProjectionKind, ResampleOptions};
use mirrorball_io::{read, write_ktx2, CubeWrite, Encoding};
use std::path::Path;

fn chain(size: u32) -> Vec<Vec<Image>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/env/city.exr");
    let loaded = read(&path, &Default::default()).expect("bundled asset reads");
    let mut env = EnvMap::new(ProjectionKind::LatLong.default_projection(), loaded.layers).unwrap();
    env.sanitize();
    let cube = ProjectionKind::Cube.default_projection();
    (0..=size.ilog2())
        .map(|p| {
            resample(&env, cube, size >> p, &ResampleOptions::default())
                .layers()
                .iter()
                .map(|l| l.with_channels(3))
                .collect()
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let levels = chain(512);
    let mut group = c.benchmark_group("encode 6x512² chain");
    group.sample_size(10);
    let mut buf = Vec::new();
    for e in Encoding::all() {
        group.bench_function(e.name(), |b| {
            b.iter(|| {
                for level in &levels {
                    for face in level {
                        e.encode(face, &mut buf);
                    }
                }
            })
        });
    }
    group.finish();

    let dir = tempfile::tempdir().unwrap();
    let mut group = c.benchmark_group("write_ktx2 6x512² chain");
    group.sample_size(10);
    for (e, zstd) in [
        (Encoding::Rgba16F, None),
        (Encoding::Rgba16F, Some(3)),
        (Encoding::Bc6hUnsigned, None),
        (Encoding::Bc6hUnsigned, Some(3)),
        (Encoding::Bc6hUnsigned, Some(19)),
    ] {
        let how = CubeWrite {
            encoding: e,
            zstd,
            ..CubeWrite::default()
        };
        let path = dir.path().join("cube.ktx2");
        group.bench_function(format!("{} zstd {zstd:?}", e.name()), |b| {
            b.iter(|| write_ktx2(&path, &levels, &how).unwrap())
        });
        let len = std::fs::metadata(&path).unwrap().len();
        println!("{} zstd {zstd:?}: {len} bytes", e.name());
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
