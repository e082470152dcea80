#!/usr/bin/env python3
"""How honest the progress bars are: a bar's pace and its time left, measured.

    python3 bench/progress_eta.py [--sizes 4096,8192] [--no-build] [--engines bevy,unity]

Standard library only.

1. Builds the release binary (`cargo build --release -p mirrorball-cli`; skip with
   --no-build).
2. Makes the inputs with mirrorball itself: bench/data/sky-W.exr (git-ignored) is
   assets/env/sky.exr upsampled to a W×W/2 float lat-long, remade only when missing.
3. Runs `mirrorball bake bench/data/sky-W.exr --for ENGINE OUT --size 1024 -q` with
   MIRRORBALL_PROGRESS_LOG set, so that the bar (drawn or not) records `label seconds
   position total` every 50 ms (crates/cli/src/progress.rs).
4. For each run prints the bar's time (from its first to its last line) and, at 10 %,
   20 % and 50 % of the bar, the time left a bar would show (elapsed × (total − position)
   / position, what a steady rate gives) against the time the bar really took from there,
   and their ratio. The target: after 20 % of the work, within 25 % of the truth.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

BENCH = Path(__file__).resolve().parent
REPO = BENCH.parent
DATA = BENCH / "data"
BIN = REPO / "target" / "release" / "mirrorball"


def sh(cmd: list[str], **kw) -> None:
    subprocess.run(cmd, check=True, **kw)


def make_input(width: int) -> Path:
    DATA.mkdir(exist_ok=True)
    out = DATA / f"sky-{width}.exr"
    if not out.exists():
        sh([str(BIN), "convert", str(REPO / "assets" / "env" / "sky.exr"), str(out),
            "--to", "latlong", "--size", str(width), "--precision", "float", "-q"])
    return out


def bar(log: Path, label: str) -> list[tuple[float, int, int]]:
    rows = []
    for line in log.read_text().splitlines():
        parts = line.split()
        if len(parts) == 4 and parts[0] == label:
            rows.append((float(parts[1]), int(parts[2]), int(parts[3])))
    return rows


def eta_at(rows: list[tuple[float, int, int]], share: float) -> tuple[float, float]:
    """The time left a steady rate gives when the bar first reaches `share`, and the truth."""
    end = rows[-1][0]
    for t, pos, total in rows:
        if total and pos >= share * total and pos > 0:
            return t * (total - pos) / pos, end - t
    return float("nan"), float("nan")


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", default="4096,8192")
    ap.add_argument("--engines", default="bevy,unity")
    ap.add_argument("--bake-size", default="1024")
    ap.add_argument("--no-build", action="store_true")
    ap.add_argument("--pace", action="store_true", help="print the bar's pace in each tenth")
    args = ap.parse_args()
    if not args.no_build:
        sh(["cargo", "build", "--release", "-p", "mirrorball-cli"], cwd=REPO)
    print(f"{'input':>12} {'engine':>7} {'bar s':>7}  {'at':>4} {'shown left':>10} "
          f"{'true left':>9} {'ratio':>6}")
    worst_after_20 = 0.0
    for width in [int(s) for s in args.sizes.split(",")]:
        src = make_input(width)
        for engine in args.engines.split(","):
            with tempfile.TemporaryDirectory() as tmp:
                log = Path(tmp) / "progress.log"
                env = dict(os.environ, MIRRORBALL_PROGRESS_LOG=str(log))
                sh([str(BIN), "bake", str(src), "--for", engine, str(Path(tmp) / "out"),
                    "--size", args.bake_size, "-q"], env=env)
                rows = bar(log, "baking")
                if not rows:
                    print(f"{width:>12} {engine:>7}: no bar recorded", file=sys.stderr)
                    continue
                if args.pace:
                    # The bar's pace in each tenth of it, in units a second: even when every
                    # step is weighted by its cost.
                    marks = [next((t for t, p, n in rows if p >= k / 10 * n), rows[-1][0])
                             for k in range(11)]
                    paces = [(rows[0][2] / 10) / max(b - a, 1e-3) / 1e9
                             for a, b in zip(marks, marks[1:])]
                    print("   pace (units/ns) per tenth: " + " ".join(f"{p:.2f}" for p in paces))
                for share in (0.1, 0.2, 0.5):
                    shown, true = eta_at(rows, share)
                    ratio = shown / true if true > 0 else float("nan")
                    if share >= 0.2:
                        worst_after_20 = max(worst_after_20, abs(ratio - 1))
                    print(f"{width}x{width // 2:>5} {engine:>7} {rows[-1][0]:>7.2f}  "
                          f"{int(share * 100):>3}% {shown:>10.2f} {true:>9.2f} {ratio:>6.2f}")
    print(f"worst error of the time left after 20 %: {100 * worst_after_20:.0f} % "
          f"(target: within 25 %)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
