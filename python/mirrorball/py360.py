"""py360convert's functions on mirrorball: ``e2c``, ``c2e``, ``e2p`` and ``c2p`` take
py360convert's arguments and give its shapes, face order and layouts, so that moving over is
one import (``import mirrorball as py360convert``). The conversions are mirrorball's
(antialiased: each output texel filtered over its footprint, bilinear inside it).

Conventions, py360convert's against mirrorball's:

* **Axes.** py360convert's equirectangular centre looks along its +Z, mirrorball's along
  -Z; both put +X to the right of the centre and +Y up. So py360convert's ``(x, y, z)`` is
  mirrorball's ``(x, y, -z)``, and the two read the same equirectangular picture alike.
* **Faces.** py360convert's order is F R B L U D (front = the picture's centre), each face
  as seen from inside the cube, upright. mirrorball's cube is OpenGL's: +X -X +Y -Y +Z -Z,
  each face stored as OpenGL reads it. Face by face: F is mirrorball's -Z face mirrored left
  to right, R is +X mirrored left to right, B is +Z mirrored, L is -X mirrored, U is +Y
  upside down, D is -Y upside down (tested against py360convert itself).
* **Layouts** (``cube_format``): "horizon" (faces side by side F R B L U D, ``w×6w``),
  "list" (six ``w×w`` arrays), "dict" (keys "F" "R" "B" "L" "U" "D"), "dice" (a 4×3 cross:
  U above F, L F R B across, D below F).
* **Texel centres.** mirrorball samples a face's texel ``i`` of ``n`` at ``(i + 0.5)/n``;
  py360convert at ``i/(n - 1)`` (its corners on the cube's edges), so the two differ by up to
  half a texel near face edges.
* **mode.** Only "bilinear" (mirrorball's filter); "nearest" is refused (use
  ``mirrorball.convert(..., max_samples=1)`` for plain bilinear lookups).
* **dtypes.** float32, float16, uint8 and uint16 arrays keep their dtype (uint8/uint16 as
  sRGB codes, like mirrorball's other functions; ``linear=True`` treats them as linear
  codes as py360convert does); float64 is converted through float32 and given back as
  float64. Any number of channels: they are converted three at a time; a 2-D array gives
  a 2-D result.
* **Sizes.** ``c2e``'s ``w`` must be ``2 h`` (mirrorball's lat-long is 2:1). ``e2p``'s view
  keeps square texels: with one ``fov_deg`` the output must be square; give
  ``fov_deg=(h_fov, v_fov)`` for other shapes (``tan(v/2)/tan(h/2) = h/w``).
"""

from __future__ import annotations

import math
from typing import Any, Sequence, Union

import numpy as np

from . import _native

FACES = "FRBLUD"
# py360convert's face k is mirrorball's layer GL[k], mirrored as FLIP[k] says.
GL = (5, 0, 4, 1, 2, 3)
FLIP = ("lr", "lr", "lr", "lr", "ud", "ud")
# Where "dice" puts each face (column, row), in FRBLUD order.
DICE = ((1, 1), (2, 1), (3, 1), (0, 1), (1, 0), (1, 2))


def _check_mode(mode: str) -> None:
    if mode != "bilinear":
        raise ValueError(
            f"mode: {mode!r}; mirrorball filters each texel over its footprint ('bilinear'); "
            "for plain bilinear lookups use mirrorball.convert(..., max_samples=1)"
        )


def _channels(arr: np.ndarray, fn, linear: bool) -> np.ndarray:
    """Runs ``fn`` (H×W×3 or ×4 → array) over ``arr``'s channels, three at a time, keeping
    2-D arrays 2-D and float64 float64."""
    if not isinstance(arr, np.ndarray):
        raise TypeError(f"array: a numpy array is needed, not {type(arr).__name__}")
    squeeze = arr.ndim == 2
    if squeeze:
        arr = arr[..., None]
    back = None
    if arr.dtype == np.float64:
        arr, back = arr.astype(np.float32), np.float64
    c = arr.shape[-1]
    if c in (3, 4):
        out = fn(arr)
    else:
        parts = []
        for k in range(0, c, 3):
            chunk = arr[..., k : k + 3]
            n = chunk.shape[-1]
            if n < 3:
                chunk = np.concatenate([chunk] + [chunk[..., :1]] * (3 - n), axis=-1)
            parts.append(fn(chunk)[..., :n])
        out = np.concatenate(parts, axis=-1)
    if back is not None:
        out = out.astype(back)
    return out[..., 0] if squeeze else out


