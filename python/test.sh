#!/usr/bin/env bash
# Builds the Python package from this checkout and runs its tests:
#   python/test.sh            # a venv at python/.venv (or $MIRRORBALL_VENV), pinned requirements
# The venv is made from python/requirements-dev.txt (pip, from PyPI), the package built and
# installed with maturin (a debug build unless MIRRORBALL_PY_RELEASE=1, into $CARGO_TARGET_DIR if set), the CLI built for
# the byte-for-byte tests (MIRRORBALL_BIN, else $CARGO_TARGET_DIR/debug/mirrorball), then
# pytest runs python/tests. Extra arguments go to pytest.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/.." && pwd)"
venv="${MIRRORBALL_VENV:-$here/.venv}"
python="${PYTHON:-python3}"
if [ ! -x "$venv/bin/python" ]; then
    "$python" -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --upgrade pip
"$venv/bin/python" -m pip install --quiet -r "$here/requirements-dev.txt"
target="${CARGO_TARGET_DIR:-$root/target}"
export CARGO_TARGET_DIR="$target"
if [ -z "${MIRRORBALL_BIN:-}" ]; then
    cargo build --quiet -p mirrorball-cli --manifest-path "$root/Cargo.toml"
    export MIRRORBALL_BIN="$target/debug/mirrorball"
fi
# A debug build by default (it shares the workspace's debug artifacts, so after `cargo test`
# only PyO3 and this crate compile); MIRRORBALL_PY_RELEASE=1 for an optimised one (benches).
profile=()
[ "${MIRRORBALL_PY_RELEASE:-0}" = 1 ] && profile=(--release)
(cd "$here" && VIRTUAL_ENV="$venv" PATH="$venv/bin:$PATH" "$venv/bin/maturin" develop "${profile[@]}" --quiet)
cd "$here"
exec "$venv/bin/python" -m pytest -q "$@"
