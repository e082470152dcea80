"""`mirrorball views` read by its consumers' own code: the COLMAP model through pycolmap
(`Reconstruction`, `read_rig_config`), nerfstudio's transforms.json through its documented
convention implemented here. A panorama whose texels hold their own direction makes each
view's pixel the direction it was sampled from, so every pixel's camera ray is checked
against the pixel itself; masks against the coverage of a fisheye worked out here.

Needs the CLI (conftest's `cli`) and pycolmap; runs without the Python package."""

import json

import numpy as np
import pytest

from conftest import direction_latlong

pycolmap = pytest.importorskip("pycolmap")
cv2 = pytest.importorskip("cv2")

# COLMAP's world is mirrorball's (x, -y, -z); nerfstudio's is mirrorball's (x, -z, y).
COLMAP_TO_MB = np.diag([1.0, -1.0, -1.0])
NS_TO_MB = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])


def srgb_encode(linear):
    linear = np.clip(linear, 0.0, 1.0)
    return np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055)


def srgb_decode(code):
    return np.where(code <= 0.04045, code / 12.92, ((code + 0.055) / 1.055) ** 2.4)


def write_png16(path, rgb):
    """Linear RGB in [0, 1] as a 16-bit sRGB PNG (what mirrorball decodes back to linear)."""
    codes = np.round(srgb_encode(rgb) * 65535).astype(np.uint16)
    assert cv2.imwrite(str(path), codes[..., ::-1])


def read_png16(path):
    """A 16-bit sRGB PNG as linear RGB."""
    codes = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    assert codes is not None and codes.dtype == np.uint16, path
    return srgb_decode(codes[..., ::-1].astype(np.float64) / 65535)


def pixel_grid(w, h):
    """Every pixel's centre, COLMAP's convention: pixel (x, y) at (x + 0.5, y + 0.5)."""
    y, x = np.mgrid[0:h, 0:w]
    return np.stack([x.ravel() + 0.5, y.ravel() + 0.5], -1).astype(np.float64)


# The panorama's texel: pi / 512 rad. Its first and last rows lie half a texel from the
# poles and span every longitude, so within a few degrees of a pole a lookup is off by up to
# half a texel (2.6e-3 rad measured at the pole, 1.1e-4 beyond 5 degrees); elsewhere what
# the views' filter leaves of a smooth field is far less than a texel.
HALF_TEXEL = 0.5 * np.pi / 512


def check_errors(err, world_mb):
    """The worst error anywhere (within half a texel), and away from the poles."""
    unit = world_mb / np.linalg.norm(world_mb, axis=-1, keepdims=True)
    away = np.abs(unit[:, 1]) < np.cos(np.deg2rad(5))
    return err.max(), err[away].max(initial=0.0)


def angles(a, b):
    a = a / np.linalg.norm(a, axis=-1, keepdims=True)
    b = b / np.linalg.norm(b, axis=-1, keepdims=True)
    return np.arccos(np.clip(np.sum(a * b, -1), -1.0, 1.0))


@pytest.fixture(scope="module")
def rig(cli, tmp_path_factory):
    """A 1024×512 direction panorama cut into a ring of six views (16-bit PNG)."""
    tmp = tmp_path_factory.mktemp("views")
    pano = tmp / "pano.png"
    write_png16(pano, direction_latlong(512, 1024).astype(np.float64))
    out = tmp / "out"
    cli("views", pano, out, "--rig", "ring6", "--size", "96", "--format", "png16", "--quiet")
    return out


def view_directions(out, name):
    """The directions a view's pixels hold (mirrorball's world), one per pixel, row-major."""
    rgb = read_png16(out / "images" / name)
    return (2.0 * rgb - 1.0).reshape(-1, 3), rgb.shape[1], rgb.shape[0]


