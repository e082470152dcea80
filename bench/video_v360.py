#!/usr/bin/env python3
"""Frames per second turning a 4096x2048 lat-long stream into 6x1024² cube faces (and EAC,
when mirrorball knows it): mirrorball through pipes, end to end as a user runs it,

    ffmpeg -f rawvideo … -i in.raw -f rawvideo - |
      mirrorball convert - - --in-size 4096x2048 --pix-fmt F --to cube --size 1024 --layout hstrip |
      ffmpeg -f rawvideo … -i - -f null -

against ffmpeg's own v360 filter doing the same (`ffmpeg -i in.raw -vf v360=e:c6x1 -f null -`),
at 8 bits (rgb24) and 16 bits (rgb48le), side by side in one run, the runs interleaved.
The input is a raw file of testsrc2 frames made once (so that decoding costs neither side
anything); `-f null` on both sides, so that no encoder counts. mirrorball antialiases (its
default --max-samples 8); v360 interpolates bilinearly (its default).

Targets (issue 19): mirrorball at least 2x v360's frames per second at 16 bits, 1.5x at 8.

The pipes themselves cost: the same run also times the pipeline with a copier in
mirrorball's place that converts nothing (this script's `--cut IN OUT`: it reads each input
frame of IN bytes and writes its first OUT bytes, the output frame's size, through pipes
widened to 1 MiB as mirrorball widens its own), so every pipe carries exactly the bytes it
carries in mirrorball's pipeline. No converter in the middle can beat that floor, so
`ceiling` (the floor's frames per second over v360's) is the best ratio this machine allows
through pipes.

On a machine with few cores the three processes share them, so the script also counts CPU
time (every process of each pipeline, user and system): the CPU a frame may take at the
target's frames per second on every core, against what the pipes alone took. Where the pipes
alone take more, no converter can reach the target here, however fast.

A stream is longer than 24 frames: `--loops N` feeds the same raw file N times over
(ffmpeg's `-stream_loop`, on every side alike: mirrorball's producer, v360's input, the
floor's producer), so a run converts N×frames frames and the one-off costs (mirrorball's
plan, v360's map tables, the processes starting) weigh as they do on a video of that
length. The default, 1, is the 24-frame run.

    python3 bench/video_v360.py [--frames 24] [--loops 1] [--reps 2] [--no-build] [--eac-to eac]
"""

import argparse
import os
import re
import resource
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FFMPEG = "/usr/bin/ffmpeg"
W, H, FACE = 4096, 2048, 1024
TARGET = {"rgb24": 1.5, "rgb48le": 2.0}
PIXEL_BYTES = {"rgb24": 3, "rgb48le": 6}


def sh(cmd, **kw):
    return subprocess.run(cmd, shell=True, check=True, **kw)


def make_input(path, pix_fmt, frames):
    if path.exists() and path.stat().st_size == frames * W * H * PIXEL_BYTES[pix_fmt]:
        return
    sh(f"{FFMPEG} -v error -y -f lavfi -i testsrc2=size={W}x{H}:rate=30 -frames:v {frames} "
       f"-pix_fmt {pix_fmt} -f rawvideo {path}")


def cut(frame_in, frame_out):
    """The floor's middle process: each frame of `frame_in` bytes from standard input, its
    first `frame_out` bytes to standard output; nothing converted."""
    import fcntl
    for fd in (0, 1):
        try:
            fcntl.fcntl(fd, fcntl.F_SETPIPE_SZ, 1 << 20)
        except OSError:
            pass
    buf = memoryview(bytearray(frame_in))
    src = open(0, "rb", buffering=0)
    while True:
        n = 0
        while n < frame_in:
            r = src.readinto(buf[n:])
            if not r:
                if n:
                    sys.exit(f"cut: the input ended {n} bytes into a frame")
                return 0
            n += r
        m = 0
        while m < frame_out:
            m += os.write(1, buf[m:frame_out])


def cpu_of_children():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def timed(cmd):
    """Wall seconds, CPU seconds of every process of the pipeline (user and system), and
    standard error."""
    c = cpu_of_children()
    t = time.perf_counter()
    p = subprocess.run(cmd, shell=True, stderr=subprocess.PIPE, text=True)
    dt = time.perf_counter() - t
    if p.returncode != 0:
        raise RuntimeError(f"{cmd}\n{p.stderr[-2000:]}")
    return dt, cpu_of_children() - c, p.stderr


