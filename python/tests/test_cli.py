"""The same results as the CLI, byte for byte, on the same input: a conversion, a
prefilter and a bake."""

import filecmp

import numpy as np
import pytest

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


def test_v360_options_equal_the_cli(cli, city_path, tmp):
    """v360= means what the CLI's --v360 means: the same 16-bit codes for EAC at v360's own
    size (YouTube's 16:9 frame scaled), a rotated c3x2 cube and a tetrahedron, as array and
    plan (the CLI's pictures read as they lie, by OpenCV)."""
    import cv2

    array, _ = mb.read(city_path)
    for i, options in enumerate([
        "e:eac:yaw=30:pitch=-10:w=384:h=216",
        "e:c3x2:out_forder=fbudlr:roll=20:w=192:h=128",
        "e:tetrahedron:w=128:h=64",
    ]):
        out = tmp / f"cli{i}.png"
        cli("convert", city_path, out, "--v360", options, "--precision", "16", "--quiet")
        theirs = cv2.imread(str(out), cv2.IMREAD_UNCHANGED)[..., ::-1]
        ours = mb.convert(array, v360=options, invalid="zero", dtype=np.uint16)
        assert ours.shape == theirs.shape, options
        assert np.array_equal(ours, theirs), options
        plan = mb.Remap(array.shape, v360=options)
        planned = plan.apply(array, invalid="zero", dtype=np.uint16).astype(np.int32)
        assert np.abs(planned - theirs).max() <= 2, options


def test_v360_is_refused_beside_what_it_says(city_path):
    array, _ = mb.read(city_path)
    for kwargs, named in [
        (dict(dst="cube"), "dst"),
        (dict(yaw=10), "yaw"),
        (dict(layout="hcross"), "layout"),
        (dict(size=64, v360="e:eac:w=384:h=216"), "size"),
    ]:
        kwargs.setdefault("v360", "e:eac")
        with pytest.raises(ValueError, match=named):
            mb.convert(array, invalid="zero", **kwargs)
    with pytest.raises(ValueError, match="bogus"):
        mb.convert(array, v360="e:eac:bogus=1")
    with pytest.raises(ValueError, match="stereo"):
        mb.convert(array, v360="e:e:in_stereo=sbs:out_stereo=sbs")
