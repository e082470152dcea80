#!/usr/bin/env python3
"""mirrorball vs. its peers, side by side in one run: lat-long ↔ cube conversion.

    bash bench/setup.sh && bench/.venv/bin/python bench/convert_peers.py

1. Builds the mirrorball CLI and the `bench_convert` example (cargo build --release).
2. Makes the inputs: 4096×2048 float ZIP lat-long EXRs upsampled by mirrorball from the
   bundled 512×256 assets/env/city.exr (and sky.exr) into bench/data/ (git-ignored).
3. In memory: lat-long 4096×2048 → cube 6×1024² (forward) and back to lat-long 4096×2048,
   best of --reps each, file reading not timed; mirrorball (the example) against cv2.remap
   with precomputed maps (float32 maps, and OpenCV's 16-bit fixed-point maps) and
   py360convert (e2c / c2e). Round-trip quality for every method with the same log-domain
   PSNR as mirrorball_core::metrics::log_psnr (peerlib.log_psnr, checked against mirrorball
   in the run).
4. End to end, file to file, as a user runs it: `mirrorball convert … --to cube` against
   Python scripts (interpreter start-up and imports included), best of --e2e-reps wall time.
5. Prints the tables and writes bench/results/convert.json.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import platform
import statistics
import shutil
import subprocess
import sys
import time
from pathlib import Path

BENCH = Path(__file__).resolve().parent
REPO = BENCH.parent
sys.path.insert(0, str(BENCH))

import numpy as np  # noqa: E402

import peerlib  # noqa: E402

DATA = BENCH / "data"
RESULTS = BENCH / "results"
MIRRORBALL = REPO / "target" / "release" / "mirrorball"
EXAMPLE = REPO / "target" / "release" / "examples" / "bench_convert"

WIDTH, HEIGHT, FACE = 4096, 2048, 1024
INPUTS = {"city": "assets/env/city.exr", "sky": "assets/env/sky.exr"}


# --------------------------------------------------------------------------------------
# small utilities


def log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def run(cmd: list[str], **kw) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, cwd=REPO, check=True, **kw)


def rustc_count() -> int:
    """How many rustc processes (other people's compiles) are running right now."""
    if shutil.which("pgrep") is None:
        return -1
    r = subprocess.run(["pgrep", "-c", "rustc"], capture_output=True, text=True)
    try:
        return int(r.stdout.strip() or 0)
    except ValueError:
        return -1


def cpu_busy(seconds: float = 3.0) -> float:
    """Share (0..1) of all CPUs busy over `seconds` while this process sleeps: the load
    others put on the machine (from /proc/stat; -1 where unavailable)."""

    def snap():
        with open("/proc/stat") as f:
            v = [int(x) for x in f.readline().split()[1:]]
        idle = v[3] + (v[4] if len(v) > 4 else 0)
        return sum(v), idle

    try:
        t0, i0 = snap()
        time.sleep(seconds)
        t1, i1 = snap()
    except OSError:
        return -1.0
    return 1.0 - (i1 - i0) / max(t1 - t0, 1)


class Load:
    """Samples other compiles and the load average around each measurement."""

    def __init__(self) -> None:
        self.samples: list[dict] = []

    def sample(self, where: str) -> None:
        self.samples.append(
            {"where": where, "rustc": rustc_count(), "loadavg_1m": round(os.getloadavg()[0], 2)}
        )

    def max_rustc(self) -> int:
        return max((s["rustc"] for s in self.samples), default=0)


def best_of(fn, reps: int):
    best, out = float("inf"), None
    for _ in range(reps):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def cpu_model() -> str:
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def git_describe() -> str:
    try:
        rev = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], cwd=REPO, capture_output=True, text=True
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no"],
            cwd=REPO,
            capture_output=True,
            text=True,
        ).stdout.strip()
        return rev + ("-dirty" if dirty else "")
    except OSError:
        return "unknown"


# --------------------------------------------------------------------------------------
# steps


def build() -> None:
    log("building: cargo build --release -p mirrorball-cli --bin mirrorball --example bench_convert")
    run(
        [
            "cargo", "build", "--release", "-p", "mirrorball-cli",
            "--bin", "mirrorball", "--example", "bench_convert",
        ]
    )


