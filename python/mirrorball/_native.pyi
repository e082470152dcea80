"""Type stubs of mirrorball's native module (re-exported by ``mirrorball``)."""

import os
from typing import Any, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[Any]
PathLike = Union[str, "os.PathLike[str]"]
DTypeLike = Optional[npt.DTypeLike]

__version__: str

class InputError(ValueError):
    """A file (or data) whose content mirrorball cannot use."""

def set_threads(n: Optional[int] = None) -> None:
    """Threads mirrorball's calls use: n ≥ 1, or None for one per core."""

def get_threads() -> int:
    """How many threads mirrorball's calls use."""

def projections() -> list[str]:
    """The projection names ``src`` and ``dst`` take."""

def convert(
    array: Array,
    src: Optional[str] = None,
    dst: Optional[str] = None,
    size: Optional[int] = None,
    layout: Optional[str] = None,
    *,
    src_layout: Optional[str] = None,
    yaw: float = 0.0,
    pitch: float = 0.0,
    roll: float = 0.0,
    exposure: float = 0.0,
    max_samples: int = 8,
    outside: Optional[str] = None,
    v360: Optional[str] = None,
    dtype: DTypeLike = None,
    linear: bool = False,
    invalid: str = "raise",
    out: Optional[Array] = None,
) -> Array:
    """Converts an environment map (H×W×C or N×H×W×C) from ``src`` (default ``"latlong"``)
    to ``dst`` (default ``"cube"``), antialiased: the CLI's ``mirrorball convert``, bit for
    bit. ``outside``: what texels outside the output's covered part hold, ``"black"`` or
    ``"rim"`` (the CLI's ``--outside``; default: black for fisheye, dual fisheye, Hammer and
    sinusoidal, the rim's value for sphere, angular and paraboloid maps). ``v360``: FFmpeg's
    v360 filter options (``"e:eac:yaw=30:w=3840:h=2160"``, the CLI's ``--v360``) in place of
    ``src``, ``dst``, ``src_layout``, ``layout``, ``yaw``, ``pitch``, ``roll`` and, with
    ``w`` and ``h``, ``size``; refused beside them."""

class Remap:
    """A conversion planned once for sources of one shape, applied to many arrays."""

    def __init__(
        self,
        src_shape: Sequence[int],
        src: Optional[str] = None,
        dst: Optional[str] = None,
        size: Optional[int] = None,
        layout: Optional[str] = None,
        *,
        src_layout: Optional[str] = None,
        yaw: float = 0.0,
        pitch: float = 0.0,
        roll: float = 0.0,
        exposure: float = 0.0,
        max_samples: int = 8,
        outside: Optional[str] = None,
        v360: Optional[str] = None,
    ) -> None: ...
    def apply(
        self,
        array: Array,
        out: Optional[Array] = None,
        *,
        dtype: DTypeLike = None,
        linear: bool = False,
        invalid: str = "raise",
    ) -> Array:
        """Converts ``array`` (or a batch) into a new array, or into ``out``."""
    def output_shape(self, c: int = 3) -> list[int]:
        """One result's shape for ``c`` channels."""
    @property
    def nbytes(self) -> int:
        """Bytes the plan holds."""
    @property
    def dst(self) -> str:
        """The output projection's text."""

def read(path: PathLike, *, dtype: DTypeLike = None, linear: bool = False) -> tuple[Array, dict[str, Any]]:
    """Reads a map: ``(array, info)``; info has "projection", "layout", "decided", "format",
    "description", "invalid"."""

def write(
    path: PathLike,
    array: Array,
    *,
    projection: Optional[str] = None,
    layout: Optional[str] = None,
    precision: Optional[str] = None,
    compression: Optional[str] = None,
    quality: int = 92,
    linear: bool = False,
    invalid: str = "raise",
) -> list[str]:
    """Writes ``array`` to ``path`` (the extension picks the container), atomically."""

def prefilter(
    array: Array,
    lobe: str,
    *,
    src: str = "latlong",
    dst: str = "cube",
    size: Optional[int] = None,
    levels: Optional[int] = None,
    mapping: str = "linear",
    samples: int = 128,
    cube_size: Optional[int] = None,
    irradiance: str = "exact",
    layout: Optional[str] = None,
    src_layout: Optional[str] = None,
    dtype: DTypeLike = None,
    linear: bool = False,
    invalid: str = "raise",
) -> list[Array]:
    """Prefiltered lighting, one array per mip level: the CLI's ``mirrorball prefilter``."""

def sh9(
    array: Array,
    *,
    src: str = "latlong",
    src_layout: Optional[str] = None,
    linear: bool = False,
    invalid: str = "raise",
) -> npt.NDArray[np.float64]:
    """The radiance's nine SH coefficients, 9×3."""

def bake(
    array: Array,
    engine: str,
    out_dir: PathLike,
    *,
    src: str = "latlong",
    size: int = 256,
    encoding: Optional[str] = None,
    effort: str = "basic",
    zstd: Optional[int] = None,
    background_size: Optional[int] = None,
    samples: int = 128,
    source: str = "",
    overwrite: bool = False,
    src_layout: Optional[str] = None,
    linear: bool = False,
    invalid: str = "raise",
) -> list[str]:
    """Image-based lighting baked for ``engine`` into ``out_dir``: the CLI's ``mirrorball bake``."""

def views(
    src: PathLike,
    out_dir: PathLike,
    *,
    rig: str = "cube",
    size: Union[int, tuple[int, int], None] = None,
    format: str = "png",
    masks: bool = False,
    mask: Optional[PathLike] = None,
    max_samples: Optional[int] = None,
    overwrite: bool = False,
    projection: Optional[str] = None,
    layout: Optional[str] = None,
) -> list[str]:
    """A panorama (or a sequence's pattern) cut into a rig of views with COLMAP's and
    nerfstudio's camera files in ``out_dir``: the CLI's ``mirrorball views``, byte for byte."""

def cut_views(
    array: Array,
    *,
    src: str = "latlong",
    rig: str = "cube",
    size: Union[int, tuple[int, int], None] = None,
    max_samples: Optional[int] = None,
    src_layout: Optional[str] = None,
    dtype: DTypeLike = None,
    linear: bool = False,
    invalid: str = "raise",
) -> list[dict[str, Any]]:
    """A panorama array cut into the rig's views in memory: per view "name", "image",
    "model", "K" (3×3 intrinsics) and "R" (3×3 cam_from_world, COLMAP's world)."""
