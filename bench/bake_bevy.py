#!/usr/bin/env python3
"""`bake --for bevy` end to end against a numpy peer doing the same job, side by side.

    bash bench/setup.sh && bench/.venv/bin/python bench/bake_bevy.py [--input sky] [--reps 3]

The job: a 4096×2048 float EXR lat-long in, Bevy's two files out: `specular.ktx2`, a GGX
chain of 6×512² down to 1×1 (level m at perceptual roughness m/9), and `diffuse.ktx2`, a
6×32² Lambert cube (irradiance / π), both mirrored in z as Bevy samples them, BC6H
(unsigned), each level Zstandard level 3, in KTX2.

1. Builds `cargo build --release -p mirrorball-cli`
   (skip with --no-build) and makes bench/data/INPUT-4k.exr (git-ignored) as
   bench/prefilter_4k.py does: assets/env/INPUT.exr upsampled by `mirrorball convert`.
2. mirrorball: `MIRRORBALL_BAKE` below, one command, reading the file included.
3. The peer (this file, `peer_bake`): OpenEXR reads the file; cv2.remap resamples it to a
   6×512² cube (bilinear, peerlib's maps); a 2×2 box pyramid; each level filtered as Bevy's
   own runtime filter does it (bevy_pbr/src/light_probe/generate.rs:717-718: roughness
   mip/(n−1), 32·2^⌊4r⌋ GGX samples, and environment_filter.wesl: importance-sampled,
   N·L-weighted, each sample read from the pyramid level its pdf asks, Krivánek and Colbert's
   rule), the 32² Lambert cube by brute force over the 32² pyramid level (exact texel
   solid angles, prefilter_reference.cube_geometry); the z mirror; BC6H by Intel's ISPC
   kernel (PyPI `ispc-texcomp`, profile "basic", mirrorball's default effort, which runs the
   same kernel through `intel_tex_2`); Zstandard (PyPI `zstandard`); a KTX2 writer.
4. Wall clock of each, interpreter start-up and imports included for the peer: one untimed
   warm-up each, then --reps rounds taking turns; prints best and median and the ratio,
   and `mirrorball compare` of the two specular level 0s (which also reads the peer's file
   back) as a check that both did the same job.
"""

from __future__ import annotations

import argparse
import json
import shlex
import statistics
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
MB = ROOT / "target" / "release" / "mirrorball"

# The mirrorball side, one command line as a user runs it: IN and OUT are filled in.
MIRRORBALL_BAKE = f"{MB} bake {{IN}} --for bevy {{OUT}} --size 512 --encoding bc6h --zstd 3 --quiet"

SIZE = 512
DIFFUSE = 32
ZSTD_LEVEL = 3


# --------------------------------------------------------------------------------------
# The peer


def _sample(pyramid, level, d):
    """Bilinear lookup (clamped inside each face) of pyramid[level] (6×n×n×3) at
    directions d (k×3), OpenGL face selection."""
    import numpy as np

    cube = pyramid[level]
    n = cube.shape[1]
    x, y, z = d[:, 0], d[:, 1], d[:, 2]
    ax, ay, az = np.abs(x), np.abs(y), np.abs(z)
    is_x = (ax >= ay) & (ax >= az)
    is_y = ~is_x & (ay >= az)
    face = np.select([is_x & (x > 0), is_x, is_y & (y > 0), is_y, z > 0], [0, 1, 2, 3, 4], 5)
    sc = np.choose(face, [-z, z, x, x, x, -x])
    tc = np.choose(face, [-y, -y, z, -z, -y, -y])
    ma = np.select([is_x, is_y], [ax, ay], az)
    fx = np.clip((sc / ma + 1.0) * 0.5 * n - 0.5, 0.0, n - 1.0)
    fy = np.clip((tc / ma + 1.0) * 0.5 * n - 0.5, 0.0, n - 1.0)
    x0 = np.minimum(fx.astype(np.int32), n - 1)
    y0 = np.minimum(fy.astype(np.int32), n - 1)
    x1 = np.minimum(x0 + 1, n - 1)
    y1 = np.minimum(y0 + 1, n - 1)
    wx = (fx - x0)[:, None]
    wy = (fy - y0)[:, None]
    top = cube[face, y0, x0] * (1 - wx) + cube[face, y0, x1] * wx
    bot = cube[face, y1, x0] * (1 - wx) + cube[face, y1, x1] * wx
    return top * (1 - wy) + bot * wy


def _texel_dirs(n):
    import numpy as np
    from peerlib import _cube_face_points

    c = (np.arange(n) + 0.5) / n * 2.0 - 1.0
    sc, tc = np.meshgrid(c, c)
    d = np.stack([np.stack(_cube_face_points(f, sc, tc), axis=-1) for f in range(6)])
    return (d / np.linalg.norm(d, axis=-1, keepdims=True)).reshape(-1, 3)


