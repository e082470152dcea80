"""Round trips through files and projections, dtypes kept, layouts, batches, Remap plans."""

import numpy as np
import pytest

import mirrorball as mb
from conftest import smooth_latlong


def test_exr_float32_round_trip_is_exact(tmp):
    rng = np.random.default_rng(1)
    for c in (3, 4):
        a = rng.random((32, 64, c), dtype=np.float32) * 100
        path = tmp / f"a{c}.exr"
        mb.write(path, a, projection="latlong")
        b, info = mb.read(path)
        assert b.dtype == np.float32 and b.shape == a.shape
        assert np.array_equal(a, b)
        assert info["projection"] == "latlong"
        assert info["decided"].endswith("recorded in the file")


def test_float16_is_written_half_and_read_back_exactly(tmp):
    a = (np.random.default_rng(2).random((16, 32, 3)) * 10).astype(np.float16)
    mb.write(tmp / "h.exr", a)
    b, info = mb.read(tmp / "h.exr", dtype=np.float16)
    assert "half" in info["description"]
    assert b.dtype == np.float16 and np.array_equal(a, b)


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
def test_png_codes_round_trip_exactly(tmp, dtype):
    top = np.iinfo(dtype).max
    a = np.random.default_rng(3).integers(0, top + 1, (24, 48, 3), dtype=dtype)
    mb.write(tmp / "a.png", a)
    b, info = mb.read(tmp / "a.png", dtype=dtype)
    assert np.array_equal(a, b)
    # Read as floats, codes are sRGB (IEC 61966-2-1's curve).
    a[0, 0] = [top // 2, top // 4, top]
    mb.write(tmp / "b.png", a)
    f, _ = mb.read(tmp / "b.png")
    expected = [((k / top + 0.055) / 1.055) ** 2.4 for k in a[0, 0]]
    assert f[0, 0] == pytest.approx(expected, rel=1e-4)


def test_linear_codes_are_code_over_max():
    a = np.full((32, 64, 3), 51, np.uint8)
    f = mb.convert(a, dst="latlong", size=64, linear=True, dtype=np.float32)
    assert np.allclose(f, 0.2, atol=1e-6)
    s = mb.convert(a, dst="latlong", size=64, dtype=np.float32)
    assert np.allclose(s, ((51 / 255 + 0.055) / 1.055) ** 2.4, atol=1e-6)
    # Codes in, the same codes out (a constant map converts to itself).
    assert np.array_equal(mb.convert(a, dst="latlong", size=64), a)
    assert np.array_equal(mb.convert(a, dst="latlong", size=64, linear=True), a)


def test_ktx2_cube_faces_round_trip(tmp, smooth):
    faces = mb.convert(smooth, dst="cube", size=16, layout="separate")
    assert faces.shape == (6, 16, 16, 3)
    mb.write(tmp / "c.ktx2", faces, projection="cube", precision="float")
    back, info = mb.read(tmp / "c.ktx2")
    # KTX2 holds RGBA: alpha 1 comes back.
    assert back.shape == (6, 16, 16, 4) and np.all(back[..., 3] == 1)
    assert info["projection"] == "cube" and info["layout"] == "separate"
    assert np.array_equal(back[..., :3], faces)


def test_cube_round_trip_returns_the_map(smooth):
    cross = mb.convert(smooth, dst="cube", size=64)
    assert cross.shape == (3 * 64, 4 * 64, 3)
    back = mb.convert(cross, src="cube", dst="latlong", size=256)
    assert back.shape == smooth.shape
    assert np.abs(back - smooth).max() < 0.01
    # The cross's unused cells are black.
    assert np.all(cross[:64, :64] == 0)


def test_layouts_hold_the_same_faces(smooth):
    faces = mb.convert(smooth, dst="cube", size=32, layout="separate")
    strip = mb.convert(smooth, dst="cube", size=32, layout="hstrip")
    assert np.array_equal(np.concatenate(list(faces), axis=1), strip)
    cross = mb.convert(smooth, dst="cube", size=32, layout="hcross")
    # OpenGL order +X -X +Y -Y +Z -Z; the horizontal cross puts -X +Z +X -Z on its middle row.
    n = 32
    assert np.array_equal(cross[n : 2 * n, 0:n], faces[1])
    assert np.array_equal(cross[n : 2 * n, n : 2 * n], faces[4])
    assert np.array_equal(cross[0:n, n : 2 * n], faces[2])
    # Faces given back as separate layers read the same as the cross.
    again = mb.convert(faces, src="cube", src_layout="separate", dst="latlong", size=128)
    assert np.array_equal(again, mb.convert(cross, src="cube", dst="latlong", size=128))


def test_dtype_is_kept_unless_asked(smooth):
    for dtype in (np.float32, np.float16, np.uint8, np.uint16):
        a = smooth_latlong(dtype=dtype) if dtype != np.uint16 else (smooth * 65535).astype(np.uint16)
        assert mb.convert(a, dst="cube", size=8).dtype == dtype
    assert mb.convert(smooth, dst="cube", size=8, dtype="uint8").dtype == np.uint8
    assert mb.convert(smooth, dst="cube", size=8, dtype=np.float16).dtype == np.float16


def test_non_contiguous_views_give_the_same_result(smooth):
    expected = mb.convert(smooth, dst="cube", size=16)
    big = np.zeros((128, 512, 5), np.float32)
    big[:, ::2, 1:4] = smooth
    view = big[:, ::2, 1:4]
    assert not view.flags.c_contiguous
    assert np.array_equal(mb.convert(view, dst="cube", size=16), expected)
    fortran = np.asfortranarray(smooth)
    assert np.array_equal(mb.convert(fortran, dst="cube", size=16), expected)


def test_batches_are_each_map_converted(smooth):
    batch = np.stack([smooth, smooth[:, ::-1], 1 - smooth])
    out = mb.convert(batch, dst="cube", size=16)
    assert out.shape == (3, 48, 64, 3)
    for i in range(3):
        assert np.array_equal(out[i], mb.convert(batch[i], dst="cube", size=16))


def test_remap_agrees_with_convert_and_fills_out(smooth):
    plan = mb.Remap(smooth.shape, src="latlong", dst="cube", size=32, layout="separate")
    expected = mb.convert(smooth, dst="cube", size=32, layout="separate")
    got = plan.apply(smooth)
    assert got.shape == (6, 32, 32, 3) == tuple(plan.output_shape(3))
    assert np.abs(got - expected).max() <= 1e-5 * np.abs(expected).max()
    out = np.empty((2, 6, 32, 32, 3), np.float32)
    res = plan.apply(np.stack([smooth, 2 * smooth]), out=out)
    assert res is out
    assert np.array_equal(out[0], got)
    assert np.allclose(out[1], 2 * got, rtol=1e-6)
    # Packed layouts and uint8 through the same plan.
    cross = mb.Remap(smooth.shape, dst="cube", size=32)
    assert np.array_equal(cross.apply(smooth)[32:64, 32:64], got[4])
    codes = smooth_latlong(dtype=np.uint8)
    u8 = plan.apply(codes)
    assert u8.dtype == np.uint8
    ref = mb.convert(codes, dst="cube", size=32, layout="separate")
    assert np.abs(u8.astype(int) - ref.astype(int)).max() <= 1


def test_rotation_turns_the_world(smooth):
    turned = mb.convert(smooth, dst="latlong", size=256, yaw=90)
    # yaw 90 turns the world 90° to the left: a quarter of the width.
    assert np.abs(turned - np.roll(smooth, -64, axis=1)).max() < 1e-3 or np.abs(
        turned - np.roll(smooth, 64, axis=1)
    ).max() < 1e-3
    assert np.abs(turned - smooth).max() > 0.1


def test_every_projection_converts_both_ways(smooth):
    names = mb.projections()
    assert "latlong" in names and "cube" in names and len(names) >= 15
    for name in names:
        out = mb.convert(smooth, dst=name, size=32)
        assert out.ndim == 3 and np.isfinite(out).all(), name
        mb.convert(out, src=name, dst="latlong", size=32)


def test_sh9_of_a_constant_map():
    a = np.full((64, 128, 3), 2.0, np.float32)
    sh = mb.sh9(a)
    assert sh.shape == (9, 3)
    # Y00 = 1/(2√π); ∫ 2·Y00 dω = 2·4π/(2√π) = 4√π.
    assert sh[0] == pytest.approx([4 * np.sqrt(np.pi)] * 3, rel=1e-4)
    assert np.abs(sh[1:]).max() < 1e-3 * sh[0, 0]


def test_threads_setting():
    mb.set_threads(1)
    try:
        assert mb.get_threads() == 1
    finally:
        mb.set_threads(None)
    assert mb.get_threads() >= 1


def test_srgb8_codes_are_the_nearest(tmp):
    # Every threshold between codes on the exact curve, a float either side of it, and a
    # sweep: the codes are io's (the count of thresholds at or below the value).
    k = np.arange(255) + 0.5
    c = k / 255
    t = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4).astype(np.float32)
    near = np.concatenate([t, np.nextafter(t, 0), np.nextafter(t, 2)])
    sweep = np.linspace(-0.01, 1.01, 300_000, dtype=np.float32)
    x = np.concatenate([near, sweep, [0, 1, 2, np.float32(2.0**-9)]]).astype(np.float32)
    x = np.resize(x, (300, 600, 3))  # 2:1, read as a lat-long
    mb.write(tmp / "x.exr", x)
    codes, _ = mb.read(tmp / "x.exr", dtype=np.uint8)
    expected = np.searchsorted(t, x, side="right").astype(np.uint8)
    assert np.array_equal(codes, expected)


