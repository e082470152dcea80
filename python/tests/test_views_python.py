"""`mirrorball.views`: the package's rig of views is the CLI's `mirrorball views`, file for
file and byte for byte, and pycolmap reads the cameras it wrote; a rerun with fewer views
removes what the first wrote and keeps the user's files."""

import pathlib

import numpy as np
import pytest

import mirrorball
from conftest import direction_latlong

pycolmap = pytest.importorskip("pycolmap")
cv2 = pytest.importorskip("cv2")


def tree(root):
    """Every file under `root`, relative, with its bytes."""
    root = pathlib.Path(root)
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


@pytest.fixture
def pano(tmp):
    """A 256×128 8-bit lat-long PNG whose texels hold their own direction."""
    path = tmp / "pano.png"
    mirrorball.write(path, (direction_latlong(128, 256) * 255 + 0.5).astype(np.uint8))
    return path


@pytest.mark.parametrize("fmt", ["png", "jpg", "png16"])
def test_views_are_the_cli_s_files(cli, tmp, pano, fmt):
    by_cli, by_py = tmp / "cli", tmp / "py"
    cli("views", pano, by_cli, "--rig", "cube-96", "--size", "40", "--format", fmt, "--masks", "-q")
    written = mirrorball.views(str(pano), by_py, rig="cube-96", size=40, format=fmt, masks=True)
    a, b = tree(by_cli), tree(by_py)
    assert sorted(a) == sorted(b)
    assert len([n for n in a if n.startswith("images/")]) == 6
    assert len([n for n in a if n.startswith("masks/")]) == 6
    for name in a:
        assert a[name] == b[name], name
    # Every file written is listed (the folder's record of them aside).
    listed = {pathlib.Path(f).relative_to(by_py).as_posix() for f in written}
    assert listed == set(b) - {".mirrorball-files"}


def test_pycolmap_reads_the_cameras_it_wrote(tmp, pano):
    out = tmp / "out"
    mirrorball.views(pano, out, rig="ring4", size=(48, 32))
    rec = pycolmap.Reconstruction(str(out / "sparse" / "0"))
    assert rec.num_images() == 6 and rec.num_cameras() == 6 and rec.num_rigs() == 1
    for image in rec.images.values():
        cam = rec.cameras[image.camera_id]
        assert cam.model == pycolmap.CameraModelId.PINHOLE
        # The view's codes (as the panorama's: (d + 1)/2 of their direction d).
        picture = cv2.imread(str(out / "images" / image.name))[..., ::-1]
        assert picture.shape[:2] == (cam.height, cam.width)
        # The view's centre pixel holds the direction its camera looks along (COLMAP's
        # world is mirrorball's (x, -y, -z)); within the panorama's and the view's texels.
        axis = image.cam_from_world().rotation.matrix().T @ np.array([0.0, 0.0, 1.0])
        want = axis * np.array([1.0, -1.0, -1.0])
        h, w = picture.shape[:2]
        centre = picture[h // 2 - 1 : h // 2 + 1, w // 2 - 1 : w // 2 + 1].mean(axis=(0, 1))
        seen = 2.0 * centre / 255.0 - 1.0
        cos = np.dot(seen, want) / np.linalg.norm(seen)
        assert cos > np.cos(np.deg2rad(3.0)), (image.name, seen, want)


def test_a_rerun_with_fewer_views_keeps_the_user_s_files(tmp, pano):
    out = tmp / "out"
    mirrorball.views(pano, out, size=16)
    (out / "mine.txt").write_text("mine")
    mirrorball.views(pano, out, rig="ring4", size=16)
    names = tree(out)
    assert "mine.txt" in names
    # cube's up/down views are gone (ring4 has its own up and down); its side views too.
    images = sorted(n for n in names if n.startswith("images/"))
    assert len(images) == 6 and not any(n.startswith("images/right/") for n in images), images
    # A file of the user's where a view would land: refused, unless overwrite.
    other = tmp / "other"
    (other / "images" / "front").mkdir(parents=True)
    (other / "images" / "front" / "pano.png").write_bytes(b"mine")
    with pytest.raises(ValueError, match="overwrite"):
        mirrorball.views(pano, other, size=16)
    assert (other / "images" / "front" / "pano.png").read_bytes() == b"mine"
    mirrorball.views(pano, other, size=16, overwrite=True)
    assert (other / "images" / "front" / "pano.png").read_bytes() != b"mine"


def test_bad_arguments_are_refused(tmp, pano):
    with pytest.raises(FileNotFoundError):
        mirrorball.views(tmp / "none.png", tmp / "out")
    with pytest.raises(ValueError, match="rig"):
        mirrorball.views(pano, tmp / "out", rig="nope")
    with pytest.raises(ValueError, match="size"):
        mirrorball.views(pano, tmp / "out", size="big")
    assert not (tmp / "out").exists()


def test_cut_views_are_the_files_pictures_with_colmap_s_cameras(tmp):
    """The in-memory cut of a float panorama: each view the picture `views` writes (as
    16-bit sRGB codes, the same codes), K and R what pycolmap reads from its model."""
    floats = direction_latlong(128, 256)
    exr = tmp / "pano.exr"
    mirrorball.write(exr, floats)
    out = tmp / "out"
    mirrorball.views(exr, out, rig="ring5", size=24, format="png16")
    cut = mirrorball.cut_views(floats, rig="ring5", size=24, dtype=np.uint16)
    rec = pycolmap.Reconstruction(str(out / "sparse" / "0"))
    by_name = {image.name.split("/")[0]: image for image in rec.images.values()}
    assert [v["name"] for v in cut] == ["yaw000", "yaw072", "yaw144", "yaw216", "yaw288", "up", "down"]
    for v in cut:
        image = by_name[v["name"]]
        cam = rec.cameras[image.camera_id]
        assert v["model"] == "PINHOLE" and v["image"].dtype == np.uint16
        assert v["image"].shape == (cam.height, cam.width, 3)
        assert np.allclose(v["K"], cam.calibration_matrix(), rtol=0, atol=1e-9)
        assert np.allclose(v["R"], image.cam_from_world().rotation.matrix(), atol=1e-9)
        written = cv2.imread(str(out / "images" / image.name), cv2.IMREAD_UNCHANGED)[..., ::-1]
        assert np.array_equal(written, v["image"]), v["name"]
    # float32 in, float32 out, unless dtype says otherwise (every function's rule).
    assert mirrorball.cut_views(floats, size=8)[0]["image"].dtype == np.float32