def _ggx_level(pyramid, n, roughness):
    """Bevy's runtime filter for one level: 32·2^⌊4r⌋ Hammersley GGX samples about N = V,
    weighted by N·L, each read at lod ½·log2(6W²/(K·pdf))."""
    import numpy as np

    count = 32 * 2 ** int(roughness * 4)
    a = roughness * roughness
    a2 = a * a
    w = pyramid[0].shape[1]
    normal = _texel_dirs(n)
    up = np.where(np.abs(normal[:, 1:2]) < 0.999, [[0.0, 1.0, 0.0]], [[1.0, 0.0, 0.0]])
    t = np.cross(up, normal)
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    b = np.cross(normal, t)
    acc = np.zeros_like(normal)
    wsum = np.zeros(len(normal))
    for i in range(count):
        xi1 = i / count
        xi2 = int(f"{i:032b}"[::-1], 2) / 2**32
        cos_t = np.sqrt((1 - xi2) / (1 + (a2 - 1) * xi2))
        sin_t = np.sqrt(1 - cos_t * cos_t)
        phi = 2 * np.pi * xi1
        h = (sin_t * np.cos(phi)) * t + (sin_t * np.sin(phi)) * b + cos_t * normal
        n_l = 2 * cos_t * cos_t - 1
        if n_l <= 0:
            continue
        light = 2 * cos_t * h - normal
        dd = a2 / (np.pi * ((a2 - 1) * cos_t * cos_t + 1) ** 2)
        pdf = dd / 4
        lod = 0.5 * np.log2(6 * w * w / (count * pdf)) if roughness > 0 else 0.0
        level = int(np.clip(round(lod), 0, len(pyramid) - 1))
        acc += n_l * _sample(pyramid, level, light)
        wsum += n_l
    return (acc / wsum[:, None]).reshape(6, n, n, 3)


def _lambert(pyramid):
    import numpy as np
    from prefilter_reference import cube_geometry

    src_dirs, omega = cube_geometry(DIFFUSE)
    radiance = next(p for p in pyramid if p.shape[1] == DIFFUSE).reshape(-1, 3)
    out = _texel_dirs(DIFFUSE)
    k = np.maximum(out @ src_dirs.T, 0.0) * omega[None, :]
    return ((k @ radiance) / np.pi).reshape(6, DIFFUSE, DIFFUSE, 3)


def _mirror_z(cube):
    """Bevy's cube: ±X and ±Z mirrored left to right (and +Z, −Z swapped), ±Y top to bottom."""
    import numpy as np

    f = [cube[0][:, ::-1], cube[1][:, ::-1], cube[2][::-1], cube[3][::-1],
         cube[5][:, ::-1], cube[4][:, ::-1]]
    return np.ascontiguousarray(np.stack(f))


def _bc6h(face):
    import ispc_texcomp as itc
    import numpy as np

    n = face.shape[0]
    if n < 4:
        face = np.pad(face, ((0, 4 - n), (0, 4 - n), (0, 0)), mode="edge")
    rgba = np.concatenate([face, np.ones(face.shape[:2] + (1,))], axis=-1).astype(np.float16)
    m = rgba.shape[0]
    surface = itc.RGBASurface(rgba.tobytes(), m, m, m * 8)
    return itc.compress_blocks_bc6h(surface, itc.BC6HEncSettings.from_profile("basic"))


def _write_ktx2(path, levels):
    """KTX2: BC6H_UFLOAT cube, each level Zstandard-compressed, smallest level last in the
    index and first in the file."""
    import zstandard

    raw = [b"".join(_bc6h(face) for face in level) for level in levels]
    comp = [zstandard.ZstdCompressor(level=ZSTD_LEVEL).compress(r) for r in raw]
    # Basic DFD as mirrorball-io's data_format_descriptor: BC6H model 133, BT709, linear.
    dfd_block = struct.pack("<IHHBBBB4B8B", 0, 2, 40, 133, 1, 1, 0, 3, 3, 0, 0, *[0] * 8)
    dfd_block += struct.pack("<I4BII", 0 | 127 << 16 | 0x80 << 24, 0, 0, 0, 0, 0,
                             0x3F800000)
    dfd = struct.pack("<I", 4 + len(dfd_block)) + dfd_block
    n_levels = len(levels)
    dfd_off = 80 + 24 * n_levels
    data = dfd_off + len(dfd)
    index, body, cursor = [None] * n_levels, b"", data
    for p in reversed(range(n_levels)):
        index[p] = struct.pack("<QQQ", cursor, len(comp[p]), len(raw[p]))
        body += comp[p]
        cursor += len(comp[p])
    head = bytes([0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A])
    size = levels[0].shape[1]
    head += struct.pack("<13I", 143, 1, size, size, 0, 0, 6, n_levels, 2, dfd_off, len(dfd),
                        0, 0)
    head += struct.pack("<QQ", 0, 0)
    Path(path).write_bytes(head + b"".join(index) + dfd + body)


