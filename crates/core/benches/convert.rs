//! `cargo bench -p mirrorball-core`: conversion throughput in memory.
//!
//! The headline case of BENCHMARKS.md: a 4096×2048 float RGB lat-long to a 6×1024² cube and
//! back. The source is a synthetic environment with detail at every scale (the bench/
//! scripts run the same conversion on a real HDR beside OpenCV).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use mirrorball_core::{resample, Codes, EnvMap, Plane, ProjectionKind, Remap, ResampleOptions};
use std::hint::black_box;

fn source() -> EnvMap {
    EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), 4096, 3, |d| {
        let v = 1.0 + (40.0 * d.x).sin() * (30.0 * d.y).cos() + (d.z * 200.0).sin().abs();
        [v as f32, (2.0 * v) as f32, (1.0 + d.y) as f32, 1.0]
    })
}

fn bench(c: &mut Criterion) {
    let src = source();
    let cube = ProjectionKind::Cube.default_projection();
    let latlong = ProjectionKind::LatLong.default_projection();
    let opts = ResampleOptions::default();
    let mut g = c.benchmark_group("latlong4096_cube1024");
    g.sample_size(10);
    g.throughput(Throughput::Elements(6 * 1024 * 1024));
    g.bench_function("forward", |b| {
        b.iter(|| black_box(resample(&src, cube, 1024, &opts)))
    });
    let faces = resample(&src, cube, 1024, &opts);
    g.throughput(Throughput::Elements(4096 * 2048));
    g.bench_function("back", |b| {
        b.iter(|| black_box(resample(&faces, latlong, 4096, &opts)))
    });
    g.finish();

    // Planned once (like cv2.remap's precomputed maps; planning not timed), applied into a
    // reused output and into a new one.
    let fwd = Remap::new(latlong, (4096, 2048), 1, cube, 1024, &opts);
    let back = Remap::new(cube, (1024, 1024), 6, latlong, 4096, &opts);
    let mut g = c.benchmark_group("latlong4096_cube1024_planned");
    g.sample_size(20);
    g.throughput(Throughput::Elements(6 * 1024 * 1024));
    let mut out = fwd.apply(&src).expect("plan fits");
    g.bench_function("forward_into", |b| {
        b.iter(|| fwd.apply_into(&src, &mut out).expect("plan fits"))
    });
    g.bench_function("forward_new", |b| {
        b.iter(|| black_box(fwd.apply(&src).expect("plan fits")))
    });
    // A raw video frame as it arrives, 8- and 16-bit codes read through a table of linear
    // values (`Remap::rows_coded`, as `convert - -` reads a pipe's frames).
    let narrow: Vec<u8> = (0..4096 * 2048 * 3).map(|i| (i * 7 % 251) as u8).collect();
    let wide: Vec<u8> = (0..4096 * 2048 * 6).map(|i| (i * 13 % 253) as u8).collect();
    let t8: Vec<f32> = (0..256).map(|k| (k as f32 / 255.0).powf(2.2)).collect();
    let t16: Vec<f32> = (0..65536).map(|k| (k as f32 / 65535.0).powf(2.2)).collect();
    for (name, codes) in [
        ("forward_codes8_into", Codes::u8(&narrow, &t8, (4096, 2048))),
        (
            "forward_codes16_into",
            Codes::u16le(&wide, &t16, (4096, 2048)),
        ),
    ] {
        let codes = codes.expect("codes of the frame's size");
        g.bench_function(name, |b| {
            b.iter(|| {
                let rows = fwd.rows_coded(codes).expect("plan takes codes");
                rows.fill(&mut out).expect("plan fits")
            })
        });
    }
    // One plane of a YUV frame (a video's Y): one channel of floats, and its 8-bit codes
    // read as they are (`Remap::rows_plane`).
    let luma: Vec<u8> = (0..4096 * 2048).map(|i| (i * 7 % 251) as u8).collect();
    let plane = Plane::u8(&luma, 16.0, (4096, 2048)).expect("a plane of the frame's size");
    let one = EnvMap::new(latlong, vec![plane.to_image()]).expect("one layer");
    let mut out1 = fwd.apply(&one).expect("plan fits");
    g.bench_function("forward_1ch_into", |b| {
        b.iter(|| fwd.apply_into(&one, &mut out1).expect("plan fits"))
    });
    g.bench_function("forward_plane8_into", |b| {
        b.iter(|| {
            let rows = fwd.rows_plane(plane).expect("plan takes codes");
            rows.fill(&mut out1).expect("plan fits")
        })
    });
    g.throughput(Throughput::Elements(4096 * 2048));
    let mut ll = back.apply(&faces).expect("plan fits");
    g.bench_function("back_into", |b| {
        b.iter(|| back.apply_into(&faces, &mut ll).expect("plan fits"))
    });
    g.finish();

    let mut g = c.benchmark_group("every_projection_from_latlong4096");
    g.sample_size(10);
    for kind in ProjectionKind::ALL {
        let p = kind.default_projection();
        let size = match kind {
            ProjectionKind::LatLong | ProjectionKind::Mercator => 2048,
            ProjectionKind::Cube | ProjectionKind::ContinuousCube => 512,
            _ => 1024,
        };
        g.bench_function(kind.name(), |b| {
            b.iter(|| black_box(resample(&src, p, size, &opts)))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
