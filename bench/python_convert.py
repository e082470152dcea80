#!/usr/bin/env python3
"""mirrorball's Python package against what Python users run today, in one process and one
run, with the ratios printed: a 4096×2048 float32 lat-long to six 1024² cube faces (e2c),
the faces back to 4096×2048 (c2e), and the same with uint8 frames.

    python bench/python_convert.py [--reps 3] [--threads N]

Compared: py360convert (`e2c`/`c2e`, cold: its caches cleared, and warm), `cv2.remap`
with float maps made beforehand (per face, INTER_LINEAR; the maps' making not timed), and
pytorch360convert on the CPU when installed (bench/requirements-python-bench.txt).
mirrorball: a `Remap` planned once then applied (warm), and `convert` (cold: plans each
call); both with antialiasing on (max_samples 8, the default). Times are the median of
--reps runs, wall clock.
"""

import argparse
import functools
import gc
import statistics
import time

import numpy as np

import mirrorball as mb

W, H, FACE = 4096, 2048, 1024


def timed(fn, reps):
    times = []
    for _ in range(reps):
        gc.collect()
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def source(dtype):
    rng = np.random.default_rng(7)
    v, u = np.meshgrid(np.linspace(0, 1, H, dtype=np.float32), np.linspace(0, 1, W, dtype=np.float32), indexing="ij")
    img = np.stack([np.sin(40 * u) * np.cos(23 * v), np.cos(31 * u + 7 * v), u * v], -1) * 0.4 + 0.5
    img += rng.random(img.shape, dtype=np.float32) * 0.05
    img = img.astype(np.float32)
    if dtype == np.uint8:
        return (np.clip(img, 0, 1) * 255 + 0.5).astype(np.uint8)
    return img


def clear_py360_caches():
    import py360convert

    for mod in (py360convert.utils, py360convert.e2c, py360convert.c2e):
        for name in dir(mod):
            obj = getattr(mod, name)
            if isinstance(obj, functools._lru_cache_wrapper):
                obj.cache_clear()
            for attr in dir(obj) if isinstance(obj, type) else ():
                f = getattr(obj, attr, None)
                if isinstance(f, functools._lru_cache_wrapper):
                    f.cache_clear()


def cv2_e2c_maps():
    """cv2.remap maps from each cube face texel (OpenGL faces) to lat-long pixels."""
    i = (np.arange(FACE, dtype=np.float64) + 0.5) / FACE * 2 - 1
    b, a = np.meshgrid(i, i, indexing="ij")
    one = np.ones_like(a)
    faces = [(one, -b, -a), (-one, -b, a), (a, one, b), (a, -one, -b), (a, -b, one), (-a, -b, -one)]
    maps = []
    for x, y, z in faces:
        n = np.sqrt(x * x + y * y + z * z)
        lon, lat = np.arctan2(x / n, -z / n), np.arcsin(y / n)
        mx = ((lon / (2 * np.pi) + 0.5) * W - 0.5).astype(np.float32)
        my = ((0.5 - lat / np.pi) * H - 0.5).astype(np.float32)
        maps.append((mx, my))
    return maps


