#!/usr/bin/env bash
# The md5 of a fixed set of outputs (converts, prefilters, bakes, renders, pipe frames, a
# compare's difference picture, the demo) made
# from the bundled maps: run with two builds and diff the lists to show which outputs a
# change altered. Usage: scripts/md5set.sh BINARY OUTDIR > list.txt
set -euo pipefail
MB=$(realpath "$1"); OUT=$2
ROOT=$(cd "$(dirname "$0")/.." && pwd)
A=$ROOT/assets/env
rm -rf "$OUT"; mkdir -p "$OUT"; cd "$OUT"
q() { "$MB" "$@" >/dev/null 2>&1 || echo "FAILED: $*" >&2; }
q convert "$A/city.exr" c.exr --to cube --size 64
q convert "$A/city.exr" c.ktx2 --to cube --size 64 --mips
q convert "$A/city.exr" c.dds --to cube --size 64
q convert "$A/sky.exr" a.exr --to angular --size 128
q convert "$A/sky.exr" f.png --to fisheye:fov=180:look=+y --size 128
q convert "$A/sky.exr" 'face_{face}.png' --to cube --size 32 --exposure -2
q convert "$A/venice.exr" ll.hdr --to latlong --size 128 --yaw 90
q convert "$A/studio.exr" e.png --to eac --size 64
q convert "$A/studio.exr" o.jpg --to octahedral --size 64
q convert "$A/city.exr" p.exr --to perspective:hfov=90:vfov=60 --size 96
q prefilter "$A/sky.exr" ggx.ktx2 --lobe ggx --size 32
q prefilter "$A/sky.exr" irr.ktx2 --lobe lambert --size 16 --sh-window auto
for e in bevy three babylon gltf filament unity unreal ktx2; do q bake "$A/sky.exr" --for $e "bake-$e" --size 32; done
q render -o door.png --object quad --env "$A/venice.exr" --mode texgen --attach eye --size 96x64
q render -o bunny.png --object "$ROOT/assets/meshes/bunny.obj" --env "$A/studio.exr" --mode pixel --size 96x64
q convert "$A/city.exr" src.png --to latlong --size 256
q compare "$A/city.exr" c.exr --diff diff.png
q demo --out demo --size 64
if command -v ffmpeg >/dev/null; then
  ffmpeg -v error -i src.png -f rawvideo -pix_fmt rgb24 - | "$MB" convert - - --from latlong --in-size 256x128 --pix-fmt rgb24 --to cube --size 32 --layout hstrip > pipe.rgb 2>/dev/null || echo "FAILED: pipe" >&2
fi
# The demo's index and summary hold timings.
find . -type f ! -name src.png ! -path ./demo/index.html ! -path ./demo/summary.txt | sort | xargs md5sum
