"""Ray Data: a folder of lat-long frames or HDRIs converted to cube maps, one `Remap` per
worker, made once and applied to every batch it is given.

    python ray_convert.py IN_DIR OUT_DIR [--size 512] [--cpus 2]

Each worker (an actor of Ray Data's pool) plans the conversion once for the frames' shape
and converts batches of frames; mirrorball releases the GIL and uses the worker's threads
(`mirrorball.set_threads`). Files are read and written by mirrorball (any format it knows).
"""

import argparse
import os
import pathlib

import numpy as np
import ray

import mirrorball as mb


class Converter:
    """Plans once (on the first frame's shape), then converts every batch of paths."""

    def __init__(self, out_dir, size, threads):
        self.out_dir = pathlib.Path(out_dir)
        self.size = size
        self.plan = None
        mb.set_threads(threads)

    def __call__(self, batch):
        written = []
        for path in batch["path"]:
            array, info = mb.read(path)
            if self.plan is None:
                self.plan = mb.Remap(array.shape, src=info["projection"], dst="cube", size=self.size)
            cube = self.plan.apply(array, invalid="zero")
            out = self.out_dir / (pathlib.Path(path).stem + ".exr")
            mb.write(out, cube, projection="cube", layout="hcross")
            written.append(str(out))
        return {"written": np.array(written)}


def convert_folder(in_dir, out_dir, size=512, cpus=2):
    """Converts every .exr/.hdr/.png/.jpg in `in_dir` into `out_dir`; returns the files."""
    paths = sorted(
        str(p) for p in pathlib.Path(in_dir).iterdir() if p.suffix.lower() in {".exr", ".hdr", ".png", ".jpg"}
    )
    pathlib.Path(out_dir).mkdir(parents=True, exist_ok=True)
    started = not ray.is_initialized()
    if started:
        # The workers import this module (Converter) by name: its folder on their path.
        here = str(pathlib.Path(__file__).resolve().parent)
        path = os.pathsep.join(p for p in (here, os.environ.get("PYTHONPATH")) if p)
        ray.init(
            num_cpus=cpus,
            include_dashboard=False,
            log_to_driver=False,
            runtime_env={"env_vars": {"PYTHONPATH": path}},
        )
    try:
        ds = ray.data.from_items([{"path": p} for p in paths])
        ds = ds.map_batches(
            Converter,
            fn_constructor_args=(out_dir, size, 1),
            batch_size=4,
            concurrency=cpus,
            num_cpus=1,
        )
        return sorted(row["written"] for row in ds.take_all())
    finally:
        if started:
            ray.shutdown()


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("in_dir")
    ap.add_argument("out_dir")
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--cpus", type=int, default=2)
    a = ap.parse_args()
    for f in convert_folder(a.in_dir, a.out_dir, a.size, a.cpus):
        print(f)
