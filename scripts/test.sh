#!/usr/bin/env bash
# Installs what octiso needs, builds it in Release with warnings, and runs the whole test suite;
# then (unless OCTISO_SANITIZE_CI=0) the suite again under ASan + UBSan (scripts/test-sanitize.sh).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh"
"$root/scripts/build.sh"
(cd "${OCTISO_BUILD_DIR:-$root/build}" && ctest --no-tests=error --output-on-failure -j "$(nproc)")
if [[ "${OCTISO_SANITIZE_CI:-1}" != "0" ]]; then
    "$root/scripts/test-sanitize.sh"
fi
