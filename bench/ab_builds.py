#!/usr/bin/env python3
"""Two builds of mirrorball side by side, in alternating rounds: `convert` and `prefilter`
end to end on the 4K benchmark maps (outputs compared byte for byte), and the renderer's
`bench_render` frames per second. Prints best and median of each and their ratios.

    bench/ab_builds.py --base DIR --new DIR [--rounds 7] [--render-rounds 4]

DIR holds `mirrorball` and `bench_render` (e.g. `target/release` with
`target/release/examples/bench_render` copied beside it). The inputs are the 4K maps
`bench/setup.sh` makes in bench/data/.
"""
import argparse, filecmp, os, statistics, subprocess, tempfile, time, collections

ap = argparse.ArgumentParser()
ap.add_argument("--base", required=True)
ap.add_argument("--new", required=True)
ap.add_argument("--rounds", type=int, default=7)
ap.add_argument("--render-rounds", type=int, default=4)
a = ap.parse_args()
data = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data")
builds = {"base": a.base, "new": a.new}
tmp = tempfile.mkdtemp(prefix="ab-builds-")
cases = {
    "convert city-4k -> six float faces": lambda b, o: [f"{b}/mirrorball", "convert", f"{data}/city-4k.exr",
        f"{o}/cube_{{face}}.exr", "--to", "cube", "--size", "1024", "--precision", "float", "--compression", "none", "-q"],
    "prefilter sky-4k, GGX 6x512^2": lambda b, o: [f"{b}/mirrorball", "prefilter", f"{data}/sky-4k.exr",
        f"{o}/p.ktx2", "--lobe", "ggx", "--size", "512", "-q"],
}

def ratio_line(name, base, new, unit, higher_is_better=False):
    bb, nb = (max if higher_is_better else min)(base), (max if higher_is_better else min)(new)
    bm, nm = statistics.median(base), statistics.median(new)
    print(f"{name}: base {bb:.3f} ({bm:.3f}) {unit} | new {nb:.3f} ({nm:.3f}) {unit} | new/base {nb / bb:.3f} ({nm / bm:.3f})")

for name, cmd in cases.items():
    t = {k: [] for k in builds}
    for r in range(a.rounds):
        for k, b in (list(builds.items()) if r % 2 == 0 else list(builds.items())[::-1]):
            o = os.path.join(tmp, k)
            os.makedirs(o, exist_ok=True)
            s = time.perf_counter()
            subprocess.run(cmd(b, o), check=True)
            t[k].append(time.perf_counter() - s)
    ratio_line(name, t["base"], t["new"], "s")
    files = sorted(os.listdir(os.path.join(tmp, "base")))
    same = all(filecmp.cmp(os.path.join(tmp, "base", f), os.path.join(tmp, "new", f), shallow=False)
               for f in files if not f.endswith(".json"))
    print(f"  outputs byte-identical (SH JSON aside): {same}")

fps = collections.defaultdict(lambda: collections.defaultdict(list))
for r in range(a.render_rounds):
    for k, b in (list(builds.items()) if r % 2 == 0 else list(builds.items())[::-1]):
        out = subprocess.run([f"{b}/bench_render", "--frames", "20", "--reps", "3"], check=True,
                             capture_output=True, text=True).stdout
        for line in out.splitlines():
            if "\t" in line:
                case, v = line.rsplit("\t", 1)
                fps[case][k].append(float(v))
for case, v in fps.items():
    ratio_line(case, v["base"], v["new"], "fps", higher_is_better=True)
