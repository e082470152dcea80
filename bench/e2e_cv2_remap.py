"""End-to-end peer: lat-long EXR → six cube faces with OpenCV's cv2.remap.

    python bench/e2e_cv2_remap.py IN.exr OUT_DIR [FACE=1024]

Reads the EXR (OpenEXR package), computes the remap coordinate maps in this run (OpenGL
cube convention, see peerlib.py), remaps with INTER_LINEAR / BORDER_WRAP, and writes the six
faces as float32 .npy files OUT_DIR/{px,nx,py,ny,pz,nz}.npy. Timed as a whole process
(interpreter start-up and imports included) by convert_peers.py.
"""

import os
import sys

import cv2
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import peerlib  # noqa: E402


def main() -> None:
    src, out_dir = sys.argv[1], sys.argv[2]
    n = int(sys.argv[3]) if len(sys.argv) > 3 else 1024
    img = peerlib.read_exr_rgb(src)
    h, w = img.shape[:2]
    mx, my = peerlib.cube_from_latlong_maps(n, w, h)
    atlas = cv2.remap(img, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_WRAP)
    os.makedirs(out_dir, exist_ok=True)
    for f, name in enumerate(peerlib.FACE_NAMES):
        np.save(os.path.join(out_dir, name + ".npy"), atlas[f * n : (f + 1) * n])


if __name__ == "__main__":
    main()
