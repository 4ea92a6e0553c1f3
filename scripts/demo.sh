#!/usr/bin/env bash
# The main job on the built-in default dataset: install, build, convert a synthetic combustion-like
# plume (256^3, u8) into a lossless octree, render two isosurfaces of it on all cores, and say
# where the image is. Override with DATASET=mixing:256 ISO=128 SIZE=1024x1024.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${OCTISO_BUILD_DIR:-$root/build}
out=${OCTISO_DEMO_DIR:-$root/out}
dataset=${DATASET:-plume:256}
iso=${ISO:-40,110}
size=${SIZE:-1024x1024}

"$root/scripts/setup.sh"
"$root/scripts/build.sh" --target octiso-convert octiso-info octiso-render >/dev/null
mkdir -p "$out"
name=${dataset%%:*}

echo "== converting --synthetic $dataset"
"$build/octiso-convert" --synthetic "$dataset" -o "$out/$name.oct"
echo "== rendering isovalues $iso at $size"
"$build/octiso-render" "$out/$name.oct" --iso "$iso" --size "$size" -o "$out/$name.png" --depth "$out/$name-depth.exr" \
    --json > "$out/$name-render.json"
seconds=$(grep -o '"seconds":[0-9.e+-]*' "$out/$name-render.json" | head -1 | cut -d: -f2)
echo
echo "image:        $out/$name.png"
echo "depth (EXR):  $out/$name-depth.exr"
echo "frame time:   $seconds s ($(nproc) threads)"