def make_input(name: str, remake: bool) -> Path:
    src = REPO / INPUTS[name]
    dst = DATA / f"{name}-4k.exr"
    if remake or not dst.exists() or dst.stat().st_mtime < src.stat().st_mtime:
        DATA.mkdir(parents=True, exist_ok=True)
        log(f"making {dst.relative_to(REPO)} from {INPUTS[name]} with mirrorball")
        run(
            [
                str(MIRRORBALL), "convert", str(src), str(dst), "--to", "latlong",
                "--size", str(WIDTH), "--precision", "float", "--compression", "zip", "-q",
            ]
        )
    return dst


def in_memory(path: Path, reps: int, load: Load) -> dict:
    import cv2
    import numpy as np
    import py360convert

    res: dict[str, dict] = {}

    # mirrorball: the cargo example, its own process (reads the EXR, times resample()); once
    # with the default options and once with plain bilinear lookups (max_samples = 1), the
    # same filter as the peers, for information.
    for name, extra, note in (
        ("mirrorball resample", [],
         "mirrorball_core::resample, default options (antialiased: integrates output texels "
         "whose footprint covers > 2.25 source texels)"),
        ("mirrorball, bilinear only", ["1"],
         "ResampleOptions { max_samples: 1 }: one bilinear lookup per texel, like the peers"),
    ):
        load.sample(f"{path.name}: {name} start")
        out = run([str(EXAMPLE), str(path), str(reps), str(FACE), str(WIDTH), *extra],
                  capture_output=True, text=True).stdout
        mb = json.loads(out.strip().splitlines()[-1])
        # The same filter planned once (mirrorball_core::Remap), like cv2's precomputed
        # maps: into a new output each call, and into a reused one.
        kind = "bilinear " if extra else ""
        what = "plain bilinear (max_samples = 1), the peers' filter" if extra else \
            "the default (antialiased) filter"
        for pname, fk, bk, pnote in (
            (f"mirrorball Remap {kind}(plan precomputed)", "plan_forward_s", "plan_back_s",
             f"mirrorball_core::Remap, {what}, planned once, untimed; new output each call"),
            (f"mirrorball Remap {kind}into reused output", "plan_into_forward_s",
             "plan_into_back_s",
             "Remap::apply_into: as above, output memory reused (as cv2.remap(dst=...))"),
        ):
            res[pname] = {
                "forward_s": mb[fk],
                "back_s": mb[bk],
                "forward_texels_per_s": mb["forward_texels"] / mb[fk],
                "back_texels_per_s": mb["back_texels"] / mb[bk],
                "roundtrip_log_psnr_db": mb["plan_roundtrip_log_psnr_db"],
                "threads": mb["threads"],
                "max_samples": mb.get("max_samples"),
                "map_build_s_untimed": mb["plan_build_s"],
                "plan_bytes": mb["plan_bytes"],
                "note": pnote,
            }
        res[name] = {
            "forward_s": mb["forward_s"],
            "back_s": mb["back_s"],
            "forward_texels_per_s": mb["forward_texels_per_s"],
            "back_texels_per_s": mb["back_texels_per_s"],
            "roundtrip_log_psnr_db": mb["roundtrip_log_psnr_db"],
            "threads": mb["threads"],
            "max_samples": mb.get("max_samples"),
            "note": note,
        }
    load.sample(f"{path.name}: mirrorball in-memory end")

    img = peerlib.read_exr_rgb(str(path))
    h, w = img.shape[:2]
    assert (w, h) == (WIDTH, HEIGHT), (w, h)
    fwd_texels, back_texels = 6 * FACE * FACE, WIDTH * HEIGHT

    # Maps are precomputed and not timed (reported for information).
    t = time.perf_counter()
    fx, fy = peerlib.cube_from_latlong_maps(FACE, WIDTH, HEIGHT)
    bx, by = peerlib.latlong_from_cube_maps(FACE, WIDTH, HEIGHT)
    maps_s = time.perf_counter() - t
    t = time.perf_counter()
    fm1, fm2 = cv2.convertMaps(fx, fy, cv2.CV_16SC2)
    bm1, bm2 = cv2.convertMaps(bx, by, cv2.CV_16SC2)
    fixed_s = time.perf_counter() - t

    def record(name, fwd, back, note, extra=None):
        (tf, cube), (tb, ll) = fwd, back
        r = {
            "forward_s": tf,
            "back_s": tb,
            "forward_texels_per_s": fwd_texels / tf,
            "back_texels_per_s": back_texels / tb,
            "roundtrip_log_psnr_db": peerlib.log_psnr(img, ll),
            "threads": cv2.getNumThreads(),
            "note": note,
        }
        r.update(extra or {})
        res[name] = r

    load.sample(f"{path.name}: peers in-memory start")
    fwd = best_of(lambda: cv2.remap(img, fx, fy, cv2.INTER_LINEAR, borderMode=cv2.BORDER_WRAP), reps)
    back = best_of(
        lambda: cv2.remap(fwd[1], bx, by, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE), reps
    )
    record("cv2.remap float32 maps", fwd, back,
           "INTER_LINEAR; BORDER_WRAP (longitude) / per-face clamp; maps precomputed, untimed",
           {"map_build_s_untimed": maps_s})

    # The same, writing into preallocated outputs (no page faults of fresh memory).
    fdst = np.empty_like(fwd[1])
    bdst = np.empty_like(back[1])
    fwd_d = best_of(lambda: cv2.remap(img, fx, fy, cv2.INTER_LINEAR, dst=fdst,
                                      borderMode=cv2.BORDER_WRAP), reps)
    back_d = best_of(lambda: cv2.remap(fwd[1], bx, by, cv2.INTER_LINEAR, dst=bdst,
                                       borderMode=cv2.BORDER_REPLICATE), reps)
    record("cv2.remap float32 maps, reused output", fwd_d, back_d,
           "as above with dst= a preallocated array",
           {"map_build_s_untimed": maps_s})

    fwd = best_of(lambda: cv2.remap(img, fm1, fm2, cv2.INTER_LINEAR, borderMode=cv2.BORDER_WRAP), reps)
    back = best_of(
        lambda: cv2.remap(fwd[1], bm1, bm2, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE), reps
    )
    record("cv2.remap fixed-point maps", fwd, back,
           "same maps after cv2.convertMaps(CV_16SC2): 1/32-texel positions",
           {"map_build_s_untimed": maps_s + fixed_s})

    # py360convert caches its samplers (lru_cache) after the first call, so best-of-N
    # leaves out its map building, as for cv2.remap.
    fwd = best_of(lambda: py360convert.e2c(img, face_w=FACE, mode="bilinear", cube_format="list"), reps)
    back = best_of(
        lambda: py360convert.c2e(fwd[1], h=HEIGHT, w=WIDTH, mode="bilinear", cube_format="list"), reps
    )
    record("py360convert e2c/c2e", fwd, back,
           "mode=bilinear, cube_format=list; own cube convention; samplers cached after the "
           "first call; samples with cv2.remap (fixed-point maps) per channel")
    load.sample(f"{path.name}: peers in-memory end")

    for r in res.values():
        r["forward_ratio_vs_mirrorball"] = r["forward_s"] / res["mirrorball resample"]["forward_s"]
        r["back_ratio_vs_mirrorball"] = r["back_s"] / res["mirrorball resample"]["back_s"]
    return res