def test_colmap_rays_are_the_pixels_directions(rig):
    rec = pycolmap.Reconstruction(str(rig / "sparse" / "0"))
    assert rec.num_images() == 8 and rec.num_cameras() == 8 and rec.num_points3D() == 0
    # The rig as the model holds it: one rig, one frame holding every view.
    assert rec.num_rigs() == 1 and rec.num_frames() == 1
    worst = np.zeros(2)
    for image in rec.images.values():
        cam = rec.cameras[image.camera_id]
        assert cam.model == pycolmap.CameraModelId.PINHOLE
        seen, w, h = view_directions(rig, image.name)
        assert (cam.width, cam.height) == (w, h)
        xy = pixel_grid(w, h)
        rays = np.concatenate([cam.cam_from_img(xy), np.ones((len(xy), 1))], -1)
        pose = image.cam_from_world()
        assert np.allclose(pose.translation, 0.0)
        world = rays @ pose.rotation.matrix() @ COLMAP_TO_MB.T  # R^T applied to each row
        worst = np.maximum(worst, check_errors(angles(world, seen), world))
    print(f"COLMAP rays vs pixels: worst {worst[0]:.2e} rad, {worst[1]:.2e} rad 5 degrees from the poles")
    assert worst[0] < HALF_TEXEL and worst[1] < 2e-4


def test_rig_config_reads_and_matches_the_model(rig):
    configs = pycolmap.read_rig_config(str(rig / "rig_config.json"))
    assert len(configs) == 1
    cams = configs[0].cameras
    assert len(cams) == 8
    assert cams[0].ref_sensor and cams[0].cam_from_rig is None
    rec = pycolmap.Reconstruction(str(rig / "sparse" / "0"))
    by_prefix = {im.name.split("/")[0] + "/": im for im in rec.images.values()}
    ref = by_prefix[cams[0].image_prefix].cam_from_world()
    for c in cams[1:]:
        assert not c.ref_sensor
        im = by_prefix[c.image_prefix]
        # cam_from_world = cam_from_rig · rig_from_world, the rig's frame the reference's.
        expected = im.cam_from_world().rotation.matrix() @ ref.rotation.matrix().T
        assert np.allclose(c.cam_from_rig.rotation.matrix(), expected, atol=1e-9)
        assert np.allclose(c.cam_from_rig.translation, 0.0)
        assert c.camera.model == pycolmap.CameraModelId.PINHOLE
        assert np.allclose(c.camera.params, rec.cameras[im.camera_id].params)


def test_nerfstudio_rays_are_the_pixels_directions(rig):
    t = json.loads((rig / "transforms.json").read_text())
    assert t["camera_model"] == "PINHOLE"
    assert len(t["frames"]) == 8
    worst = np.zeros(2)
    for f in t["frames"]:
        assert "mask_path" not in f  # a lat-long covers every direction
        seen, w, h = view_directions(rig, f["file_path"].removeprefix("images/"))
        assert (f["w"], f["h"]) == (w, h)
        xy = pixel_grid(w, h)
        # nerfstudio's cameras: x right, y up, looking down -Z; c2w in its world.
        d = np.stack(
            [(xy[:, 0] - f["cx"]) / f["fl_x"], -(xy[:, 1] - f["cy"]) / f["fl_y"], -np.ones(len(xy))], -1
        )
        c2w = np.array(f["transform_matrix"])
        assert np.allclose(c2w[3], [0, 0, 0, 1]) and np.allclose(c2w[:3, 3], 0)
        world = d @ c2w[:3, :3].T @ NS_TO_MB.T
        worst = np.maximum(worst, check_errors(angles(world, seen), world))
    print(f"nerfstudio rays vs pixels: worst {worst[0]:.2e} rad, {worst[1]:.2e} rad 5 degrees from the poles")
    assert worst[0] < HALF_TEXEL and worst[1] < 2e-4


