"""Bad input: each a clear exception of the right class, naming the argument; no panic
ever reaches Python."""

import os

import numpy as np
import pytest

import mirrorball as mb


def test_wrong_dtype_is_a_type_error_naming_the_array(smooth):
    with pytest.raises(TypeError, match=r"array: dtype float64; give float32"):
        mb.convert(smooth.astype(np.float64))
    with pytest.raises(TypeError, match=r"array: dtype int32"):
        mb.convert(smooth.astype(np.int32))
    with pytest.raises(TypeError, match=r"array: a numpy array"):
        mb.convert([[1, 2, 3]])
    with pytest.raises(TypeError, match=r"dtype: float64"):
        mb.convert(smooth, dtype=np.float64)


def test_wrong_shape_names_the_array(smooth):
    with pytest.raises(ValueError, match=r"array: an array of shape 128×256 \(2 dimensions\)"):
        mb.convert(smooth[..., 0])
    with pytest.raises(ValueError, match=r"array: shape 128×256×2: 2 channels"):
        mb.convert(smooth[..., :2])
    # A lat-long is 2:1.
    with pytest.raises(mb.InputError, match=r"array: a latlong map is 2:1 \(256x128 for this width\) but the picture is 256x100"):
        mb.convert(smooth[:100])
    # No cube layout is 2:1 ... but a 4:3 picture read as a cube is.
    with pytest.raises(mb.InputError, match=r"array: a 256x128 picture fits no layout of a cube map"):
        mb.convert(smooth, src="cube")
    with pytest.raises(ValueError, match="array"):
        mb.convert(np.zeros((2, 2, 3, 3, 3, 3), np.float32))


def test_zero_size_names_the_array():
    with pytest.raises(ValueError, match=r"array: shape 0×256×3: the array is empty"):
        mb.convert(np.zeros((0, 256, 3), np.float32))
    with pytest.raises(ValueError, match=r"array: .*empty"):
        mb.convert(np.zeros((0, 128, 256, 3), np.float32))


def test_nan_names_the_array_unless_asked(smooth):
    a = smooth.copy()
    a[3, 4, 1] = np.nan
    a[5, 6, 0] = np.inf
    with pytest.raises(ValueError, match=r"array: 2 NaN or infinite values"):
        mb.convert(a, dst="cube", size=8)
    out = mb.convert(a, dst="cube", size=8, invalid="zero")
    assert np.isfinite(out).all()
    with pytest.raises(ValueError, match=r"invalid: 'drop'"):
        mb.convert(a, invalid="drop")


def test_out_must_fit(smooth):
    plan = mb.Remap(smooth.shape, dst="cube", size=8, layout="separate")
    with pytest.raises(ValueError, match=r"out: shape"):
        plan.apply(smooth, out=np.empty((6, 8, 8, 4), np.float32))
    with pytest.raises(TypeError, match=r"out: dtype float64"):
        plan.apply(smooth, out=np.empty((6, 8, 8, 3), np.float64))
    strided = np.empty((6, 8, 16, 3), np.float32)[:, :, ::2]
    with pytest.raises(ValueError, match=r"out: not C-contiguous"):
        plan.apply(smooth, out=strided)
    readonly = np.empty((6, 8, 8, 3), np.float32)
    readonly.flags.writeable = False
    with pytest.raises(ValueError, match=r"out: cannot be written"):
        plan.apply(smooth, out=readonly)
    with pytest.raises(ValueError, match=r"array: pictures of 128x64 \(W×H\); the plan was made for 256x128"):
        plan.apply(smooth[::2, ::2])
    with pytest.raises(ValueError, match=r"src_shape"):
        mb.Remap((0, 5))


def test_unknown_names_name_their_argument(smooth):
    with pytest.raises(ValueError, match=r"^src: .*latlonk"):
        mb.convert(smooth, src="latlonk")
    with pytest.raises(ValueError, match=r"^dst: .*cubee"):
        mb.convert(smooth, dst="cubee")
    with pytest.raises(ValueError, match=r"^dst: "):
        mb.convert(smooth, dst="fisheye:fov=abc")
    with pytest.raises(ValueError, match=r"^layout: "):
        mb.convert(smooth, layout="diagonal")
    with pytest.raises(ValueError, match=r"^lobe: "):
        mb.prefilter(smooth, "blinn")
    with pytest.raises(ValueError, match=r"^engine: "):
        mb.bake(smooth, "godot", "x")
    with pytest.raises(ValueError, match=r"^max_samples: 0"):
        mb.convert(smooth, max_samples=0)
    with pytest.raises(ValueError, match=r"^yaw: NaN is not a finite"):
        mb.convert(smooth, yaw=float("nan"))
    with pytest.raises(ValueError, match=r"^size: 0"):
        mb.convert(smooth, size=0)
    with pytest.raises(ValueError, match=r"^n: 0 threads"):
        mb.set_threads(0)


def test_missing_file_is_file_not_found(tmp):
    missing = tmp / "none.exr"
    with pytest.raises(FileNotFoundError) as e:
        mb.read(missing)
    assert e.value.filename == str(missing)
    with pytest.raises(IsADirectoryError):
        mb.read(tmp)


def test_unreadable_file_is_permission_error(tmp, sky_path):
    if os.geteuid() == 0:
        pytest.skip("root reads every file")
    p = tmp / "locked.exr"
    p.write_bytes(sky_path.read_bytes())
    p.chmod(0)
    with pytest.raises(PermissionError):
        mb.read(p)


def test_closed_file_object_is_refused(tmp, sky_path):
    f = open(sky_path, "rb")
    f.close()
    with pytest.raises(TypeError, match=r"path: a str or os.PathLike is needed, not BufferedReader"):
        mb.read(f)


def test_bad_content_is_input_error(tmp, sky_path):
    truncated = tmp / "t.exr"
    truncated.write_bytes(sky_path.read_bytes()[:5000])
    with pytest.raises(mb.InputError) as e:
        mb.read(truncated)
    assert isinstance(e.value, ValueError)
    assert str(truncated) in str(e.value)
    junk = tmp / "j.png"
    junk.write_bytes(b"\x89PNG\r\n\x1a\n" + b"\0" * 100)
    with pytest.raises(mb.InputError):
        mb.read(junk)
    empty = tmp / "e.hdr"
    empty.write_bytes(b"")
    with pytest.raises(mb.InputError, match="empty"):
        mb.read(empty)


def test_write_refusals(tmp, smooth):
    with pytest.raises(ValueError, match=r"^path: .*unknown output extension"):
        mb.write(tmp / "a.tiff", smooth)
    with pytest.raises(ValueError, match=r"^precision: "):
        mb.write(tmp / "a.png", smooth, precision="half")
    with pytest.raises(ValueError, match=r"^projection: KTX2 .*holds a cube map"):
        mb.write(tmp / "a.ktx2", smooth)
    with pytest.raises(ValueError, match=r"^projection: .*latlonk"):
        mb.write(tmp / "a.exr", smooth, projection="latlonk")
    with pytest.raises(ValueError, match=r"^mips: "):
        mb.write(tmp / "a.exr", smooth, projection="latlong", mips=True)
    with pytest.raises(FileNotFoundError):
        mb.write(tmp / "no" / "such" / "folder" / "a.exr", smooth)
