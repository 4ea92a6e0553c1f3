#!/usr/bin/env bash
# Installs what octiso needs, builds it in Release with warnings, and runs the whole test suite.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
cd "${OCTISO_BUILD_DIR:-$root/build}"
ctest --output-on-failure -j "$(nproc)"