def peer_bake(src: str, out: str) -> None:
    import cv2
    import numpy as np
    from peerlib import cube_from_latlong_maps, read_exr_rgb

    latlong = read_exr_rgb(src)
    h, w = latlong.shape[:2]
    mx, my = cube_from_latlong_maps(SIZE, w, h)
    atlas = cv2.remap(latlong, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_WRAP)
    cube = np.maximum(atlas.reshape(6, SIZE, SIZE, 3).astype(np.float64), 0.0)
    pyramid = [cube]
    while pyramid[-1].shape[1] > 1:
        c = pyramid[-1]
        m = c.shape[1] // 2
        pyramid.append(c.reshape(6, m, 2, m, 2, 3).mean(axis=(2, 4)))
    n_levels = len(pyramid)
    specular = [pyramid[0]] + [
        _ggx_level(pyramid, SIZE >> m, m / (n_levels - 1)) for m in range(1, n_levels)
    ]
    Path(out).mkdir(parents=True, exist_ok=True)
    _write_ktx2(Path(out) / "specular.ktx2", [_mirror_z(c) for c in specular])
    _write_ktx2(Path(out) / "diffuse.ktx2", [_mirror_z(_lambert(pyramid))])


# --------------------------------------------------------------------------------------
# The comparison


def timed(cmd):
    t = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"failed: {shlex.join(cmd)}\n{r.stdout}{r.stderr}")
    return time.perf_counter() - t


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--input", default="sky", choices=["sky", "city", "studio", "venice"])
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--no-build", action="store_true")
    ap.add_argument("--peer-only", nargs=2, metavar=("IN", "OUT"), help=argparse.SUPPRESS)
    ap.add_argument("--json", type=Path, default=HERE / "results" / "bake-bevy.json")
    args = ap.parse_args()
    if args.peer_only:
        sys.path.insert(0, str(HERE))
        peer_bake(*args.peer_only)
        return 0
    if not args.no_build:
        subprocess.run(["cargo", "build", "--release", "-p", "mirrorball-cli", "--bin",
                        "mirrorball"], cwd=ROOT, check=True)
    sys.path.insert(0, str(HERE))
    from prefilter_4k import make_input

    src = make_input(args.input)
    with tempfile.TemporaryDirectory() as tmp:
        ours_dir, peer_dir = Path(tmp) / "mirrorball", Path(tmp) / "peer"
        ours = shlex.split(MIRRORBALL_BAKE.format(IN=src, OUT=ours_dir))
        peer = [sys.executable, __file__, "--peer-only", str(src), str(peer_dir)]
        times = {"mirrorball": [], "peer": []}
        timed(ours), timed(peer)  # warm-up
        for _ in range(args.reps):
            times["mirrorball"].append(timed(ours))
            times["peer"].append(timed(peer))
        cmp = subprocess.run([str(MB), "compare", str(ours_dir / "specular.ktx2"),
                              str(peer_dir / "specular.ktx2")],
                             capture_output=True, text=True)
        agreement = (cmp.stdout + cmp.stderr).strip()
        sizes = {k: {f: (d / f).stat().st_size for f in ("specular.ktx2", "diffuse.ktx2")}
                 for k, d in (("mirrorball", ours_dir), ("peer", peer_dir))}
    best = {k: min(v) for k, v in times.items()}
    med = {k: statistics.median(v) for k, v in times.items()}
    print(f"bake --for bevy, {src.name} → 6×{SIZE}² GGX chain + 6×{DIFFUSE}² Lambert, "
          f"BC6H + zstd {ZSTD_LEVEL}, end to end, {args.reps} rounds")
    for k in times:
        print(f"  {k:10} best {best[k]:7.2f} s  median {med[k]:7.2f} s  "
              f"files {sizes[k]['specular.ktx2'] / 1e6:.2f} + "
              f"{sizes[k]['diffuse.ktx2'] / 1e3:.1f} kB")
    print(f"  ratio (peer / mirrorball): best {best['peer'] / best['mirrorball']:.1f}×, "
          f"median {med['peer'] / med['mirrorball']:.1f}×")
    print(f"  specular level 0, mirrorball vs peer (`mirrorball compare`): {agreement}")
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps({"times": times, "best": best, "median": med,
                                     "sizes": sizes, "level0_compare": agreement}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