def test_fisheye_masks_are_its_coverage(cli, tmp):
    pano = tmp / "pano.png"
    write_png16(pano, direction_latlong(128, 256).astype(np.float64))
    fish = tmp / "fish.png"
    # 200°, looking along -Z: the directions within 100° of -Z.
    cli("convert", pano, fish, "--to", "fisheye:fov=200", "--size", 256, "--quiet")
    out = tmp / "out"
    cli("views", fish, out, "--rig", "cube", "--size", 48, "--quiet")
    rec = pycolmap.Reconstruction(str(out / "sparse" / "0"))
    t = json.loads((out / "transforms.json").read_text())
    masks = {f["file_path"].removeprefix("images/"): f["mask_path"] for f in t["frames"]}
    counts = np.zeros(2, int)
    for image in rec.images.values():
        cam = rec.cameras[image.camera_id]
        # COLMAP's mask naming: masks/NAME.png.
        assert masks[image.name] == f"masks/{image.name}.png"
        mask = cv2.imread(str(out / masks[image.name]), cv2.IMREAD_UNCHANGED)
        assert mask.dtype == np.uint8 and mask.shape == (cam.height, cam.width)
        assert set(np.unique(mask)) <= {0, 255}
        xy = pixel_grid(cam.width, cam.height)
        rays = np.concatenate([cam.cam_from_img(xy), np.ones((len(xy), 1))], -1)
        world = rays @ image.cam_from_world().rotation.matrix() @ COLMAP_TO_MB.T
        off_axis = angles(world, np.array([0.0, 0.0, -1.0]))
        covered = off_axis <= np.deg2rad(100)
        clear = np.abs(off_axis - np.deg2rad(100)) > 1e-6
        valid = mask.ravel() == 255
        assert np.array_equal(valid[clear], covered[clear]), image.name
        counts += np.bincount(valid.astype(int), minlength=2)
    assert counts.min() > 1000, counts


def test_exif_time_and_place_are_carried(cli, tmp):
    """A JPEG panorama's capture time and GPS fields, read back by Pillow from every JPEG
    view, and recorded in transforms.json for PNG views."""
    Image = pytest.importorskip("PIL.Image")
    from PIL import ExifTags

    pano = tmp / "pano.jpg"
    rgb = (direction_latlong(64, 128) * 255 + 0.5).astype(np.uint8)
    exif = Image.Exif()
    exif.get_ifd(ExifTags.IFD.Exif)[ExifTags.Base.DateTimeOriginal] = "2024:05:01 12:34:56"
    gps = exif.get_ifd(ExifTags.IFD.GPSInfo)
    gps[ExifTags.GPS.GPSLatitudeRef] = "S"
    gps[ExifTags.GPS.GPSLatitude] = (33.0, 30.0, 0.0)
    gps[ExifTags.GPS.GPSLongitudeRef] = "E"
    gps[ExifTags.GPS.GPSLongitude] = (151.0, 12.0, 36.0)
    Image.fromarray(rgb).save(pano, exif=exif)

    out = tmp / "jpg"
    cli("views", pano, out, "--size", 32, "--format", "jpg", "--quiet")
    for view in ["front", "right", "back", "left", "up", "down"]:
        with Image.open(out / "images" / view / "pano.jpg") as im:
            e = im.getexif()
            assert e.get_ifd(ExifTags.IFD.Exif)[ExifTags.Base.DateTimeOriginal] == "2024:05:01 12:34:56"
            g = e.get_ifd(ExifTags.IFD.GPSInfo)
            assert g[ExifTags.GPS.GPSLatitudeRef] == "S"
            assert [float(v) for v in g[ExifTags.GPS.GPSLatitude]] == [33.0, 30.0, 0.0]
            assert [float(v) for v in g[ExifTags.GPS.GPSLongitude]] == [151.0, 12.0, 36.0]
            assert im.size == (32, 32)

    out = tmp / "png"
    cli("views", pano, out, "--size", 32, "--quiet")
    record = json.loads((out / "transforms.json").read_text())["mirrorball"]["exif"]["pano"]
    assert record["DateTimeOriginal"] == "2024:05:01 12:34:56"
    assert record["latitude"] == pytest.approx(-33.5)
    assert record["longitude"] == pytest.approx(151.21)


