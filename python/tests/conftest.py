"""Shared fixtures: the bundled environment maps, the CLI binary, small test pictures."""

import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
ASSETS = ROOT / "assets" / "env"


@pytest.fixture(scope="session")
def sky_path():
    """A bundled 512×256 half-float lat-long HDR (with negatives and a bright sun)."""
    return ASSETS / "sky.exr"


@pytest.fixture(scope="session")
def city_path():
    return ASSETS / "city.exr"


def cli_binary():
    """The CLI: MIRRORBALL_BIN, else $CARGO_TARGET_DIR/debug/mirrorball, else target/debug."""
    if os.environ.get("MIRRORBALL_BIN"):
        return pathlib.Path(os.environ["MIRRORBALL_BIN"])
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    return target / "debug" / "mirrorball"


@pytest.fixture(scope="session")
def cli():
    binary = cli_binary()
    if not binary.exists():
        pytest.fail(f"no CLI at {binary}: cargo build -p mirrorball-cli, or set MIRRORBALL_BIN")

    def run(*args, cwd=None):
        r = subprocess.run([str(binary), *map(str, args)], capture_output=True, text=True, cwd=cwd)
        assert r.returncode == 0, f"mirrorball {' '.join(map(str, args))}: {r.stderr}"
        return r

    return run


def smooth_latlong(h=128, w=256, c=3, dtype=np.float32):
    """A smooth, positive lat-long: low-order functions of the direction (no detail that
    antialiasing or interpolation would treat differently)."""
    v, u = np.meshgrid((np.arange(h) + 0.5) / h, (np.arange(w) + 0.5) / w, indexing="ij")
    lon, lat = (u - 0.5) * 2 * np.pi, (0.5 - v) * np.pi
    x, y, z = np.cos(lat) * np.sin(lon), np.sin(lat), -np.cos(lat) * np.cos(lon)
    chans = [0.5 + 0.4 * x, 0.5 + 0.4 * y, 0.5 + 0.4 * z, 0.6 + 0.2 * x * y]
    out = np.stack(chans[:c], axis=-1).astype(np.float32)
    return out.astype(dtype) if dtype != np.uint8 else (out * 255 + 0.5).astype(np.uint8)


def direction_latlong(h=128, w=256):
    """A lat-long whose texels are their own directions mapped to [0, 1]: where a texel
    lands after a conversion says which direction it came from."""
    v, u = np.meshgrid((np.arange(h) + 0.5) / h, (np.arange(w) + 0.5) / w, indexing="ij")
    lon, lat = (u - 0.5) * 2 * np.pi, (0.5 - v) * np.pi
    d = np.stack([np.cos(lat) * np.sin(lon), np.sin(lat), -np.cos(lat) * np.cos(lon)], -1)
    return (0.5 + 0.5 * d).astype(np.float32)


@pytest.fixture
def smooth():
    return smooth_latlong()


@pytest.fixture
def tmp(tmp_path):
    yield tmp_path
    shutil.rmtree(tmp_path, ignore_errors=True)
