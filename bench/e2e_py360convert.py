"""End-to-end peer: lat-long EXR → six cube faces with py360convert.e2c.

    python bench/e2e_py360convert.py IN.exr OUT_DIR [FACE=1024]

Reads the EXR (OpenEXR package), converts with py360convert.e2c(face_w=FACE,
mode="bilinear", cube_format="list") (py360convert's own cube convention; it samples with
cv2.remap when OpenCV is installed, as it is here), and writes the six faces as float32 .npy
files OUT_DIR/{F,R,B,L,U,D}.npy. Timed as a whole process (interpreter start-up and imports
included) by convert_peers.py.
"""

import os
import sys

import numpy as np
import py360convert

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import peerlib  # noqa: E402


def main() -> None:
    src, out_dir = sys.argv[1], sys.argv[2]
    n = int(sys.argv[3]) if len(sys.argv) > 3 else 1024
    img = peerlib.read_exr_rgb(src)
    faces = py360convert.e2c(img, face_w=n, mode="bilinear", cube_format="list")
    os.makedirs(out_dir, exist_ok=True)
    for name, face in zip("FRBLUD", faces):
        np.save(os.path.join(out_dir, name + ".npy"), np.ascontiguousarray(face))


if __name__ == "__main__":
    main()