def cv2_c2e_maps():
    """cv2.remap maps from each lat-long pixel to a horizontal strip of the six faces."""
    u = (np.arange(W) + 0.5) / W
    v = (np.arange(H) + 0.5) / H
    uu, vv = np.meshgrid(u, v)
    lon, lat = (uu - 0.5) * 2 * np.pi, (0.5 - vv) * np.pi
    x, y, z = np.cos(lat) * np.sin(lon), np.sin(lat), -np.cos(lat) * np.cos(lon)
    ax, ay, az = np.abs(x), np.abs(y), np.abs(z)
    face = np.where((ax >= ay) & (ax >= az), np.where(x >= 0, 0, 1), np.where(ay >= az, np.where(y >= 0, 2, 3), np.where(z >= 0, 4, 5)))
    table = {0: (-z, -y, ax), 1: (z, -y, ax), 2: (x, z, ay), 3: (x, -z, ay), 4: (x, -y, az), 5: (-x, -y, az)}
    sc = np.zeros_like(x)
    tc = np.zeros_like(x)
    for f, (s, t, m) in table.items():
        k = face == f
        sc[k], tc[k] = s[k] / m[k], t[k] / m[k]
    mx = (face * FACE + (sc + 1) / 2 * FACE - 0.5).astype(np.float32)
    my = ((tc + 1) / 2 * FACE - 0.5).astype(np.float32)
    return mx, my


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--threads", type=int, default=None)
    a = ap.parse_args()
    mb.set_threads(a.threads)
    import cv2
    import py360convert

    cv2.setNumThreads(mb.get_threads())
    print(f"threads: {mb.get_threads()} (mirrorball and OpenCV), numpy {np.__version__}, cv2 {cv2.__version__}")
    try:
        import pytorch360convert
        import torch

        torch.set_num_threads(mb.get_threads())
    except ImportError:
        pytorch360convert = None
        print("pytorch360convert: not installed (pip install -r bench/requirements-python-bench.txt)")

    e2c_maps = cv2_e2c_maps()
    c2e_maps = cv2_c2e_maps()
    for dtype in (np.float32, np.uint8):
        name = np.dtype(dtype).name
        img = source(dtype)
        rows = {}
        plan = mb.Remap(img.shape, dst="cube", size=FACE, layout="separate")
        out = np.empty((6, FACE, FACE, 3), dtype)
        plan.apply(img, out=out)
        rows["mirrorball Remap.apply (planned, warm)"] = timed(lambda: plan.apply(img, out=out), a.reps)
        rows["mirrorball convert (plans each call)"] = timed(lambda: mb.convert(img, dst="cube", size=FACE, layout="separate"), a.reps)
        rows["mirrorball Remap plan + apply (cold)"] = timed(
            lambda: mb.Remap(img.shape, dst="cube", size=FACE, layout="separate").apply(img), a.reps
        )
        py_img = img

        def py360_cold():
            clear_py360_caches()
            py360convert.e2c(py_img, face_w=FACE, cube_format="list")

        rows["py360convert e2c cold"] = timed(py360_cold, a.reps)
        py360convert.e2c(py_img, face_w=FACE, cube_format="list")
        rows["py360convert e2c warm"] = timed(lambda: py360convert.e2c(py_img, face_w=FACE, cube_format="list"), a.reps)
        rows["cv2.remap, maps made beforehand"] = timed(
            lambda: [cv2.remap(img, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_WRAP) for mx, my in e2c_maps], a.reps
        )
        if pytorch360convert is not None and dtype == np.float32:
            t = torch.from_numpy(img).permute(2, 0, 1).contiguous()
            pytorch360convert.e2c(t, face_w=FACE)
            rows["pytorch360convert e2c (CPU)"] = timed(lambda: pytorch360convert.e2c(t, face_w=FACE), a.reps)
        report(f"e2c {name}: {W}x{H} -> 6x{FACE}²", rows, "mirrorball Remap.apply (planned, warm)")

        faces = plan.apply(img)
        cube_plan = mb.Remap((FACE, FACE), src="cube", src_layout="separate", dst="latlong", size=W)
        back = np.empty((H, W, 3), dtype)
        cube_plan.apply(faces, out=back)
        rows = {"mirrorball Remap.apply (planned, warm)": timed(lambda: cube_plan.apply(faces, out=back), a.reps)}
        rows["mirrorball convert (plans each call)"] = timed(
            lambda: mb.convert(faces, src="cube", src_layout="separate", dst="latlong", size=W), a.reps
        )
        py_faces = [np.ascontiguousarray(f) for f in mb.py360._to_py360(faces)]

        def py360_c2e_cold():
            clear_py360_caches()
            py360convert.c2e(py_faces, H, W, cube_format="list")

        rows["py360convert c2e cold"] = timed(py360_c2e_cold, a.reps)
        py360convert.c2e(py_faces, H, W, cube_format="list")
        rows["py360convert c2e warm"] = timed(lambda: py360convert.c2e(py_faces, H, W, cube_format="list"), a.reps)
        strip = np.concatenate(list(faces), axis=1)
        rows["cv2.remap, maps made beforehand"] = timed(
            lambda: cv2.remap(strip, c2e_maps[0], c2e_maps[1], cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE), a.reps
        )
        if pytorch360convert is not None and dtype == np.float32:
            tf = [torch.from_numpy(np.ascontiguousarray(f)).permute(2, 0, 1).contiguous() for f in py_faces]
            try:
                pytorch360convert.c2e(tf, H, W, cube_format="list")
                rows["pytorch360convert c2e (CPU)"] = timed(lambda: pytorch360convert.c2e(tf, H, W, cube_format="list"), a.reps)
            except Exception as e:  # its signature varies between versions
                print(f"pytorch360convert c2e: {e}")
        report(f"c2e {name}: 6x{FACE}² -> {W}x{H}", rows, "mirrorball Remap.apply (planned, warm)")


def report(title, rows, ours):
    print(f"\n{title}")
    base = rows[ours]
    for k, t in rows.items():
        ratio = "" if k == ours else f"  mirrorball warm is {t / base:5.2f}x faster"
        print(f"  {k:42s} {t * 1000:9.1f} ms{ratio}")


if __name__ == "__main__":
    main()