def test_colmap_applies_the_rig_to_a_database(rig, tmp):
    """COLMAP's own step of rig-aware mapping: the views imported one camera per folder,
    then `apply_rig_config` makes them one rig (the first view its reference) and one frame,
    each sensor posed as the model poses its camera."""
    db_path = tmp / "database.db"
    pycolmap.Database.open(str(db_path)).close()
    pycolmap.import_images(str(db_path), str(rig / "images"), camera_mode=pycolmap.CameraMode.PER_FOLDER)
    configs = pycolmap.read_rig_config(str(rig / "rig_config.json"))
    rec = pycolmap.Reconstruction(str(rig / "sparse" / "0"))
    posed = {im.name: im.cam_from_world().rotation.matrix() for im in rec.images.values()}
    with pycolmap.Database.open(str(db_path)) as db:
        pycolmap.apply_rig_config(configs, db)
        rigs, frames = db.read_all_rigs(), db.read_all_frames()
        assert len(rigs) == 1 and len(frames) == 1
        images = {im.camera_id: im.name for im in db.read_all_images()}
        assert len(images) == 8 and len(frames[0].data_ids) == 8
        cameras = {c.camera_id: c for c in db.read_all_cameras()}
    r = rigs[0]
    ref = images[r.ref_sensor_id.id]
    assert ref.startswith(configs[0].cameras[0].image_prefix)
    assert len(list(r.non_ref_sensors)) == 7
    for sensor in r.non_ref_sensors:
        name = images[sensor.id]
        expected = posed[name] @ posed[ref].T
        assert np.allclose(r.sensor_from_rig(sensor).rotation.matrix(), expected, atol=1e-9), name
        model = rec.cameras[rec.find_image_with_name(name).camera_id]
        assert cameras[sensor.id].model == pycolmap.CameraModelId.PINHOLE
        assert np.allclose(cameras[sensor.id].params, model.params)


def test_fisheye_views_are_colmaps_opencv_fisheye(cli, tmp):
    """Fisheye views (equidistant, OPENCV_FISHEYE with k = 0): pycolmap's own fisheye model
    gives each pixel inside the disk the direction the pixel holds."""
    pano = tmp / "pano.png"
    write_png16(pano, direction_latlong(512, 1024).astype(np.float64))
    rig_file = tmp / "rig.json"
    rig_file.write_text(json.dumps({"views": [
        {"name": "front", "model": "fisheye", "fov": 170},
        {"name": "back", "model": "fisheye", "yaw": 180, "pitch": 20, "roll": 10, "fov": 140},
    ]}))
    out = tmp / "out"
    cli("views", pano, out, "--rig", rig_file, "--size", 160, "--format", "png16", "--quiet")
    rec = pycolmap.Reconstruction(str(out / "sparse" / "0"))
    fovs = {"front": 170.0, "back": 140.0}
    worst = np.zeros(2)
    for image in rec.images.values():
        cam = rec.cameras[image.camera_id]
        assert cam.model == pycolmap.CameraModelId.OPENCV_FISHEYE
        seen, w, h = view_directions(out, image.name)
        xy = pixel_grid(w, h)
        # Inside the disk, less a pixel at its rim (where the picture's filter reaches out).
        r = np.hypot(xy[:, 0] - cam.principal_point_x, xy[:, 1] - cam.principal_point_y)
        inside = r < 0.5 * w - 1.0
        rays = np.concatenate([cam.cam_from_img(xy[inside]), np.ones((inside.sum(), 1))], -1)
        world = rays @ image.cam_from_world().rotation.matrix() @ COLMAP_TO_MB.T
        worst = np.maximum(worst, check_errors(angles(world, seen[inside]), world))
        mask = cv2.imread(str(out / "masks" / f"{image.name}.png"), cv2.IMREAD_UNCHANGED)
        assert mask.ravel()[r > 0.5 * w + 1.0].max() == 0 and mask.ravel()[inside].min() == 255
        assert np.isclose(cam.focal_length_x, 0.5 * w / np.deg2rad(0.5 * fovs[image.name.split("/")[0]]))
    print(f"OPENCV_FISHEYE rays vs pixels: worst {worst[0]:.2e} rad, {worst[1]:.2e} rad 5 degrees from the poles")
    assert worst[0] < HALF_TEXEL and worst[1] < 5e-4
