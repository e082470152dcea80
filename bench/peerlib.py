"""Shared helpers for the conversion benchmark's Python peers.

Everything here uses the same conventions as mirrorball, so the peers' maps are directly
comparable with its own (though each peer only ever round-trips through its own cube):

* lat-long: row 0 is the +Y pole; u = (x + 0.5) / W, longitude = 2π(u − ½), so the middle
  column looks along −Z and u = ¾ along +X; direction
  d = (sin λ cos φ, sin φ, −cos λ cos φ), φ = π(½ − v).
* cube: OpenGL's faces and order (+X −X +Y −Y +Z −Z) and its major-axis table; face row 0 is
  t = 0. The six faces are stacked top to bottom into one (6N × N) atlas, so a single
  cv2.remap call makes or reads the whole cube.

Only numpy is imported at module level, so the end-to-end scripts pay for exactly the
libraries they use.
"""

from __future__ import annotations

import numpy as np

FACE_NAMES = ("px", "nx", "py", "ny", "pz", "nz")


# --------------------------------------------------------------------------------------
# EXR input


def read_exr_rgb(path: str) -> np.ndarray:
    """Reads an EXR's R, G, B channels as a float32 H×W×3 array (OpenEXR PyPI package)."""
    import OpenEXR

    with OpenEXR.File(str(path)) as f:
        ch = f.channels()
        if "RGB" in ch:
            px = ch["RGB"].pixels
        elif "RGBA" in ch:
            px = ch["RGBA"].pixels[..., :3]
        else:
            px = np.stack([ch[c].pixels for c in ("R", "G", "B")], axis=-1)
    if px.dtype != np.float32:
        px = px.astype(np.float32)
    return np.ascontiguousarray(px)


# --------------------------------------------------------------------------------------
# Directions


def _cube_face_points(face: int, sc: np.ndarray, tc: np.ndarray):
    """OpenGL's inverse major-axis table: the cube point for face coordinates sc, tc."""
    one = np.ones_like(sc)
    return {
        0: (one, -tc, -sc),  # +X
        1: (-one, -tc, sc),  # -X
        2: (sc, one, tc),  # +Y
        3: (sc, -one, -tc),  # -Y
        4: (sc, -tc, one),  # +Z
        5: (-sc, -tc, -one),  # -Z
    }[face]


def latlong_dirs(w: int, h: int):
    """Unit directions (x, y, z), each h×w float64, of the lat-long texel centres."""
    lon = 2.0 * np.pi * ((np.arange(w) + 0.5) / w - 0.5)
    lat = np.pi * (0.5 - (np.arange(h) + 0.5) / h)
    sl, cl = np.sin(lon)[None, :], np.cos(lon)[None, :]
    sp, cp = np.sin(lat)[:, None], np.cos(lat)[:, None]
    return sl * cp, np.broadcast_to(sp, (h, w)), -cl * cp


# --------------------------------------------------------------------------------------
# cv2.remap coordinate maps (pixel centres at integer coordinates, as OpenCV expects)


def cube_from_latlong_maps(n: int, w: int, h: int):
    """Maps for cv2.remap: lat-long (w×h) → cube atlas (6n rows × n columns), float32.

    x may run half a texel past either side (use BORDER_WRAP for the longitude seam); y is
    clamped to the first and last rows, so the poles never wrap to the opposite edge.
    """
    c = (np.arange(n) + 0.5) / n * 2.0 - 1.0
    sc, tc = np.meshgrid(c, c)  # row j ↔ tc, column i ↔ sc
    mx = np.empty((6 * n, n), np.float32)
    my = np.empty((6 * n, n), np.float32)
    for f in range(6):
        x, y, z = _cube_face_points(f, sc, tc)
        lon = np.arctan2(x, -z)
        lat = np.arctan2(y, np.hypot(x, z))
        mx[f * n : (f + 1) * n] = (lon / (2.0 * np.pi) + 0.5) * w - 0.5
        my[f * n : (f + 1) * n] = np.clip((0.5 - lat / np.pi) * h - 0.5, 0.0, h - 1.0)
    return mx, my


