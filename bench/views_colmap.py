"""`mirrorball views` against COLMAP's way of cutting panoramas into a rig (issue 38).

    python bench/views_colmap.py [--bin PATH] [--panos 3] [--reps 3] [--size 1600]
                                 [--pano 7680x3840] [--workers N] [--keep DIR]

Makes one synthetic, detailed 7680×3840 JPEG panorama (quality 95, with GPS EXIF) in a
temporary folder, copied `--panos` times (`pano_000.jpg`, …), then times, alternating,
`--reps` times each, wall clock of a whole run:

- **mirrorball**: the release binary, `views 'DIR/pano_*.jpg' OUT --rig cube --size 1600
  --format jpg --masks -q`: all panoramas as one sequence (one rig), six antialiased
  90° views each, JPEG quality 92 with the EXIF carried, and a mask per view (`--masks`,
  so both tools write the same files; a lat-long's masks are all white).
- **COLMAP**: the rendering path of colmap/colmap `python/examples/panorama_sfm.py`
  (`render_perspective_images` and `PanoProcessor.process`), re-implemented here step for
  step, in this process: a `SIMPLE_PINHOLE` virtual camera made by pycolmap
  (`create_virtual_camera`, here 1600×1600 with a 90° field of view instead of the
  script's `pano_width·hfov/360` wide), its pixel-centre rays by `camera.cam_from_img`
  (`get_virtual_camera_rays`, computed once, under a lock, for the first panorama), the
  rotations `Rotation.from_euler("XY", [-pitch, -yaw])` (`get_virtual_rotations`, here the
  cube's six: yaw 0, 90, 180, 270 at pitch 0, then pitch ±90), per view the rays rotated
  into the panorama, `spherical_img_from_cam`, −0.5 to OpenCV's pixel origin,
  `cv2.remap(INTER_LINEAR, BORDER_WRAP)`, the mask of the pixels whose closest camera
  centre is this view's, `PIL.Image.save(..., exif=GPS only)` (PIL's default JPEG quality,
  75) and `pycolmap.Bitmap.from_array(mask).write(...)`; the panoramas spread over a
  `ThreadPoolExecutor` (the script's `min(32, cpu_count − 1)` workers would be one on a
  two-core machine; `--workers`, default the core count, gives it every core, as
  mirrorball's thread pool has them). Process start-up and imports are not timed for it.

Prints each run's wall time, the bests and medians, their ratios and the threads each
used.
"""

import argparse
import os
import shutil
import statistics
import subprocess
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from pathlib import Path
from threading import Lock

import cv2
import numpy as np
import PIL.ExifTags
import PIL.Image
import pycolmap
from scipy.spatial.transform import Rotation

# The cube's faces as (yaw, pitch) in degrees, in mirrorball's `cube` order (front right
# back left up down).
CUBE = [(0.0, 0.0), (90.0, 0.0), (180.0, 0.0), (270.0, 0.0), (0.0, 90.0), (0.0, -90.0)]


def make_panorama(path: Path, w: int, h: int) -> None:
    """A detailed picture: a zone plate in longitude, checkers of several sizes, smooth
    colour ramps and noise, saved as a JPEG (quality 95) with a GPS position."""
    rng = np.random.default_rng(38)
    y = np.linspace(0.0, 1.0, h, dtype=np.float32)[:, None]
    x = np.linspace(0.0, 1.0, w, dtype=np.float32)[None, :]
    plate = 0.5 + 0.5 * np.cos(2000.0 * (x - 0.5) ** 2 + 900.0 * (y - 0.5) ** 2)
    checks = (((x * 96).astype(np.int32) + (y * 48).astype(np.int32)) % 2).astype(np.float32)
    fine = (((x * 1920).astype(np.int32) ^ (y * 960).astype(np.int32)) & 1).astype(np.float32)
    base = np.stack(
        [
            0.45 * plate + 0.25 * checks + 0.2 * x,
            0.35 * plate + 0.25 * fine + 0.3 * y,
            0.3 * checks + 0.3 * fine + 0.3 * (1 - x) * y,
        ],
        axis=-1,
    )
    base += rng.normal(0.0, 0.04, size=(h, w, 1)).astype(np.float32)
    img = np.clip(base * 255.0, 0, 255).astype(np.uint8)
    exif = PIL.Image.Exif()
    exif[PIL.ExifTags.IFD.GPSInfo] = {
        1: "N",
        2: (48.0, 51.0, 29.0),
        3: "E",
        4: (2.0, 17.0, 40.0),
    }
    PIL.Image.fromarray(img).save(path, quality=95, exif=exif)


