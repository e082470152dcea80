"""The Ray and Dask examples (python/examples), each run on a local cluster; every frame
they write equals the same conversion made in this process."""

import pathlib
import shutil
import sys

import numpy as np
import pytest

import mirrorball as mb

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"
sys.path.insert(0, str(EXAMPLES))


@pytest.fixture
def frames(tmp, sky_path, city_path):
    src = tmp / "in"
    src.mkdir()
    for i in range(3):
        shutil.copy(sky_path, src / f"sky{i}.exr")
        shutil.copy(city_path, src / f"city{i}.exr")
    return src


def check(written, frames, out):
    assert [pathlib.Path(w).name for w in written] == sorted(p.name for p in frames.iterdir())
    for w in written:
        got, info = mb.read(w)
        assert info["projection"] == "cube"
        array, _ = mb.read(frames / pathlib.Path(w).name)
        expected = mb.convert(array, dst="cube", size=32, invalid="zero", layout="separate")
        assert np.abs(got - expected).max() <= 1e-4 * max(1.0, np.abs(expected).max())


def test_ray_example(frames, tmp):
    ray_convert = pytest.importorskip("ray_convert")
    written = ray_convert.convert_folder(frames, tmp / "out", size=32, cpus=2)
    check(written, frames, tmp / "out")


def test_dask_example(frames, tmp):
    dask_convert = pytest.importorskip("dask_convert")
    written = dask_convert.convert_folder(frames, tmp / "out", size=32, workers=2)
    check(written, frames, tmp / "out")