def _to_py360(faces: np.ndarray) -> list[np.ndarray]:
    """mirrorball's six layers (6×n×n×C, OpenGL order) as py360convert's FRBLUD faces."""
    out = []
    for layer, flip in zip(GL, FLIP):
        f = faces[layer]
        out.append(np.ascontiguousarray(f[:, ::-1] if flip == "lr" else f[::-1]))
    return out


def _from_py360(faces: Sequence[np.ndarray]) -> np.ndarray:
    """py360convert's FRBLUD faces as mirrorball's layers (6×n×n×C)."""
    layers: list[Any] = [None] * 6
    for f, layer, flip in zip(faces, GL, FLIP):
        layers[layer] = f[:, ::-1] if flip == "lr" else f[::-1]
    return np.stack(layers)


def _cube_format(faces: list[np.ndarray], cube_format: str):
    if cube_format == "list":
        return faces
    if cube_format == "dict":
        return dict(zip(FACES, faces))
    if cube_format == "horizon":
        return np.concatenate(faces, axis=1)
    if cube_format == "dice":
        w = faces[0].shape[0]
        dice = np.zeros((3 * w, 4 * w) + faces[0].shape[2:], faces[0].dtype)
        for (x, y), f in zip(DICE, faces):
            dice[y * w : (y + 1) * w, x * w : (x + 1) * w] = f
        return dice
    raise ValueError(f"cube_format: {cube_format!r}; give 'horizon', 'list', 'dict' or 'dice'")


def _faces_of(cubemap, cube_format: str) -> list[np.ndarray]:
    if cube_format == "list":
        if not isinstance(cubemap, (list, tuple)) or len(cubemap) != 6:
            raise TypeError("cubemap: six arrays are needed for cube_format='list'")
        return [np.asarray(f) for f in cubemap]
    if cube_format == "dict":
        if not isinstance(cubemap, dict):
            raise TypeError("cubemap: a dict with keys F R B L U D is needed for cube_format='dict'")
        missing = [k for k in FACES if k not in cubemap]
        if missing:
            raise ValueError(f"cubemap: no face {', '.join(missing)} (keys F R B L U D)")
        return [np.asarray(cubemap[k]) for k in FACES]
    if not isinstance(cubemap, np.ndarray):
        raise TypeError(f"cubemap: a numpy array is needed for cube_format={cube_format!r}")
    if cube_format == "horizon":
        w = cubemap.shape[0]
        if cubemap.shape[1] != 6 * w:
            raise ValueError(f"cubemap: shape {cubemap.shape}; 'horizon' is w×6w")
        return [cubemap[:, k * w : (k + 1) * w] for k in range(6)]
    if cube_format == "dice":
        w = cubemap.shape[0] // 3
        if cubemap.shape[0] != 3 * w or cubemap.shape[1] != 4 * w:
            raise ValueError(f"cubemap: shape {cubemap.shape}; 'dice' is 3w×4w")
        return [cubemap[y * w : (y + 1) * w, x * w : (x + 1) * w] for x, y in DICE]
    raise ValueError(f"cube_format: {cube_format!r}; give 'horizon', 'list', 'dict' or 'dice'")


def e2c(
    e_img: np.ndarray,
    face_w: int = 256,
    mode: str = "bilinear",
    cube_format: str = "dice",
    *,
    linear: bool = False,
) -> Union[np.ndarray, list[np.ndarray], dict[str, np.ndarray]]:
    """Equirectangular (H×W[×C]) to a cube map of ``face_w`` faces, as py360convert's
    ``e2c``: faces F R B L U D in ``cube_format`` 'dice' (default), 'horizon', 'list' or
    'dict'."""
    _check_mode(mode)

    def one(a):
        layers = _native.convert(a, src="latlong", dst="cube", size=face_w, layout="separate", linear=linear)
        return np.concatenate(_to_py360(layers), axis=1)

    horizon = _channels(e_img, one, linear)
    w = horizon.shape[0]
    faces = [horizon[:, k * w : (k + 1) * w] for k in range(6)]
    return _cube_format(faces, cube_format)


