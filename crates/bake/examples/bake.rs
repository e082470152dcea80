//! `cargo run -p mirrorball-bake --example bake -- ENGINE IN.exr OUT-DIR [SIZE [ENCODING
//! [ZSTD]]]`: the library flow end to end (read, prefilter to the engine's spec, write), for
//! tests and benchmarks that need an engine's files made by the library itself. `ENCODING`
//! `-` is the engine's default; `ZSTD` is a Zstandard level.

use mirrorball_bake::{write, BakeOptions, Engine, Lighting};
use mirrorball_core::Choice;
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 3 {
        eprintln!("usage: bake ENGINE IN OUT-DIR [SIZE [ENCODING [ZSTD]]]");
        std::process::exit(2);
    }
    let engine = Engine::parse_name(&args[0]).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(2)
    });
    let encoding = match args.get(4).map(String::as_str) {
        None | Some("-") => None,
        Some(name) => Some(
            mirrorball_io::Encoding::parse_name(name).unwrap_or_else(|e| {
                eprintln!("{e}");
                std::process::exit(2)
            }),
        ),
    };
    let opts = BakeOptions {
        size: args.get(3).and_then(|s| s.parse().ok()).unwrap_or(64),
        encoding,
        zstd: args.get(5).and_then(|s| s.parse().ok()),
        source: args[1].clone(),
        ..Default::default()
    };
    if let Err(e) = engine.check(&opts) {
        eprintln!("{e}");
        std::process::exit(2);
    }
    let loaded =
        mirrorball_io::read(Path::new(&args[1]), &Default::default()).unwrap_or_else(|e| {
            eprintln!("{e}");
            std::process::exit(1)
        });
    let projection = mirrorball_core::ProjectionKind::LatLong.default_projection();
    let mut env = mirrorball_core::EnvMap::new(projection, loaded.layers).unwrap_or_else(|e| {
        eprintln!("{}: {e} (this example reads lat-long maps)", args[1]);
        std::process::exit(1)
    });
    env.sanitize();
    let spec = engine.chain_spec(&opts);
    let lighting = Lighting::from_env(&env, &spec, Default::default());
    let dir = Path::new(&args[2]);
    std::fs::create_dir_all(dir).expect("the output folder");
    match write(engine, &lighting, dir, &opts) {
        Ok(files) => files.iter().for_each(|f| println!("{}", f.display())),
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1)
        }
    }
}
