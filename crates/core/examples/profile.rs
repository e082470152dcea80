//! A small, deterministic workload for `valgrind --tool=callgrind` (instruction counts do not
//! depend on what else the machine is doing):
//! `cargo build --release -p mirrorball-core --example profile &&
//!  RAYON_NUM_THREADS=1 valgrind --tool=callgrind target/release/examples/profile forward`.
use mirrorball_core::{resample, EnvMap, ProjectionKind, ResampleOptions};

fn main() {
    let which = std::env::args().nth(1).unwrap_or_else(|| "both".into());
    let size: u32 = std::env::args()
        .nth(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1024);
    let src = EnvMap::from_fn(ProjectionKind::LatLong.default_projection(), size, 3, |d| {
        [
            (1.0 + d.x) as f32,
            (1.0 + d.y) as f32,
            (1.0 + d.z) as f32,
            1.0,
        ]
    });
    let cube_p = ProjectionKind::Cube.default_projection();
    let opts = ResampleOptions::default();
    let cube = EnvMap::from_fn(cube_p, size / 4, 3, |d| [(1.0 + d.x) as f32, 1.0, 1.0, 1.0]);
    if which == "none" {
        return;
    }
    if which == "remap" {
        // The planned conversion: compare counts with MB_REPS=0 and MB_REPS=5.
        let reps: usize = std::env::var("MB_REPS")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(5);
        let plan = mirrorball_core::Remap::new(
            *src.projection(),
            (src.width(), src.height()),
            1,
            cube_p,
            size / 4,
            &opts,
        );
        let mut out = plan.apply(&src).expect("plan fits");
        for _ in 0..reps {
            plan.apply_into(&src, &mut out).expect("plan fits");
        }
        std::hint::black_box(out);
        return;
    }
    if which != "back" {
        for _ in 0..5 {
            std::hint::black_box(resample(&src, cube_p, size / 4, &opts));
        }
    }
    if which != "forward" {
        for _ in 0..5 {
            std::hint::black_box(resample(&cube, *src.projection(), size, &opts));
        }
    }
}
