"""The py360convert-shaped helpers against py360convert itself: face order, orientation,
layouts, views, dtypes. mirrorball antialiases and samples texel centres where
py360convert samples face corners, so values agree to a tolerance on smooth maps; a face
in the wrong place or mirrored is off by far more (checked on a map of directions)."""

import numpy as np
import pytest

import mirrorball as mb
from conftest import direction_latlong, smooth_latlong

py360convert = pytest.importorskip("py360convert")


def close(a, b, worst=0.03, mean=0.004):
    assert a.shape == b.shape and a.dtype == b.dtype
    d = np.abs(a.astype(np.float64) - b.astype(np.float64))
    assert d.max() < worst and d.mean() < mean, (d.max(), d.mean())


@pytest.fixture(scope="module")
def dirs():
    return direction_latlong(256, 512)


@pytest.mark.parametrize("cube_format", ["dice", "horizon", "list", "dict"])
def test_e2c_agrees_in_every_layout(dirs, cube_format):
    ours = mb.e2c(dirs, face_w=64, cube_format=cube_format)
    theirs = py360convert.e2c(dirs, face_w=64, cube_format=cube_format)
    if cube_format == "list":
        assert len(ours) == 6
        for a, b in zip(ours, theirs):
            close(a, b)
    elif cube_format == "dict":
        assert list(ours) == list("FRBLUD") and set(theirs) == set(ours)
        for k in "FRBLUD":
            close(ours[k], theirs[k])
    else:
        close(ours, theirs)


def test_each_face_is_where_py360convert_puts_it(dirs):
    ours = mb.e2c(dirs, face_w=32, cube_format="dict")
    theirs = py360convert.e2c(dirs, face_w=32, cube_format="dict")
    for k in "FRBLUD":
        right = np.abs(ours[k] - theirs[k]).mean()
        # A mirrored or turned face of directions is far off.
        for wrong in (ours[k][:, ::-1], ours[k][::-1], np.rot90(ours[k])):
            assert np.abs(wrong - theirs[k]).mean() > 20 * right, k
        for other in "FRBLUD".replace(k, ""):
            assert np.abs(ours[other] - theirs[k]).mean() > 20 * right, (k, other)
    # The front face looks at the picture's centre: mirrorball's -Z, py360convert's +Z.
    centre = ours["F"][16, 16]
    assert np.allclose(centre, [0.5, 0.5, 0.0], atol=0.03)


def test_c2e_agrees(dirs):
    cube = py360convert.e2c(dirs, face_w=64)
    close(mb.c2e(cube, 128, 256), py360convert.c2e(cube, 128, 256), worst=0.06, mean=0.006)
    listed = py360convert.e2c(dirs, face_w=64, cube_format="list")
    close(mb.c2e(listed, 128, 256, cube_format="list"), mb.c2e(cube, 128, 256), worst=1e-6, mean=1e-7)
    with pytest.raises(ValueError, match=r"w: 300"):
        mb.c2e(cube, 128, 300)


@pytest.mark.parametrize("u, v, rot", [(0, 0, 0), (30, 20, 0), (-120, -40, 0), (45, 10, 15)])
def test_e2p_agrees(dirs, u, v, rot):
    ours = mb.e2p(dirs, 80, u, v, (96, 96), in_rot_deg=rot)
    theirs = py360convert.e2p(dirs, 80, u, v, (96, 96), in_rot_deg=rot)
    close(ours, theirs)


def test_e2p_other_shapes(dirs):
    h_fov = 90.0
    v_fov = np.degrees(2 * np.arctan(np.tan(np.radians(h_fov / 2)) * 48 / 96))
    ours = mb.e2p(dirs, (h_fov, v_fov), 10, 5, (48, 96))
    theirs = py360convert.e2p(dirs, (h_fov, v_fov), 10, 5, (48, 96))
    close(ours, theirs)
    with pytest.raises(ValueError, match=r"out_hw"):
        mb.e2p(dirs, 90, 0, 0, (48, 96))


def test_c2p_is_e2p_from_a_cube(dirs):
    cube = mb.e2c(dirs, face_w=128)
    close(mb.c2p(cube, 70, 25, -15, (64, 64)), py360convert.e2p(dirs, 70, 25, -15, (64, 64)))


def test_dtypes_and_channels_as_py360convert():
    img = smooth_latlong(128, 256, 3)
    grey = img[..., 0]
    out = mb.e2c(grey, face_w=32, cube_format="horizon")
    assert out.ndim == 2 and out.shape == (32, 192)
    close(out, py360convert.e2c(grey, face_w=32, cube_format="horizon"))
    f64 = img.astype(np.float64)
    assert mb.e2c(f64, face_w=16).dtype == np.float64
    five = np.concatenate([img, img[..., :2] * 0.5], axis=-1)
    ours = mb.e2c(five, face_w=32, cube_format="horizon")
    assert ours.shape == (32, 192, 5)
    close(ours, py360convert.e2c(five, face_w=32, cube_format="horizon"))
    codes = (img * 255 + 0.5).astype(np.uint8)
    ours = mb.e2c(codes, face_w=32, linear=True)
    theirs = py360convert.e2c(codes, face_w=32)
    assert ours.dtype == np.uint8
    assert np.abs(ours.astype(int) - theirs.astype(int)).max() <= 8
    with pytest.raises(ValueError, match=r"mode: 'nearest'"):
        mb.e2c(img, mode="nearest")
    with pytest.raises(ValueError, match=r"cube_format: 'cross'"):
        mb.e2c(img, cube_format="cross")
