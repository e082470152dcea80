#!/usr/bin/env bash
# Creates bench/.venv with the Python peers of the conversion benchmark (PyPI only).
#   bash bench/setup.sh && bench/.venv/bin/python bench/convert_peers.py
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
python="${PYTHON:-python3}"
if ! "$python" -c 'import sys; sys.exit(sys.version_info < (3, 10))' 2>/dev/null; then
    echo "setup.sh: need Python >= 3.10 (set PYTHON=/path/to/python3)" >&2
    exit 1
fi
if [ ! -x "$here/.venv/bin/python" ]; then
    "$python" -m venv "$here/.venv" || {
        echo "setup.sh: 'python3 -m venv' failed; on Debian/Ubuntu: apt-get install python3-venv" >&2
        exit 1
    }
fi
"$here/.venv/bin/python" -m pip install --quiet --upgrade pip
"$here/.venv/bin/python" -m pip install --quiet -r "$here/requirements.txt"
"$here/.venv/bin/python" - <<'PY'
import cv2, numpy, OpenEXR, py360convert
from importlib.metadata import version
print("bench/.venv ready: numpy", numpy.__version__, "| opencv-python-headless",
      version("opencv-python-headless"), "| py360convert", version("py360convert"),
      "| OpenEXR", version("OpenEXR"))
PY