def c2e(
    cubemap,
    h: int,
    w: int,
    mode: str = "bilinear",
    cube_format: str = "dice",
    *,
    linear: bool = False,
) -> np.ndarray:
    """A cube map (py360convert's faces and ``cube_format``) to an ``h``×``w``
    equirectangular picture, as py360convert's ``c2e`` (``w`` must be ``2 h``)."""
    _check_mode(mode)
    if w != 2 * h:
        raise ValueError(f"w: {w}; mirrorball's lat-long is 2:1, so w must be 2·h = {2 * h}")
    faces = _faces_of(cubemap, cube_format)
    squeeze = faces[0].ndim == 2
    stacked = _from_py360([f[..., None] if squeeze else f for f in faces])
    # Channels last of each layer: run them through _channels as one tall picture.
    n = stacked.shape[1]
    tall = stacked.reshape((6 * n,) + stacked.shape[2:])

    def one(a):
        layers = a.reshape((6, n) + a.shape[1:])
        return _native.convert(layers, src="cube", src_layout="separate", dst="latlong", size=w, linear=linear)

    out = _channels(tall, one, linear)
    return out[..., 0] if squeeze else out


def _view(fov_deg, u_deg: float, v_deg: float, out_hw, in_rot_deg: float) -> tuple[str, int]:
    """The perspective spec and size of py360convert's view arguments."""
    if isinstance(fov_deg, (tuple, list)):
        h_fov, v_fov = (float(x) for x in fov_deg)
    else:
        h_fov = v_fov = float(fov_deg)
    out_h, out_w = (int(x) for x in out_hw)
    if not (0 < h_fov < 180 and 0 < v_fov < 180):
        raise ValueError(f"fov_deg: {fov_deg}; each field of view in (0, 180) degrees")
    want_h = round(out_w * math.tan(math.radians(v_fov) / 2) / math.tan(math.radians(h_fov) / 2))
    if want_h != out_h:
        raise ValueError(
            f"out_hw: {out_hw} with fov_deg {fov_deg}: mirrorball's texels are square, so a "
            f"{out_w}-wide view of these fields of view is {want_h} high; give fov_deg=(h_fov, v_fov) "
            f"with tan(v_fov/2)/tan(h_fov/2) = {out_h}/{out_w}"
        )
    spec = f"perspective:hfov={h_fov!r}:vfov={v_fov!r}:yaw={float(u_deg)!r}:pitch={float(v_deg)!r}:roll={float(in_rot_deg)!r}"
    return spec, out_w


def e2p(
    e_img: np.ndarray,
    fov_deg,
    u_deg: float,
    v_deg: float,
    out_hw,
    in_rot_deg: float = 0,
    mode: str = "bilinear",
    *,
    linear: bool = False,
) -> np.ndarray:
    """Equirectangular to a perspective view, as py360convert's ``e2p``: ``fov_deg`` (one,
    or (h_fov, v_fov)), ``u_deg`` (+ right), ``v_deg`` (+ up), ``out_hw``, ``in_rot_deg``."""
    _check_mode(mode)
    spec, size = _view(fov_deg, u_deg, v_deg, out_hw, in_rot_deg)
    return _channels(e_img, lambda a: _native.convert(a, src="latlong", dst=spec, size=size, linear=linear), linear)


def c2p(
    cubemap,
    fov_deg,
    u_deg: float,
    v_deg: float,
    out_hw,
    in_rot_deg: float = 0,
    mode: str = "bilinear",
    cube_format: str = "dice",
    *,
    linear: bool = False,
) -> np.ndarray:
    """A cube map (py360convert's faces and ``cube_format``) to a perspective view, with
    ``e2p``'s view arguments (py360convert has no ``c2p``: this is its ``e2p`` read from a
    cube)."""
    _check_mode(mode)
    spec, size = _view(fov_deg, u_deg, v_deg, out_hw, in_rot_deg)
    faces = _faces_of(cubemap, cube_format)
    squeeze = faces[0].ndim == 2
    stacked = _from_py360([f[..., None] if squeeze else f for f in faces])
    n = stacked.shape[1]
    tall = stacked.reshape((6 * n,) + stacked.shape[2:])

    def one(a):
        layers = a.reshape((6, n) + a.shape[1:])
        return _native.convert(layers, src="cube", src_layout="separate", dst=spec, size=size, linear=linear)

    out = _channels(tall, one, linear)
    return out[..., 0] if squeeze else out
