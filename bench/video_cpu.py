#!/usr/bin/env python3
"""CPU time a frame of the 360° conversion alone, mirrorball against FFmpeg's `v360`, so that
two cores do not decide it: each pipeline's CPU time (user + system, every process and
thread) less the CPU time of the same pipeline with no conversion in it.

    bench/video_cpu.py --mirrorball target/release/mirrorball [--frames 30] [--rounds 3]

The binary must be built with `--features video`. Sources, made once from testsrc2 (blurred,
so that both filters see detail but no aliasing decides the picture):

- 4096x2048 lat-long, H.264 yuv420p and H.264 yuv420p10le (High 10);
- 3840x1920 dual fisheye (two 190° lenses, made by v360 from the lat-long), yuv420p.

Cases, each written as raw frames into Matroska (`-c:v rawvideo`), so that no encoder counts:

- yuv420p and yuv420p10le, in process: `mirrorball convert in.mp4 out.mkv --to cube --size
  1024 --codec rawvideo` (antialiased, each plane at its own size) against
  `ffmpeg -i in.mp4 -vf v360=e:c3x2:w=3072:h=2048 -c:v rawvideo out.mkv` (bilinear, its
  default); both less `ffmpeg -i in.mp4 -vf crop=W:H -c:v rawvideo out.mkv` (the same decode
  and write, no conversion). The same for EAC.
- rgb48le (16-bit RGB, which neither decoder gives a video in): mirrorball through pipes,
  `ffmpeg -i in.mp4 -vf format=rgb48le -f rawvideo - | mirrorball convert - - --pix-fmt
  rgb48le … | ffmpeg -f rawvideo … -i - -c:v rawvideo out.mkv`, less the same pipeline with
  `cat`-like copying (`--cut`) in mirrorball's place; v360 as
  `-vf format=rgb48le,v360=…`, less `-vf format=rgb48le,crop=…`.
- dual fisheye 3840x1920 → 3840x1920 lat-long, yuv420p, in process, against
  `v360=dfisheye:e:ih_fov=190:iv_fov=190`; the issue's target compares it with the cube's
  conversion a frame (mirrorball's own).

Prints per case the best round's CPU seconds, the conversion's CPU a frame and
mirrorball/v360, and the targets of issue 37: ≤ ½ of v360's at 10 and 16 bits, ≤ ⅔ at 8
bits, dual fisheye ≤ 1.5× the cube's.
"""
import argparse
import os
import resource
import shutil
import subprocess
import sys
import tempfile

if len(sys.argv) == 4 and sys.argv[1] == "--cut":
    # The copier in mirrorball's place: reads frames of IN bytes, writes their first OUT.
    n_in, n_out = int(sys.argv[2]), int(sys.argv[3])
    src, dst = sys.stdin.buffer, sys.stdout.buffer
    while True:
        frame = src.read(n_in)
        if len(frame) < n_in:
            break
        dst.write(frame[:n_out])
    sys.exit(0)

ap = argparse.ArgumentParser()
ap.add_argument("--mirrorball", required=True)
ap.add_argument("--frames", type=int, default=30)
ap.add_argument("--rounds", type=int, default=3)
ap.add_argument("--only", help="run only the cases whose name contains this")
a = ap.parse_args()
tmp = tempfile.mkdtemp(prefix="video-cpu-")
ff = ["ffmpeg", "-y", "-v", "error", "-nostdin"]
W, H = 4096, 2048


def make(name, pix_fmt, extra_vf="", size=f"{W}x{H}"):
    path = os.path.join(tmp, name)
    vf = "gblur=sigma=1.5" + (f",{extra_vf}" if extra_vf else "")
    subprocess.run(ff + ["-f", "lavfi", "-i", f"testsrc2=size={W}x{H}:rate=30", "-vf", vf,
                         "-frames:v", str(a.frames), "-pix_fmt", pix_fmt, "-c:v", "libx264",
                         "-preset", "ultrafast", "-qp", "10", path], check=True)
    return path