class ColmapPeer:
    """`PanoProcessor`'s rendering, for a rig of `rotations` of `size`² 90° views."""

    def __init__(self, out: Path, size: int):
        self.out = out
        self.size = size
        # get_virtual_rotations: cam_from_pano for each view.
        self.rotations = [
            Rotation.from_euler("XY", [-pitch, -yaw], degrees=True).as_matrix()
            for yaw, pitch in CUBE
        ]
        # Each panorama pixel goes to the view with the closest camera centre.
        self.centres = np.einsum("nij,i->nj", self.rotations, [0, 0, 1])
        self.lock = Lock()
        self.camera = None
        self.pano_size = None
        self.rays = None

    def _camera(self) -> pycolmap.Camera:
        # create_virtual_camera, at the benchmark's size.
        hfov = 90.0
        focal = self.size / (2 * np.tan(np.deg2rad(hfov) / 2))
        cam = pycolmap.Camera.create_from_model_id(
            camera_id=0,
            model=pycolmap.CameraModelId.SIMPLE_PINHOLE,
            focal_length=focal,
            width=self.size,
            height=self.size,
        )
        cam.has_prior_focal_length = True
        return cam

    @staticmethod
    def _rays(cam: pycolmap.Camera) -> np.ndarray:
        # get_virtual_camera_rays: pixel centres at +0.5, column-major (x, y) order.
        x, y = np.indices((cam.width, cam.height)).astype(np.float32)
        xy = np.column_stack([x.ravel(), y.ravel()]) + 0.5
        xy_norm = cam.cam_from_img(image_points=xy)
        rays = np.concatenate([xy_norm, np.ones_like(xy_norm[:, :1])], -1)
        rays /= np.linalg.norm(rays, axis=-1, keepdims=True)
        return rays

    @staticmethod
    def _spherical(size, r: np.ndarray) -> np.ndarray:
        # spherical_img_from_cam.
        r = r.T
        yaw = np.arctan2(r[0], r[2])
        pitch = -np.arctan2(r[1], np.linalg.norm(r[[0, 2]], axis=0))
        u = (1 + yaw / np.pi) / 2
        v = (1 - pitch * 2 / np.pi) / 2
        return np.stack([u, v], -1) * size

    def process(self, pano_path: Path) -> None:
        pil = PIL.Image.open(pano_path)
        pano_exif = pil.getexif()
        gps = PIL.Image.Exif()
        gps[PIL.ExifTags.IFD.GPSInfo] = pano_exif.get_ifd(PIL.ExifTags.IFD.GPSInfo)
        pano = np.asarray(pil)
        ph, pw = pano.shape[:2]
        with self.lock:
            if self.camera is None:
                self.camera = self._camera()
                self.pano_size = (pw, ph)
                self.rays = self._rays(self.camera)
        cam = self.camera
        for idx, cam_from_pano in enumerate(self.rotations):
            rays_in_pano = self.rays @ cam_from_pano
            xy = self._spherical(self.pano_size, rays_in_pano)
            xy = xy.reshape(cam.width, cam.height, 2).astype(np.float32)
            xy -= 0.5
            mx, my = np.moveaxis(xy, [0, 1, 2], [2, 1, 0])
            image = cv2.remap(pano, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_WRAP)
            closest = np.argmax(rays_in_pano @ self.centres.T, -1)
            mask = (
                ((closest == idx) * 255)
                .astype(np.uint8)
                .reshape(cam.width, cam.height)
                .transpose()
            )
            name = f"pano_camera{idx}/{pano_path.name}"
            image_path = self.out / "images" / name
            image_path.parent.mkdir(exist_ok=True, parents=True)
            PIL.Image.fromarray(image).save(image_path, exif=gps)
            mask_path = self.out / "masks" / f"{name}.png"
            mask_path.parent.mkdir(exist_ok=True, parents=True)
            if not pycolmap.Bitmap.from_array(mask).write(mask_path):
                raise RuntimeError(f"cannot write {mask_path}")


