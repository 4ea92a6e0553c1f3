#!/usr/bin/env bash
# The viewer on the built-in default dataset (issue 20): installs, builds octiso-convert and
# octiso-view, converts the synthetic plume (256^3 u8, as scripts/demo.sh) and serves it on
# loopback; open the printed URL in a browser, Ctrl-C to stop. Override with DATASET=mixing:256
# ISO=127.5 PORT=8080.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${OCTISO_BUILD_DIR:-$root/build}
out=${OCTISO_DEMO_DIR:-$root/out}
dataset=${DATASET:-plume:256}
iso=${ISO:-40.5}
port=${PORT:-8080}

"$root/scripts/setup.sh"
"$root/scripts/build.sh" --target octiso-convert octiso-view >/dev/null
mkdir -p "$out"
name=${dataset%%:*}
[[ -f "$out/$name.oct" ]] || "$build/octiso-convert" --synthetic "$dataset" -o "$out/$name.oct"
exec "$build/octiso-view" "$out/$name.oct" --iso "$iso" --port "$port"