def mirrorball_e2e_command(exe: Path, path: Path, out: Path) -> list[str]:
    return [
        str(exe), "convert", str(path), str(out / "cube_{face}.exr"),
        "--to", "cube", "--size", str(FACE), "--layout", "separate",
        "--precision", "float", "--compression", "none", "-q",
    ]


def end_to_end(path: Path, reps: int, load: Load, extra: dict[str, Path]) -> dict:
    py = sys.executable
    out = DATA / "e2e"
    methods = {
        "mirrorball convert (CLI)": mirrorball_e2e_command(MIRRORBALL, path, out / "mirrorball"),
        # Other builds of mirrorball (--e2e-also), in the same rounds: before/after a change.
        **{
            f"mirrorball {name}": mirrorball_e2e_command(exe, path, out / f"mirrorball-{name}")
            for name, exe in extra.items()
        },
        "python cv2.remap": [py, str(BENCH / "e2e_cv2_remap.py"), str(path), str(out / "cv2"), str(FACE)],
        "python py360convert": [
            py, str(BENCH / "e2e_py360convert.py"), str(path), str(out / "py360convert"), str(FACE)
        ],
    }
    for m in ["mirrorball", *(f"mirrorball-{name}" for name in extra)]:
        (out / m).mkdir(parents=True, exist_ok=True)
    times: dict[str, list[float]] = {m: [] for m in methods}
    # One untimed warm-up each (page cache, .pyc files), then rounds that take the methods
    # in turn, so a burst of background load hits them alike.
    for m, cmd in methods.items():
        run(cmd, stdout=subprocess.DEVNULL)
    load.sample("end-to-end start")
    for _ in range(reps):
        for m, cmd in methods.items():
            t = time.perf_counter()
            run(cmd, stdout=subprocess.DEVNULL)
            times[m].append(time.perf_counter() - t)
    load.sample("end-to-end end")
    mb = min(times["mirrorball convert (CLI)"])
    mb_median = statistics.median(times["mirrorball convert (CLI)"])
    return {
        m: {
            "best_wall_s": min(ts),
            "median_wall_s": statistics.median(ts),
            "runs_s": ts,
            "ratio_peer_over_mirrorball": min(ts) / mb,
            # Medians too: this machine's speed drifts between runs, and a best-of-N ratio
            # moves with whichever side had the luckier run.
            "median_ratio_peer_over_mirrorball": statistics.median(ts) / mb_median,
            "command": " ".join(os.path.relpath(c, REPO) if c.startswith(str(REPO)) else c
                                for c in methods[m]),
        }
        for m, ts in times.items()
    }


