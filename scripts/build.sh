#!/usr/bin/env bash
# Configures and builds octiso in Release with warnings into build/ (or $OCTISO_BUILD_DIR).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${OCTISO_BUILD_DIR:-$root/build}
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=${OCTISO_BUILD_TYPE:-Release} ${OCTISO_CMAKE_ARGS:-} >/dev/null
cmake --build "$build" -j "$(nproc)" "$@"
