"""mirrorball: environment maps and 360° panoramas for numpy.

Every projection mirrorball knows, both ways, with antialiasing; OpenEXR, Radiance HDR,
PNG, JPEG, WebP, KTX2 and DDS files; prefiltered lighting and engine bakes; rigs of
perspective views with the camera files COLMAP and nerfstudio read (:func:`views`). The work is
the Rust workspace's (the same code as the ``mirrorball`` command line, bit for bit): this
package holds no conversion logic of its own.

Arrays are H×W×C (C = 3 or 4) or batches N×H×W×C, float32, float16, uint8 or uint16,
C-contiguous or not. uint8 and uint16 arrays are sRGB codes, read and written as the
command line reads and writes PNG; pass ``linear=True`` to treat them as linear codes
(code / 255, code / 65535). The result keeps the input's dtype unless ``dtype=`` says
otherwise. The GIL is released while the work runs, Ctrl-C stops a long call, and the
thread count is :func:`set_threads`'s.

Errors: a bad argument raises ``ValueError`` (or ``TypeError``) naming it; a file whose
content cannot be used raises :class:`InputError` (a ``ValueError``); a missing or
unreadable file raises the ``OSError`` Python raises (``FileNotFoundError``,
``PermissionError``).

py360convert users: :func:`e2c`, :func:`c2e`, :func:`e2p` and :func:`c2p` take
py360convert's arguments and give its face order and layouts (see ``mirrorball.py360``).
"""

from ._native import (
    InputError,
    Remap,
    __version__,
    bake,
    convert,
    cut_views,
    get_threads,
    prefilter,
    projections,
    read,
    set_threads,
    sh9,
    views,
    write,
)
from .py360 import c2e, c2p, e2c, e2p

__all__ = [
    "InputError",
    "Remap",
    "__version__",
    "bake",
    "c2e",
    "c2p",
    "convert",
    "cut_views",
    "e2c",
    "e2p",
    "get_threads",
    "prefilter",
    "projections",
    "read",
    "set_threads",
    "sh9",
    "views",
    "write",
]