def checks(path: Path, mb_psnr: float | None) -> dict:
    """Cross-checks: (1) peerlib.log_psnr against mirrorball's own metric on mirrorball's
    round trip through files; (2) cv2.remap's cube faces against mirrorball's, which use the
    same OpenGL convention."""
    out = DATA / "e2e"
    back = DATA / "check_mirrorball_back.exr"
    run([str(MIRRORBALL), "convert", str(out / "mirrorball" / "cube_{face}.exr"), str(back),
         "--to", "latlong", "--size", str(WIDTH), "--precision", "float", "--compression", "none", "-q"])
    ref = peerlib.read_exr_rgb(str(path))
    numpy_psnr = peerlib.log_psnr(ref, peerlib.read_exr_rgb(str(back)))
    diffs = {}
    for name in peerlib.FACE_NAMES:
        a = peerlib.read_exr_rgb(str(out / "mirrorball" / f"cube_{name}.exr"))
        b = np.load(out / "cv2" / f"{name}.npy")
        diffs[name] = float(np.mean(np.abs(np.log1p(np.fmax(a, 0)) - np.log1p(np.fmax(b, 0)))))
    return {
        "metric": {
            "numpy_log_psnr_of_mirrorball_cli_roundtrip_db": numpy_psnr,
            "mirrorball_example_log_psnr_db": mb_psnr,
            "note": "mirrorball CLI cube files converted back by the CLI (float EXR), scored "
            "with peerlib.log_psnr; should equal the example's value",
        },
        "cube_faces_mean_abs_log_diff_mirrorball_vs_cv2": diffs,
    }


# --------------------------------------------------------------------------------------
# printing


def finite_or_none(x):
    """JSON has no infinity: an exact round trip is written as null."""
    if isinstance(x, dict):
        return {k: finite_or_none(v) for k, v in x.items()}
    if isinstance(x, list):
        return [finite_or_none(v) for v in x]
    if isinstance(x, float) and not np.isfinite(x):
        return None
    return x


def fmt_psnr(p) -> str:
    return "   exact" if p is None or p == float("inf") else f"{p:8.2f}"


