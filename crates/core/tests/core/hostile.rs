//! Projection specs (`--from`, `--to`, `--env-as`, `info`'s records) against hostile text:
//! core's `ProjectionSpec::parse`, the parser the CLI uses, on its seed corpus, mutations of
//! it, and a bolero fuzz target (a coverage-guided campaign: `scripts/fuzz.sh spec`).

#[path = "../../../io/tests/io/mutate.rs"]
mod mutate;

use mutate::{apply_script, mutations};
use std::path::{Path, PathBuf};

fn corpus(sub: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/corpus")
        .join(sub);
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    v.sort();
    v
}

fn check_spec(s: &str) {
    match mirrorball_core::projection::ProjectionSpec::parse(s) {
        Ok(spec) => {
            // Every parsed spec builds or says why not, for no size and a small one.
            for extent in [None, Some((64, 32))] {
                if let Err(e) = spec.build(extent) {
                    assert!(!e.message.is_empty(), "{s}");
                }
            }
        }
        Err(e) => assert!(!e.message.is_empty(), "{s:?}"),
    }
}

#[test]
fn spec_corpus_parses_and_mutations_fail_cleanly() {
    let text = std::fs::read_to_string(&corpus("spec")[0]).unwrap();
    for (k, line) in text.lines().enumerate() {
        let spec = mirrorball_core::projection::ProjectionSpec::parse(line)
            .unwrap_or_else(|e| panic!("{line}: {e}"));
        spec.build(None).unwrap_or_else(|e| panic!("{line}: {e}"));
        for m in mutations(line.as_bytes(), k as u64) {
            check_spec(&String::from_utf8_lossy(&m));
        }
    }
}

#[test]
fn fuzz_spec() {
    let text = std::fs::read_to_string(&corpus("spec")[0]).unwrap();
    let seeds: Vec<&str> = text.lines().collect();
    bolero::check!()
        .with_iterations(2000)
        .for_each(|input: &[u8]| {
            let Some((&pick, script)) = input.split_first() else {
                return;
            };
            let seed = seeds[pick as usize % seeds.len()];
            check_spec(&String::from_utf8_lossy(&apply_script(
                seed.as_bytes(),
                script,
            )));
            // And the raw bytes as a spec.
            check_spec(&String::from_utf8_lossy(input));
        });
}