@pytest.mark.parametrize("dtype", [np.float32, np.uint8, np.uint16])
@pytest.mark.parametrize("layout", ["separate", "cross", "vcross", "c3x2"])
def test_remap_reads_arrays_in_place_to_the_same_bits(dtype, layout):
    """A C-contiguous RGB array is read where it lies (no float copy); a strided view of
    the same values is copied first. Both must give the same bits, for every dtype, a
    batch, and layouts made by rows, turned cells and packed ones; a wide-range float map
    (a sun past what a half float holds, tiny values) shrunk so that taps read mip levels."""
    rng = np.random.default_rng(3)
    if dtype == np.float32:
        src = (rng.random((2, 128, 256, 3), np.float32) * 2.0) ** 6
        src[0, 5, 7] = 2e5
    else:
        top = np.iinfo(dtype).max
        src = rng.integers(0, top + 1, (2, 128, 256, 3)).astype(dtype)
    plan = mb.Remap(src.shape[1:], dst="cube", size=20, layout=layout, yaw=17)
    strided = np.zeros((2, 128, 256, 4), dtype)
    strided[..., :3] = src
    view = strided[..., :3]
    assert src.flags.c_contiguous and not view.flags.c_contiguous
    for out_dtype in [None, np.float32, np.uint8, np.uint16, np.float16]:
        kw = {} if out_dtype is None else {"dtype": out_dtype}
        fast, slow = plan.apply(src, **kw), plan.apply(view, **kw)
        assert fast.dtype == slow.dtype and fast.shape == slow.shape
        assert np.array_equal(fast.view(np.uint8), slow.view(np.uint8)), (out_dtype, layout)
        single = plan.apply(src[1], **kw)
        assert np.array_equal(single.view(np.uint8), fast[1].view(np.uint8))
    if dtype == np.uint8:
        lin_fast, lin_slow = plan.apply(src, linear=True), plan.apply(view, linear=True)
        assert np.array_equal(lin_fast, lin_slow)


def test_remap_in_place_keeps_the_invalid_rules(smooth):
    plan = mb.Remap(smooth.shape, dst="cube", size=16, layout="separate")
    bad = smooth.copy()
    bad[3, 4, 1] = np.nan
    bad[9, 9, 0] = -1.0
    with pytest.raises(ValueError, match="1 NaN or infinite"):
        plan.apply(bad)
    # invalid='zero': the NaN and the negative set to 0 first, as convert does.
    zeroed = bad.copy()
    zeroed[3, 4, 1] = 0.0
    zeroed[9, 9, 0] = 0.0
    assert np.array_equal(plan.apply(bad, invalid="zero"), plan.apply(zeroed))
    kept = plan.apply(bad, invalid="keep")
    assert np.isnan(kept).any()
    # The source is never written, and an output that is the input is refused.
    before = bad.copy()
    plan.apply(bad, invalid="zero")
    assert np.array_equal(before, bad, equal_nan=True)
