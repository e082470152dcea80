//! `cargo run -p mirrorball-bake --example prefiltered -- IN.exr ROUGHNESS X,Y,Z…`: the
//! library's own GGX prefilter of a lat-long map at perceptual `ROUGHNESS`, evaluated about
//! each direction given, printed as a JSON array of `[r, g, b]`: the yardstick the browser
//! tests hold an engine's rendering of rough levels to.

use mirrorball_core::{glam::DVec3, EnvMap, ProjectionKind};
use mirrorball_filter::{Lobe, Prefilterer};
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let fail = |e: String| -> ! {
        eprintln!("{e}");
        std::process::exit(2)
    };
    if args.len() < 3 {
        fail("usage: prefiltered IN ROUGHNESS X,Y,Z…".into());
    }
    let roughness: f64 = args[1]
        .parse()
        .unwrap_or_else(|_| fail(format!("ROUGHNESS: not a number: {}", args[1])));
    let dirs: Vec<DVec3> = args[2..]
        .iter()
        .map(|a| {
            let v: Vec<f64> = a.split(',').filter_map(|c| c.parse().ok()).collect();
            match v[..] {
                [x, y, z] => DVec3::new(x, y, z),
                _ => fail(format!("not a direction X,Y,Z: {a}")),
            }
        })
        .collect();
    let loaded = mirrorball_io::read(Path::new(&args[0]), &Default::default())
        .unwrap_or_else(|e| fail(e.to_string()));
    let projection = ProjectionKind::LatLong.default_projection();
    let mut env = EnvMap::new(projection, loaded.layers).unwrap_or_else(|e| fail(e.to_string()));
    env.sanitize();
    let pre = Prefilterer::new(&env, Default::default());
    let values = pre.eval(&Lobe::Ggx { roughness }, &dirs);
    println!("{}", serde_json::to_string(&values).expect("numbers"));
}
