#!/usr/bin/env bash
# A coverage-guided (libFuzzer) campaign of one of the hostile::fuzz_* bolero targets, on the
# stable toolchain: builds the target's test binary with sanitizer coverage (in
# target/fuzz) and runs libFuzzer on it. See docs/fuzzing.md.
#   scripts/fuzz.sh TARGET [SECONDS]     TARGET: exr hdr png jpeg webp ktx2 dds obj gltf spec
# The corpus grows in target/fuzz/corpus/TARGET; crashes are written to
# target/fuzz/crashes/TARGET/ (save them under the seeds' crashes/ folder with the fix).
# FUZZ_TARGET_DIR moves target/fuzz elsewhere.
set -euo pipefail
cd "$(dirname "$0")/.."
target="${1:?usage: scripts/fuzz.sh TARGET [SECONDS]}"
dir="${FUZZ_TARGET_DIR:-target/fuzz}"
seconds="${2:-1800}"
case "$target" in
    exr|hdr|png|jpeg|webp|ktx2|dds) pkg=mirrorball-io; bin=io ;;
    obj|gltf) pkg=mirrorball-render; bin=render ;;
    spec) pkg=mirrorball-core; bin=core ;;
    scene)
        # A process per input (the `mirrorball` binary reads the scene): libFuzzer would see
        # no coverage, and the instrumented binary does not link without libFuzzer.
        echo "fuzz.sh: the scene target runs the binary per input; use the random engine:" >&2
        echo "  BOLERO_RANDOM_ITERATIONS=100000000 BOLERO_RANDOM_TEST_TIME_MS=1800000 cargo test -p mirrorball-cli --test cli -- hostile::fuzz_scene --exact" >&2
        exit 2 ;;
    *) echo "fuzz.sh: unknown target '$target'" >&2; exit 2 ;;
esac
flags="--cfg fuzzing -Cpasses=sancov-module --cfg fuzzing_libfuzzer \
-Cllvm-args=-sanitizer-coverage-inline-8bit-counters -Cllvm-args=-sanitizer-coverage-level=4 \
-Cllvm-args=-sanitizer-coverage-pc-table -Cllvm-args=-sanitizer-coverage-trace-compares \
-Cllvm-args=-sanitizer-coverage-stack-depth"
host="$(rustc -vV | sed -n 's/^host: //p')"
# Only the one test binary: the crates' own unit tests would not link with these flags.
exe="$(RUSTC_BOOTSTRAP=1 RUSTFLAGS="$flags" cargo test --config 'profile.fuzz.inherits="dev"' \
    --config 'profile.fuzz.opt-level=3' --profile fuzz --target "$host" --target-dir "$dir" \
    -p "$pkg" --test "$bin" --no-run 2>&1 | tee /dev/stderr | sed -n 's/.*Executable .*(\(.*\))$/\1/p' | tail -1)"
corpus="$dir/corpus/$target"
crashes="$dir/crashes/$target/"
mkdir -p "$corpus" "$crashes"
BOLERO_FUZZER=libfuzzer \
BOLERO_LIBFUZZER_ARGS="-max_total_time=$seconds -rss_limit_mb=2048 -malloc_limit_mb=1024 \
-print_final_stats=1 -artifact_prefix=$crashes $corpus" \
    "$exe" "hostile::fuzz_$target" --exact --nocapture --test-threads 1