def cpu(cmd):
    """CPU seconds (user + system) of `cmd` (a list, or a shell pipeline string) and all its
    processes and threads."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, shell=isinstance(cmd, str))
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


OUT = os.path.join(tmp, "out.mkv")


def best(cmd):
    t = min(cpu(cmd) for _ in range(a.rounds))
    for f in (OUT, os.path.join(tmp, "out.nut")):
        if os.path.exists(f):
            os.remove(f)
    return t


def size_of(path):
    probe = subprocess.run(["ffprobe", "-v", "error", "-select_streams", "v:0", "-show_entries",
                            "stream=width,height", "-of", "csv=p=0", path],
                           check=True, capture_output=True, text=True)
    return tuple(int(x) for x in probe.stdout.strip().split(","))


def out_size(src, flags, codec="rawvideo"):
    subprocess.run([a.mirrorball, "convert", src, OUT, *flags, "--codec", codec, "-q"],
                   check=True)
    s = size_of(OUT)
    os.remove(OUT)
    return s


print(f"{a.frames} frames; CPU seconds (user + system, all processes), best of {a.rounds}")
srcs = {"yuv420p": make("in8.mp4", "yuv420p"), "yuv420p10le": make("in10.mp4", "yuv420p10le")}
cube = ["--to", "cube", "--size", "1024"]
eac = ["--to", "eac", "--size", "1024"]
results = {}


def report(name, t_base, t_v, t_mb, w, h, target):
    conv_v = (t_v - t_base[0]) / a.frames
    conv_mb = (t_mb - t_base[1]) / a.frames
    ratio = conv_mb / conv_v
    results[name] = conv_mb
    ok = "met" if ratio <= target else "NOT met"
    print(f"{name:34} {w}x{h}: baseline {t_base[0]:.2f}/{t_base[1]:.2f} s, v360 {t_v:.2f} s, "
          f"mirrorball {t_mb:.2f} s; conversion a frame: v360 {conv_v * 1000:.1f} ms, "
          f"mirrorball {conv_mb * 1000:.1f} ms, mirrorball/v360 {ratio:.2f} "
          f"(target ≤ {target:.2f}: {ok})", flush=True)


def wanted(name):
    return a.only is None or a.only in name


for fmt, src in srcs.items():
    target = 2 / 3 if fmt == "yuv420p" else 0.5
    # Matroska takes raw 8-bit YUV only: 10-bit frames are written lossless by FFV1 on
    # every side alike (the baseline pays the same encoder).
    codec = ["-c:v", "rawvideo"] if fmt == "yuv420p" else ["-c:v", "ffv1"]
    raw = [*codec, OUT]
    for label, v360, flags in [("cube 6x1024^2 (c3x2)", "e:c3x2", cube), ("EAC 6x1024^2", "e:eac", eac)]:
        name = f"{label} {fmt}"
        if not wanted(name):
            continue
        w, h = out_size(src, flags, codec[1])
        t_base = best(ff + ["-i", src, "-vf", f"crop=min({w}\\,iw):min({h}\\,ih):0:0,pad={w}:{h}", *raw])
        t_v = best(ff + ["-i", src, "-vf", f"v360={v360}:w={w}:h={h}", *raw])
        t_mb = best([a.mirrorball, "convert", src, OUT, *flags, "--codec", codec[1], "-q"])
        report(name, (t_base, t_base), t_v, t_mb, w, h, target)
# Raw RGB goes into NUT (Matroska refuses it); only ffmpeg writes these.
NUT = os.path.join(tmp, "out.nut")
raw = ["-c:v", "rawvideo", NUT]

# 16-bit RGB: mirrorball through pipes (no video decoder gives rgb48le frames).
for label, v360, flags, size in [("cube 6x1024^2 (hstrip)", "e:c6x1", cube + ["--layout", "hstrip"], (6144, 1024)),
                                   ("EAC 6x1024^2", "e:eac", eac, None)]:
    name = f"{label} rgb48le (pipes)"
    if not wanted(name):
        continue
    src = srcs["yuv420p"]
    w, h = size or out_size(src, flags)
    frame_in, frame_out = W * H * 6, w * h * 6
    dec = f"ffmpeg -v error -nostdin -i {src} -vf format=rgb48le -f rawvideo -"
    enc = f"ffmpeg -y -v error -nostdin -f rawvideo -pix_fmt rgb48le -s {w}x{h} -i - -c:v rawvideo {NUT}"
    mb = " ".join([a.mirrorball, "convert", "-", "-", "--in-size", f"{W}x{H}", "--pix-fmt", "rgb48le", *flags, "-q"])
    t_mb = best(f"{dec} | {mb} | {enc}")
    t_mb_base = best(f"{dec} | {sys.executable} {os.path.abspath(__file__)} --cut {frame_in} {frame_out} | {enc}")
    t_v = best(ff + ["-i", src, "-vf", f"format=rgb48le,v360={v360}:w={w}:h={h}", *raw])
    t_v_base = best(ff + ["-i", src, "-vf", f"format=rgb48le,crop=min({w}\\,iw):min({h}\\,ih):0:0,pad={w}:{h}", *raw])
    report(name, (t_v_base, t_mb_base), t_v, t_mb, w, h, 0.5)

# Dual fisheye, the 360° cameras' format, to a lat-long of the same size.
if wanted("dual fisheye"):
    df = os.path.join(tmp, "dfish.mp4")
    subprocess.run(ff + ["-i", srcs["yuv420p"], "-vf", "v360=e:dfisheye:w=3840:h=1920:h_fov=190:v_fov=190",
                         "-pix_fmt", "yuv420p", "-c:v", "libx264", "-preset", "ultrafast", "-qp", "10", df],
                   check=True)
    w, h = 3840, 1920
    flags = ["--from", "dual-fisheye:fov=190", "--to", "latlong", "--size", str(w)]
    raw = ["-c:v", "rawvideo", OUT]
    t_base = best(ff + ["-i", df, "-vf", f"crop={w}:{h}:0:0", *raw])
    t_v = best(ff + ["-i", df, "-vf", f"v360=dfisheye:e:ih_fov=190:iv_fov=190:w={w}:h={h}", *raw])
    t_mb = best([a.mirrorball, "convert", df, OUT, *flags, "--codec", "rawvideo", "-q"])
    report("dual fisheye yuv420p", (t_base, t_base), t_v, t_mb, w, h, float("inf"))
    c = results.get("cube 6x1024^2 (c3x2) yuv420p")
    if c:
        d = results["dual fisheye yuv420p"]
        print(f"dual fisheye / cube, mirrorball's conversion a frame: {d * 1000:.1f} / {c * 1000:.1f} ms "
              f"= {d / c:.2f} (target ≤ 1.5: {'met' if d / c <= 1.5 else 'NOT met'})")
shutil.rmtree(tmp)
