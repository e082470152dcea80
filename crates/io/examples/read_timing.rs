//! Times reading an image file: `cargo run --release -p mirrorball-io --example read_timing -- FILE [REPS]`.
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let Some(path) = args.next() else {
        eprintln!("usage: read_timing FILE [REPS=3]");
        std::process::exit(2);
    };
    let reps: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(3);
    for _ in 0..reps {
        let t = Instant::now();
        match mirrorball_io::read(
            std::path::Path::new(&path),
            &mirrorball_io::Limits::default(),
        ) {
            Ok(l) => println!(
                "{:.3}s  {}  {}x{}",
                t.elapsed().as_secs_f64(),
                l.description,
                l.layers[0].width(),
                l.layers[0].height()
            ),
            Err(e) => {
                eprintln!("{e}");
                std::process::exit(1);
            }
        }
    }
}
