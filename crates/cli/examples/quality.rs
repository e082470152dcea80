//! Round-trip quality table for BENCHMARKS.md:
//! `cargo run --release -p mirrorball-cli --example quality`.
//!
//! For each bundled HDR and each projection: lat-long (512×256) → projection → lat-long
//! (512×256), log-domain PSNR over the directions the projection covers, at two sizes: the
//! same texel budget as the source (131,072 texels), and four times that.
use mirrorball_core::metrics::log_psnr_where;
use mirrorball_core::{
    resample, EnvMap, Outside, ProjectionKind, ResampleOptions, WorldProjection,
};

/// Edge giving about `budget` texels in total.
fn edge_for_budget(kind: ProjectionKind, budget: f64) -> u32 {
    let p = kind.default_projection();
    let (w, h) = p.layer_extent(1024);
    let per = w as f64 * h as f64 * p.layer_count() as f64;
    (1024.0 * (budget / per).sqrt()).round() as u32
}

fn main() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/env");
    println!("| environment | projection | size (1×) | log-PSNR 1× (dB) | size (4×) | log-PSNR 4× (dB) |");
    println!("| --- | --- | --- | --- | --- | --- |");
    for name in ["city", "venice", "studio", "sky"] {
        let path = std::path::PathBuf::from(format!("{dir}/{name}.exr"));
        let loaded = mirrorball_io::read(&path, &Default::default()).expect("bundled asset");
        let mut src =
            EnvMap::new(ProjectionKind::LatLong.default_projection(), loaded.layers).unwrap();
        src.sanitize();
        let budget = (src.width() * src.height()) as f64;
        for kind in ProjectionKind::ALL {
            let p = kind.default_projection();
            let mut cells = Vec::new();
            for k in [1.0, 4.0] {
                let e = edge_for_budget(kind, budget * k);
                // Outside a disk or an outline: the rim's value (the test's rule).
                let forward = ResampleOptions {
                    outside: Some(Outside::Rim),
                    ..ResampleOptions::default()
                };
                let out = resample(&src, p, e, &forward);
                let back = resample(
                    &out,
                    *src.projection(),
                    src.width(),
                    &ResampleOptions::default(),
                );
                let psnr = log_psnr_where(&src, &back, |d| p.dir_to_uv(d).is_some()).unwrap();
                let (w, h) = (out.width(), out.height());
                cells.push(format!("{}×{}×{}", out.layers().len(), w, h));
                cells.push(format!("{psnr:.2}"));
            }
            println!("| {name} | {} | {} |", kind.name(), cells.join(" | "));
        }
    }
}
