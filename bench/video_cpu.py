#!/usr/bin/env python3
"""CPU time a frame of the 360° conversion alone, mirrorball's video path against FFmpeg's
`v360`, so that two cores do not decide it: each pipeline's CPU time (user + system, all
threads) less the CPU time of the same decode and the same write without the conversion.

    bench/video_cpu.py --mirrorball target/release/mirrorball [--frames 30] [--rounds 3]

The binary must be built with `--features video`. A 4096x2048 yuv420p H.264 lat-long
(testsrc2, blurred) is made once; each case writes raw frames (`-c:v rawvideo` into
Matroska), so the encoder costs a copy on both sides:

- baseline: `ffmpeg -i in.mp4 -vf crop=W:H -c:v rawvideo out.mkv` (decode and write the
  output's size, no conversion);
- v360: `ffmpeg -i in.mp4 -vf v360=e:c3x2:w=3072:h=2048 -c:v rawvideo out.mkv`
  (bilinear, its default);
- mirrorball: `mirrorball convert in.mp4 out.mkv --to cube --size 1024 --codec rawvideo`
  (antialiased), and the same for EAC.

Prints per case the best round's CPU seconds, the CPU a frame of conversion (less the
baseline) and mirrorball/v360.
"""
import argparse, os, resource, shutil, subprocess, tempfile

ap = argparse.ArgumentParser()
ap.add_argument("--mirrorball", required=True)
ap.add_argument("--frames", type=int, default=30)
ap.add_argument("--rounds", type=int, default=3)
a = ap.parse_args()
tmp = tempfile.mkdtemp(prefix="video-cpu-")
src = os.path.join(tmp, "in.mp4")
ff = ["ffmpeg", "-y", "-v", "error", "-nostdin"]
subprocess.run(ff + ["-f", "lavfi", "-i",
    f"testsrc2=size=4096x2048:rate=30,gblur=sigma=1.5", "-frames:v", str(a.frames),
    "-pix_fmt", "yuv420p", "-c:v", "libx264", "-preset", "ultrafast", "-crf", "18", src], check=True)


def cpu(cmd):
    """CPU seconds (user + system) of `cmd` and its threads."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def best(cmd):
    out = cmd[-1] if not cmd[-1].startswith("-") else None
    times = []
    for _ in range(a.rounds):
        times.append(cpu(cmd))
    for f in os.listdir(tmp):
        if f != "in.mp4":
            os.remove(os.path.join(tmp, f))
    return min(times)


out = os.path.join(tmp, "out.mkv")
raw = ["-c:v", "rawvideo", out]
cases = [
    ("cube 6x1024^2 (c3x2)", (3072, 2048), "e:c3x2", ["--to", "cube", "--size", "1024"]),
    ("EAC 6x1024^2", None, "e:eac", ["--to", "eac", "--size", "1024"]),
]
print(f"{a.frames} frames of 4096x2048 yuv420p; CPU seconds, best of {a.rounds}")
for name, size, v360, flags in cases:
    mb = [a.mirrorball, "convert", src, out, *flags, "--codec", "rawvideo", "-q"]
    t_mb = best(mb)
    if size is None:
        subprocess.run(mb, check=True)
        probe = subprocess.run(["ffprobe", "-v", "error", "-select_streams", "v:0", "-show_entries",
            "stream=width,height", "-of", "csv=p=0", out], check=True, capture_output=True, text=True)
        size = tuple(int(x) for x in probe.stdout.strip().split(","))
    w, h = size
    t_base = best(ff + ["-i", src, "-vf", f"crop={w}:{h}:0:0", *raw])
    t_v360 = best(ff + ["-i", src, "-vf", f"v360={v360}:w={w}:h={h}", *raw])
    conv_mb = (t_mb - t_base) / a.frames
    conv_v = (t_v360 - t_base) / a.frames
    print(f"{name} ({w}x{h}): baseline {t_base:.2f} s, v360 {t_v360:.2f} s, mirrorball {t_mb:.2f} s; "
          f"conversion a frame: v360 {conv_v * 1000:.1f} ms, mirrorball {conv_mb * 1000:.1f} ms, "
          f"mirrorball/v360 {conv_mb / conv_v:.2f}")
shutil.rmtree(tmp)