def print_in_memory(name: str, res: dict, reps: int) -> None:
    print(f"\nIn memory, {name}: lat-long {WIDTH}x{HEIGHT} float RGB -> cube 6x{FACE}^2 -> "
          f"lat-long {WIDTH}x{HEIGHT} (best of {reps}; file reading not timed)")
    hdr = (f"{'method':<46} {'fwd s':>7} {'back s':>7} {'fwd Mtex/s':>10} {'back Mtex/s':>11} "
           f"{'fwd ratio':>9} {'back ratio':>10} {'log-PSNR dB':>11}")
    print(hdr)
    print("-" * len(hdr))
    for m, r in res.items():
        print(f"{m:<46} {r['forward_s']:7.4f} {r['back_s']:7.4f} "
              f"{r['forward_texels_per_s'] / 1e6:10.1f} {r['back_texels_per_s'] / 1e6:11.1f} "
              f"{r['forward_ratio_vs_mirrorball']:9.2f} {r['back_ratio_vs_mirrorball']:10.2f} "
              f"{fmt_psnr(r['roundtrip_log_psnr_db']):>11}")
    print("ratio = method time / mirrorball time (> 1: mirrorball faster); texels = output texels; "
          "log-PSNR: round trip vs input")
    pairs = (
        ("precomputed, new output", "cv2.remap float32 maps", "mirrorball Remap (plan precomputed)"),
        ("precomputed, reused output", "cv2.remap float32 maps, reused output",
         "mirrorball Remap into reused output"),
        ("same filter, new output", "cv2.remap float32 maps",
         "mirrorball Remap bilinear (plan precomputed)"),
        ("same filter, reused output", "cv2.remap float32 maps, reused output",
         "mirrorball Remap bilinear into reused output"),
        ("mirrorball on the fly", "cv2.remap float32 maps", "mirrorball resample"),
    )
    print("Throughput against cv2.remap (issue 2's target: forward >= 1.5x):")
    for label, peer, mine in pairs:
        if peer in res and mine in res:
            p, q = res[peer], res[mine]
            print(f"  {label:<28} forward {p['forward_s'] / q['forward_s']:5.2f}x  "
                  f"back {p['back_s'] / q['back_s']:5.2f}x  "
                  f"(log-PSNR {fmt_psnr(q['roundtrip_log_psnr_db'])} vs "
                  f"{fmt_psnr(p['roundtrip_log_psnr_db'])} dB)")


def print_e2e(path: Path, res: dict, reps: int) -> None:
    print(f"\nEnd to end, {path.name} (float ZIP EXR) -> six 1024^2 float faces, whole process "
          f"wall time, best of {reps}")
    hdr = (f"{'method':<28} {'best wall s':>11} {'ratio (peer/mirrorball)':>24} "
           f"{'median s':>9} {'median ratio':>12}   runs s")
    print(hdr)
    print("-" * len(hdr))
    for m, r in res.items():
        runs = " ".join(f"{t:.2f}" for t in r["runs_s"])
        print(f"{m:<28} {r['best_wall_s']:11.3f} {r['ratio_peer_over_mirrorball']:24.2f} "
              f"{r['median_wall_s']:9.3f} {r['median_ratio_peer_over_mirrorball']:12.2f}   {runs}")
    print("mirrorball writes uncompressed float EXRs; the Python scripts write raw float32 .npy")