def run_colmap(panos, out: Path, size: int, workers: int) -> float:
    t = time.perf_counter()
    peer = ColmapPeer(out, size)
    with ThreadPoolExecutor(max_workers=workers) as pool:
        for f in as_completed([pool.submit(peer.process, p) for p in panos]):
            f.result()
    return time.perf_counter() - t


def run_mirrorball(binary: str, pattern: str, out: Path, size: int) -> float:
    t = time.perf_counter()
    subprocess.run(
        [binary, "views", pattern, str(out), "--rig", "cube", "--size", str(size),
         "--format", "jpg", "--masks", "-q"],
        check=True,
    )
    return time.perf_counter() - t


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    target = os.environ.get("CARGO_TARGET_DIR", "target")
    ap.add_argument("--bin", default=os.path.join(target, "release", "mirrorball"))
    ap.add_argument("--panos", type=int, default=3)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--size", type=int, default=1600)
    ap.add_argument("--pano", default="7680x3840")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 2)
    ap.add_argument("--keep", help="write the outputs of the last run here")
    args = ap.parse_args()
    pw, ph = (int(s) for s in args.pano.split("x"))

    with tempfile.TemporaryDirectory(prefix="views_colmap_") as tmp:
        tmp = Path(tmp)
        src = tmp / "src"
        src.mkdir()
        t = time.perf_counter()
        make_panorama(src / "pano_000.jpg", pw, ph)
        for i in range(1, args.panos):
            shutil.copyfile(src / "pano_000.jpg", src / f"pano_{i:03}.jpg")
        panos = sorted(src.glob("pano_*.jpg"))
        mb_size = (src / "pano_000.jpg").stat().st_size / 1e6
        print(
            f"{args.panos} panoramas {pw}x{ph} JPEG ({mb_size:.1f} MB each, made in "
            f"{time.perf_counter() - t:.1f}s); six 90° views of {args.size}x{args.size}"
        )
        cores = os.cpu_count()
        print(
            f"threads: mirrorball its rayon pool ({os.environ.get('RAYON_NUM_THREADS', cores)}"
            f" of {cores} cores); COLMAP's path {args.workers} ThreadPoolExecutor workers,"
            f" cv2 {cv2.getNumThreads()} threads"
        )
        times = {"mirrorball": [], "colmap": []}
        for rep in range(args.reps):
            for who in ("mirrorball", "colmap"):
                out = tmp / f"out_{who}"
                shutil.rmtree(out, ignore_errors=True)
                if who == "mirrorball":
                    dt = run_mirrorball(args.bin, str(src / "pano_*.jpg"), out, args.size)
                else:
                    out.mkdir()
                    dt = run_colmap(panos, out, args.size, args.workers)
                times[who].append(dt)
                print(f"  rep {rep}: {who:<10} {dt:7.2f}s ({dt / args.panos:.2f}s a panorama)")
        if args.keep:
            for who in times:
                shutil.copytree(tmp / f"out_{who}", Path(args.keep) / who, dirs_exist_ok=True)
        # Best and median: a shared machine's other work lengthens runs, never shortens them.
        for label, pick in (("best", min), ("median", statistics.median)):
            mb, cm = pick(times["mirrorball"]), pick(times["colmap"])
            print(
                f"{label}: mirrorball {mb:.2f}s ({mb / args.panos:.2f}s/pano), "
                f"COLMAP panorama_sfm.py path {cm:.2f}s ({cm / args.panos:.2f}s/pano): "
                f"mirrorball {cm / mb:.2f}x faster"
            )


if __name__ == "__main__":
    main()
