"""Dask: a folder of lat-long frames or HDRIs converted to cube maps on a cluster (here a
`LocalCluster`; any `distributed` scheduler works), one `Remap` per partition.

    python dask_convert.py IN_DIR OUT_DIR [--size 512] [--workers 2]

The paths are split into partitions; each task plans the conversion once for its frames'
shape and converts them one after another. mirrorball releases the GIL, so a worker's
threads can read, convert and write at once.
"""

import argparse
import pathlib

import dask.bag as db
from dask.distributed import Client, LocalCluster

import mirrorball as mb


def convert_partition(paths, out_dir, size):
    """Converts `paths` with one plan; returns the files written."""
    plan, written = None, []
    for path in paths:
        array, info = mb.read(path)
        if plan is None:
            plan = mb.Remap(array.shape, src=info["projection"], dst="cube", size=size)
        cube = plan.apply(array, invalid="zero")
        out = pathlib.Path(out_dir) / (pathlib.Path(path).stem + ".exr")
        mb.write(out, cube, projection="cube", layout="hcross")
        written.append(str(out))
    return written


def convert_folder(in_dir, out_dir, size=512, workers=2, client=None):
    """Converts every .exr/.hdr/.png/.jpg in `in_dir` into `out_dir`; returns the files."""
    paths = sorted(
        str(p) for p in pathlib.Path(in_dir).iterdir() if p.suffix.lower() in {".exr", ".hdr", ".png", ".jpg"}
    )
    pathlib.Path(out_dir).mkdir(parents=True, exist_ok=True)
    own = client is None
    if own:
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
        client = Client(cluster)
    try:
        bag = db.from_sequence(paths, npartitions=max(1, min(len(paths), workers * 2)))
        return sorted(bag.map_partitions(convert_partition, str(out_dir), size).compute())
    finally:
        if own:
            client.close()
            cluster.close()


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("in_dir")
    ap.add_argument("out_dir")
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args()
    for f in convert_folder(a.in_dir, a.out_dir, a.size, a.workers):
        print(f)