# --------------------------------------------------------------------------------------


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--reps", type=int, default=5, help="in-memory repetitions (best of), default 5")
    ap.add_argument("--e2e-reps", type=int, default=3, help="end-to-end repetitions, default 3")
    ap.add_argument("--no-build", action="store_true", help="skip cargo build")
    ap.add_argument("--remake-input", action="store_true", help="remake bench/data/*-4k.exr")
    ap.add_argument("--inputs", default="city,sky",
                    help="inputs for the in-memory/quality table (first one also end to end): "
                    "comma-separated from city, sky; default city,sky")
    ap.add_argument("--wait-idle", type=float, default=0, metavar="SECONDS",
                    help="before measuring, wait up to SECONDS for other rustc processes to "
                    "finish (timings are noisy while others compile); default 0")
    ap.add_argument("--json", default=str(RESULTS / "convert.json"), help="where to write results")
    ap.add_argument("--e2e-also", action="append", default=[], metavar="NAME=PATH",
                    help="also time another mirrorball binary end to end, in the same rounds "
                    "(say, a build of an earlier commit); repeatable")
    args = ap.parse_args()
    extra = {}
    for spec in args.e2e_also:
        name, sep, exe = spec.partition("=")
        if not sep or not name or not Path(exe).is_file():
            ap.error(f"--e2e-also {spec!r}: give NAME=PATH of an existing mirrorball binary")
        extra[name] = Path(exe).resolve()

    import cv2
    import OpenEXR
    import py360convert
    from importlib.metadata import version

    names = [n.strip() for n in args.inputs.split(",") if n.strip()]
    if not names or any(n not in INPUTS for n in names):
        ap.error(f"--inputs: choose from {', '.join(INPUTS)}")

    if not args.no_build:
        try:
            build()
        except subprocess.CalledProcessError:
            log("convert_peers: cargo build failed (see above); fix the build, or pass "
                "--no-build to measure the binaries already in target/release")
            return 1
    for exe in (MIRRORBALL, EXAMPLE):
        if not exe.exists():
            log(f"missing {exe}: build it (drop --no-build)")
            return 1
    paths = {n: make_input(n, args.remake_input) for n in names}

    idle_wait = None
    if args.wait_idle > 0:
        t_wait = time.monotonic()
        deadline = t_wait + args.wait_idle
        while time.monotonic() < deadline:
            n, busy = rustc_count(), cpu_busy()
            if n <= 0 and busy < 0.15:
                break
            log(f"waiting for a quiet machine: {n} rustc process(es), CPUs {busy:.0%} busy ...")
            time.sleep(7)
        idle_wait = {"waited_s": round(time.monotonic() - t_wait, 1),
                     "rustc": rustc_count(), "cpu_busy": round(cpu_busy(), 3)}
        log(f"measuring: {idle_wait}")

    load = Load()
    load.sample("start")
    results: dict = {
        "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "machine": {
            "cpu": cpu_model(),
            "logical_cpus": os.cpu_count(),
            "os": platform.platform(),
        },
        "versions": {
            "mirrorball_git": git_describe(),
            "python": platform.python_version(),
            "numpy": np.__version__,
            "opencv-python-headless": version("opencv-python-headless"),
            "cv2": cv2.__version__,
            "py360convert": version("py360convert"),
            "OpenEXR": getattr(OpenEXR, "__version__", version("OpenEXR")),
        },
        "setup": {
            "latlong": [WIDTH, HEIGHT],
            "cube_face": FACE,
            "in_memory_reps": args.reps,
            "e2e_reps": args.e2e_reps,
            "cv2_threads": cv2.getNumThreads(),
        },
        "in_memory": {},
    }

    for n in names:
        log(f"in-memory: {paths[n].name}")
        results["in_memory"][paths[n].name] = in_memory(paths[n], args.reps, load)

    first = paths[names[0]]
    log(f"end to end: {first.name}")
    results["end_to_end"] = {first.name: end_to_end(first, args.e2e_reps, load, extra)}
    load.sample("end")
    log("cross-checks")
    mb_psnr = results["in_memory"][first.name]["mirrorball resample"]["roundtrip_log_psnr_db"]
    results["checks"] = checks(first, mb_psnr)
    results["load"] = {"max_rustc_processes_seen": load.max_rustc(), "wait_idle": idle_wait,
                       "samples": load.samples}

    # Targets being tracked (reported, not enforced).
    mem = results["in_memory"][first.name]
    e2e = results["end_to_end"][first.name]
    fastest_py = min((r["best_wall_s"], m) for m, r in e2e.items() if m.startswith("python"))
    targets = {}
    # Each mirrorball variant against the peer on the same footing (maps precomputed, new or
    # reused output).
    pairs = (
        ("mirrorball resample", "cv2.remap float32 maps"),
        ("mirrorball Remap (plan precomputed)", "cv2.remap float32 maps"),
        ("mirrorball Remap bilinear (plan precomputed)", "cv2.remap float32 maps"),
        ("mirrorball Remap into reused output", "cv2.remap float32 maps, reused output"),
        ("mirrorball Remap bilinear into reused output", "cv2.remap float32 maps, reused output"),
        ("mirrorball Remap bilinear (plan precomputed)", "cv2.remap fixed-point maps"),
    )
    for mine, peer in pairs:
        if mine not in mem or peer not in mem:
            continue
        m = mem[mine]
        tp = m["forward_texels_per_s"] / mem[peer]["forward_texels_per_s"]
        q_ok = (m["roundtrip_log_psnr_db"] or float("inf")) >= mem[peer]["roundtrip_log_psnr_db"]
        targets[f"in_memory_forward_{mine}_vs_{peer}"] = {
            "mirrorball": mine,
            "peer": peer,
            "mirrorball_throughput_over_peer": tp,
            "target": 1.5,
            "quality_equal_or_better": q_ok,
            "met": tp >= 1.5 and q_ok,
        }
    sp = fastest_py[0] / e2e["mirrorball convert (CLI)"]["best_wall_s"]
    targets["end_to_end_vs_fastest_python"] = {
        "fastest_python": fastest_py[1],
        "speedup": sp,
        "median_speedup": e2e[fastest_py[1]]["median_wall_s"]
        / e2e["mirrorball convert (CLI)"]["median_wall_s"],
        "target": 4.0,
        "met": sp >= 4.0,
    }
    results["targets"] = targets

    # ---- print
    v = results["versions"]
    print(f"mirrorball {v['mirrorball_git']} | numpy {v['numpy']} | opencv-python-headless "
          f"{v['opencv-python-headless']} | py360convert {v['py360convert']} | OpenEXR "
          f"{v['OpenEXR']} | Python {v['python']}")
    print(f"{results['machine']['cpu']}, {results['machine']['logical_cpus']} logical CPUs; "
          f"cv2 threads {cv2.getNumThreads()}, rayon threads {mem['mirrorball resample']['threads']}; other rustc "
          f"processes seen during the run: max {load.max_rustc()}; 1-min load average "
          f"{min(x['loadavg_1m'] for x in load.samples)}-{max(x['loadavg_1m'] for x in load.samples)}"
          + (f"; waited {idle_wait['waited_s']} s for a quiet machine, then {idle_wait['rustc']} "
             f"rustc, CPUs {idle_wait['cpu_busy']:.0%} busy" if idle_wait else ""))
    for n in names:
        print_in_memory(paths[n].name, results["in_memory"][paths[n].name], args.reps)
    print_e2e(first, e2e, args.e2e_reps)
    c = results["checks"]
    print(f"\nChecks: numpy log-PSNR of mirrorball's CLI round trip "
          f"{c['metric']['numpy_log_psnr_of_mirrorball_cli_roundtrip_db']:.4f} dB vs the "
          f"example's (Rust metric) {'exact' if mb_psnr is None else f'{mb_psnr:.4f}'} dB; cube faces, mean "
          f"|d ln(1+x)| mirrorball vs cv2.remap: "
          + " ".join(f"{k} {d:.1e}" for k, d in c["cube_faces_mean_abs_log_diff_mirrorball_vs_cv2"].items()))
    print("\nTargets (tracked, not enforced):")
    for k, t in targets.items():
        if "speedup" in t:
            print(f"  end to end: fastest Python ({t['fastest_python']}) / mirrorball = "
                  f"{t['speedup']:.2f}x best of each, {t['median_speedup']:.2f}x median of each "
                  f"(target >= 4x, on the best): {'MET' if t['met'] else 'NOT MET'}")
        else:
            print(f"  in memory forward, {t['mirrorball']} vs {t['peer']}: throughput = "
                  f"{t['mirrorball_throughput_over_peer']:.2f}x the peer's (target >= 1.5x), "
                  f"quality {'equal or better' if t['quality_equal_or_better'] else 'worse'}: "
                  f"{'MET' if t['met'] else 'NOT MET'}")

    Path(args.json).parent.mkdir(parents=True, exist_ok=True)
    with open(args.json, "w") as f:
        json.dump(finite_or_none(results), f, indent=2, allow_nan=False, default=str)
        f.write("\n")
    log(f"wrote {os.path.relpath(args.json)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
