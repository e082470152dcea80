"""The same results as the CLI, byte for byte, on the same input: a conversion, a
prefilter and a bake."""

import filecmp

import numpy as np

import mirrorball as mb


def test_convert_equals_the_cli(cli, sky_path, tmp):
    cli("convert", sky_path, tmp / "cli.exr", "--to", "cube", "--size", 64, "--precision", "float", "--yaw", 30, "--quiet")
    array, info = mb.read(sky_path)
    assert info["projection"] == "latlong"
    # The CLI sets the file's negative values to 0 before converting: invalid="zero".
    cube = mb.convert(array, src=info["projection"], dst="cube", size=64, yaw=30, invalid="zero", layout="separate")
    cli_cube, cli_info = mb.read(tmp / "cli.exr")
    assert cli_info["projection"] == "cube" and "hcross" in cli_info["decided"]
    assert cube.shape == cli_cube.shape == (6, 64, 64, 3)
    assert np.array_equal(cube, cli_cube)
    cross = mb.convert(array, dst="cube", size=64, yaw=30, invalid="zero")
    assert np.array_equal(cross[64:128, 64:128], cube[4])
    mb.write(tmp / "py.exr", cube, projection="cube", layout="hcross")
    assert filecmp.cmp(tmp / "py.exr", tmp / "cli.exr", shallow=False)


def test_convert_to_png_equals_the_cli(cli, city_path, tmp):
    cli("convert", city_path, tmp / "cli.png", "--to", "angular", "--size", 96, "--quiet")
    array, _ = mb.read(city_path)
    codes = mb.convert(array, dst="angular", size=96, invalid="zero", dtype=np.uint8)
    cli_codes, _ = mb.read(tmp / "cli.png", dtype=np.uint8)
    assert np.array_equal(codes, cli_codes)
    mb.write(tmp / "py.png", codes, projection="angular")
    assert filecmp.cmp(tmp / "py.png", tmp / "cli.png", shallow=False)


def test_prefilter_equals_the_cli(cli, sky_path, tmp):
    cli(
        "prefilter", sky_path, tmp / "cli.exr", "--lobe", "ggx", "--size", 16, "--samples", 32,
        "--precision", "float", "--no-sh", "--no-preview", "--quiet",
    )
    array, _ = mb.read(sky_path)
    levels = mb.prefilter(array, "ggx", size=16, samples=32, invalid="zero", layout="separate")
    assert len(levels) == 5  # 16² down to 1²
    for i, level in enumerate(levels):
        theirs, _ = mb.read(tmp / f"cli_mip{i}.exr")
        assert np.array_equal(level, theirs), f"level {i}"
        mb.write(tmp / f"py_mip{i}.exr", level, projection="cube", layout="hcross")
        assert filecmp.cmp(tmp / f"py_mip{i}.exr", tmp / f"cli_mip{i}.exr", shallow=False)
    # Rougher levels are blurrier: less spread between texels.
    assert levels[3].std() < levels[0].std()


def test_bake_equals_the_cli(cli, sky_path, tmp):
    (tmp / "a").mkdir()
    (tmp / "b").mkdir()
    src = "sky.exr"
    import shutil

    shutil.copy(sky_path, tmp / "a" / src)
    cli("bake", src, "--for", "ktx2", "out", "--size", 16, "--samples", 32, "--quiet", cwd=tmp / "a")
    array, _ = mb.read(sky_path)
    import os

    here = os.getcwd()
    os.chdir(tmp / "b")
    try:
        files = mb.bake(array, "ktx2", "out", size=16, samples=32, source=src)
    finally:
        os.chdir(here)
    names = sorted(p.name for p in (tmp / "a" / "out").iterdir())
    assert names == sorted(p.name for p in (tmp / "b" / "out").iterdir())
    assert {"specular.ktx2", "diffuse.ktx2", "sh.json", "README.md"} <= set(names)
    assert len(files) >= 4
    for name in names:
        assert filecmp.cmp(tmp / "a" / "out" / name, tmp / "b" / "out" / name, shallow=False), name