def latlong_from_cube_maps(n: int, w: int, h: int):
    """Maps for cv2.remap: cube atlas (6n × n) → lat-long (w×h), float32.

    Each lookup is clamped inside its own face, so bilinear filtering never reads the next
    face of the atlas (faces are clamped at their edges, not joined: within half a texel of
    a cube edge the value is the edge texel's).
    """
    x, y, z = latlong_dirs(w, h)
    ax, ay, az = np.abs(x), np.abs(y), np.abs(z)
    is_x = (ax >= ay) & (ax >= az)
    is_y = ~is_x & (ay >= az)
    is_z = ~is_x & ~is_y
    face = np.select(
        [is_x & (x >= 0), is_x, is_y & (y >= 0), is_y, is_z & (z >= 0)], [0, 1, 2, 3, 4], 5
    )
    sc = np.select(
        [face == 0, face == 1, face == 2, face == 3, face == 4], [-z, z, x, x, x], -x
    )
    tc = np.select(
        [face == 0, face == 1, face == 2, face == 3, face == 4], [-y, -y, z, -z, -y], -y
    )
    ma = np.select([is_x, is_y], [ax, ay], az)
    s = (sc / ma + 1.0) * 0.5
    t = (tc / ma + 1.0) * 0.5
    mx = np.clip(s * n - 0.5, 0.0, n - 1.0)
    my = np.clip(t * n - 0.5, 0.0, n - 1.0) + face * n
    return mx.astype(np.float32), my.astype(np.float32)


# --------------------------------------------------------------------------------------
# Quality: the same log-domain PSNR as mirrorball_core::metrics::log_psnr


def latlong_row_solid_angles(w: int, h: int) -> np.ndarray:
    """Exact solid angle of one texel in each row: 2π/W · (sin φ_top − sin φ_bottom)."""
    y = np.arange(h, dtype=np.float64)
    top = np.pi * (0.5 - y / h)
    bot = np.pi * (0.5 - (y + 1.0) / h)
    return 2.0 * np.pi / w * (np.sin(top) - np.sin(bot))


def log_psnr(reference: np.ndarray, test: np.ndarray) -> float:
    """Log-domain PSNR (dB) of `test` against `reference`, both lat-long H×W×(3|4).

    Mirrors mirrorball_core::metrics::log_psnr exactly: each colour value x becomes
    ln(1 + max(x, 0)) (NaN counts as 0, as Rust's f32::max does); squared errors are
    weighted by each texel's exact solid angle (a value pair with an infinity is left out of
    the sum but its weight still counts); peak = the reference's largest log value;
    PSNR = 10 log10(peak² / MSE).
    """
    if reference.shape[:2] != test.shape[:2]:
        raise ValueError(f"shape mismatch: {reference.shape} vs {test.shape}")
    h, w = reference.shape[:2]
    wt = latlong_row_solid_angles(w, h)
    se = 0.0
    peak = 0.0
    # Row blocks keep the float64 temporaries small.
    for y0 in range(0, h, 256):
        y1 = min(h, y0 + 256)
        la = np.log1p(np.fmax(reference[y0:y1, :, :3].astype(np.float64), 0.0))
        lb = np.log1p(np.fmax(test[y0:y1, :, :3].astype(np.float64), 0.0))
        fin = np.isfinite(la) & np.isfinite(lb)
        d2 = np.where(fin, (la - lb) ** 2, 0.0)
        se += float(np.sum(d2.sum(axis=(1, 2)) * wt[y0:y1]))
        if fin.any():
            peak = max(peak, float(np.max(np.where(fin, la, 0.0))))
    wsum = 3.0 * w * float(wt.sum())
    mse = se / max(wsum, np.finfo(np.float64).tiny)
    if mse == 0.0:
        return float("inf")
    return 10.0 * float(np.log10(peak * peak / mse))