def main():
    if len(sys.argv) == 4 and sys.argv[1] == "--cut":
        return cut(int(sys.argv[2]), int(sys.argv[3]))
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames", type=int, default=24)
    ap.add_argument("--reps", type=int, default=2)
    ap.add_argument("--loops", type=int, default=1,
                    help="feed the input this many times over (a longer stream)")
    ap.add_argument("--no-build", action="store_true")
    ap.add_argument("--eac-to", default="eac",
                    help="mirrorball's --to for EAC (skipped when mirrorball refuses it)")
    ap.add_argument("--data", default=str(ROOT / "bench" / "data"))
    a = ap.parse_args()
    mb = ROOT / "target" / "release" / "mirrorball"
    if not a.no_build:
        sh(f"cargo build --release -p mirrorball-cli --bin mirrorball", cwd=ROOT)
    data = Path(a.data)
    data.mkdir(parents=True, exist_ok=True)
    total = a.frames * a.loops
    print(f"{os.cpu_count()} CPUs; {total} frames of {W}x{H} ({a.frames} made, fed {a.loops} "
          f"time(s)); best of {a.reps}")

    # (name, mirrorball --to and layout, output frame size, v360 output options)
    targets = [("cube 6x1024²", f"--to cube --size {FACE} --layout hstrip", (6 * FACE, FACE),
                f"v360=input=e:output=c6x1:w={6 * FACE}:h={FACE}")]
    probe = subprocess.run(f"{mb} convert - - --in-size 8x4 --pix-fmt rgb24 --to {a.eac_to} -q "
                           "--size 16 < /dev/null", shell=True, stderr=subprocess.PIPE, text=True)
    if "unknown" in probe.stderr or "--to" in probe.stderr:
        print(f"EAC: mirrorball has no --to {a.eac_to} yet; cube only")
    else:
        targets.append(("EAC 3x2", f"--to {a.eac_to} --size {FACE}", None,
                        f"v360=input=e:output=eac:w={3 * FACE}:h={2 * FACE}"))

    rows = []
    for pix_fmt in ["rgb24", "rgb48le"]:
        src = data / f"testsrc2-{W}x{H}-{a.frames}.{pix_fmt}.raw"
        make_input(src, pix_fmt, a.frames)
        feed = (f"{FFMPEG} -v error -stream_loop {a.loops - 1} -f rawvideo -pix_fmt {pix_fmt} "
                f"-s {W}x{H} -i {src}")
        for name, to, size, v360 in targets:
            best = {"mirrorball": 1e9, "v360": 1e9, "floor": 1e9}
            cpu = {"mirrorball": 1e9, "floor": 1e9}
            steady = 0.0
            for _ in range(a.reps):
                # The output frame size is what mirrorball says it writes.
                if size is None:
                    _, _, err = timed(f"{feed} -frames:v 1 -f rawvideo - | {mb} convert - - "
                                   f"--in-size {W}x{H} --pix-fmt {pix_fmt} {to} > /dev/null")
                    m = re.search(r"writing (\d+)x(\d+)", err)
                    size = (int(m.group(1)), int(m.group(2)))
                mcmd = (f"{feed} -f rawvideo - | {mb} convert - - --in-size {W}x{H} "
                        f"--pix-fmt {pix_fmt} {to} | {FFMPEG} -v error -f rawvideo "
                        f"-pix_fmt {pix_fmt} -s {size[0]}x{size[1]} -i - -f null -")
                dt, c, err = timed(mcmd)
                best["mirrorball"] = min(best["mirrorball"], dt)
                cpu["mirrorball"] = min(cpu["mirrorball"], c)
                m = re.search(r"in ([\d.]+)s \(([\d.]+) frames/s; planned in ([\d.]+)s\)", err)
                if m:
                    steady = max(steady, float(m.group(2)))
                dt, _, _ = timed(f"{feed} -vf {v360} -f null -")
                best["v360"] = min(best["v360"], dt)
                bpp = PIXEL_BYTES[pix_fmt]
                copier = f"{sys.executable} {Path(__file__).resolve()} --cut {W * H * bpp} " \
                         f"{size[0] * size[1] * bpp}"
                dt, c, _ = timed(f"{feed} -f rawvideo - | {copier} | {FFMPEG} -v error "
                              f"-f rawvideo -pix_fmt {pix_fmt} -s {size[0]}x{size[1]} -i - "
                              f"-f null -")
                best["floor"] = min(best["floor"], dt)
                cpu["floor"] = min(cpu["floor"], c)
            fm = total / best["mirrorball"]
            fv = total / best["v360"]
            ff = total / best["floor"]
            # CPU time a frame may take, all processes together, for the target's wall time
            # on every core; what the pipes alone (ffmpeg, copier, ffmpeg) and the mirrorball
            # pipeline took.
            allowed = os.cpu_count() * best["v360"] / TARGET[pix_fmt] / total * 1e3
            cpus = (allowed, cpu["floor"] / total * 1e3, cpu["mirrorball"] / total * 1e3)
            rows.append((name, pix_fmt, fm, steady, fv, fm / fv, TARGET[pix_fmt], ff / fv, cpus))

    print()
    print(f"{'to':14} {'pixels':8} {'mirrorball':>11} {'(no plan)':>10} {'v360':>8} "
          f"{'ratio':>6} {'target':>7} {'ceiling':>8}")
    for name, pix_fmt, fm, steady, fv, r, t, ceil, _ in rows:
        verdict = "met" if r >= t else ("NOT met" if ceil >= t else "NOT met: over the ceiling")
        print(f"{name:14} {pix_fmt:8} {fm:8.2f} f/s {steady:7.2f} f/s {fv:5.2f} f/s "
              f"{r:5.2f}x {t:5.1f}x {ceil:7.2f}x {verdict}")
    print("\nmirrorball f/s: end to end, wall clock, planning (once per run) included; "
          "(no plan): mirrorball's own count after planning; ceiling: the pipes with a copier in "
          "mirrorball's place, over v360 (no converter through pipes can pass it)")
    print()
    print(f"{'CPU ms a frame':14} {'pixels':8} {'at target':>10} {'pipes':>7} {'left':>7} "
          f"{'mirrorball':>11}")
    for name, pix_fmt, *_, (allowed, pipes, mb) in rows:
        print(f"{name:14} {pix_fmt:8} {allowed:10.1f} {pipes:7.1f} {allowed - pipes:7.1f} "
              f"{mb:11.1f}")
    print("\nat target: every core's time a frame for the target's frames per second; pipes: "
          "what ffmpeg | copier | ffmpeg took (all three processes); left: what that leaves for "
          "converting (none: the target is out of reach on this machine whatever converts); "
          "mirrorball: its whole pipeline (both ffmpeg ends included)")


if __name__ == "__main__":
    sys.exit(main())
