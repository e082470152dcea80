#!/usr/bin/env python3
"""A Ray Data pipeline over many 360° frames, mirrorball against py360convert, one run.

    python bench/python_ray.py [--frames 200] [--width 2048] [--face 512] [--cpus 2] [--reps 2]

Both pipelines are the same Ray Data job: uint8 lat-long frames (a stand-in for decoded
video: eight distinct frames made once in each worker, then taken in turn; the same pixels
for both), converted to six cube faces, each
face's sum taken so that nothing is written; `map_batches` with one actor a CPU, each with
one thread (`mirrorball.set_threads(1)`, `cv2.setNumThreads(1)`). mirrorball plans once a
worker (`Remap`, antialiased, the default `max_samples=8`); py360convert's `e2c` runs as its
users call it (its own caches warm after the first frame). Each pipeline runs once on 8
frames first (Ray's workers started, the libraries imported); then the median wall time of
--reps runs of each, alternated, and the ratio are printed. Each timed run includes its
actors' start (frames made, mirrorball's plan), as a job over a folder pays it.
"""

import argparse
import statistics
import time

import numpy as np
import ray


def frame(i, w):
    """Frame `i`: a smooth pattern that moves with i, plus fixed noise; uint8 RGB."""
    h = w // 2
    v, u = np.meshgrid(np.linspace(0, 1, h, dtype=np.float32), np.linspace(0, 1, w, dtype=np.float32), indexing="ij")
    t = i * 0.05
    img = np.stack([np.sin(40 * u + t) * np.cos(23 * v), np.cos(31 * u + 7 * v - t), u * v], -1) * 0.4 + 0.5
    return (np.clip(img, 0, 1) * 255 + 0.5).astype(np.uint8)


class Mirrorball:
    def __init__(self, w, face):
        import mirrorball as mb

        mb.set_threads(1)
        self.frames = [frame(k, w) for k in range(8)]
        self.plan = mb.Remap((w // 2, w, 3), dst="cube", size=face, layout="separate")
        self.out = np.empty(tuple([6] + self.plan.output_shape(3)[1:]), np.uint8)

    def __call__(self, batch):
        sums = []
        for i in batch["id"]:
            self.plan.apply(self.frames[int(i) % 8], out=self.out)
            sums.append(int(self.out.sum(dtype=np.int64)))
        return {"sum": np.array(sums)}


class Py360:
    def __init__(self, w, face):
        import cv2

        cv2.setNumThreads(1)
        self.frames = [frame(k, w) for k in range(8)]
        self.face = face

    def __call__(self, batch):
        import py360convert

        sums = []
        for i in batch["id"]:
            faces = py360convert.e2c(self.frames[int(i) % 8], face_w=self.face, cube_format="list")
            sums.append(int(sum(f.sum(dtype=np.int64) for f in faces)))
        return {"sum": np.array(sums)}


def run(udf, a, frames=None):
    frames = frames or a.frames
    t0 = time.perf_counter()
    # Items made in the driver (a read task would wait for a CPU the actors hold).
    ds = ray.data.from_items([{"id": i} for i in range(frames)]).map_batches(
        udf, fn_constructor_args=(a.width, a.face), batch_size=8, concurrency=a.cpus, num_cpus=1
    )
    n = sum(1 for _ in ds.iter_rows())
    assert n == frames
    return time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=200)
    ap.add_argument("--width", type=int, default=2048)
    ap.add_argument("--face", type=int, default=512)
    ap.add_argument("--cpus", type=int, default=2)
    ap.add_argument("--reps", type=int, default=2)
    a = ap.parse_args()
    ray.init(num_cpus=a.cpus, include_dashboard=False, log_to_driver=False)
    try:
        # Ray's workers started and both libraries imported before anything is timed.
        run(Mirrorball, a, 8)
        run(Py360, a, 8)
        times = {"mirrorball Remap": [], "py360convert e2c": []}
        for _ in range(a.reps):
            times["mirrorball Remap"].append(run(Mirrorball, a))
            times["py360convert e2c"].append(run(Py360, a))
    finally:
        ray.shutdown()
    print(f"Ray Data, {a.frames} frames {a.width}x{a.width // 2} uint8 -> 6x{a.face}², {a.cpus} CPUs, median of {a.reps}")
    ours = statistics.median(times["mirrorball Remap"])
    for k, ts in times.items():
        t = statistics.median(ts)
        ratio = "" if k == "mirrorball Remap" else f"  mirrorball is {t / ours:5.2f}x faster"
        print(f"  {k:20s} {t:8.2f} s  ({a.frames / t:6.1f} frames/s){ratio}")


if __name__ == "__main__":
    main()
