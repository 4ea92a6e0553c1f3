#!/usr/bin/env bash
# Builds octiso_tests with ThreadSanitizer (gcc, build-tsan/ or $OCTISO_TSAN_BUILD_DIR) and runs
# the renderer and builder tests under it. What TSan can and cannot see with Debian's
# uninstrumented libtbb is written in README.md (reliability); read it before trusting a clean run.
#   scripts/tsan.sh [GTEST_FILTER]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${OCTISO_TSAN_BUILD_DIR:-$root/build-tsan}
filter=${1:-'OctreeBuild*:OctreeOverArrayData*:DecodeToDense*:SparseOctree*:RenderAgreement*:RenderCracks*:RenderPaths*:RenderNothingOutsideData*:TraversalRobustness*:TinyVolumes*:Macrocell*:*/OctreeBuild*:*/RenderAgreement*:*/MacrocellGridTest*'}
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DOCTISO_TSAN=ON -DOCTISO_BUILD_BENCH=OFF ${OCTISO_CMAKE_ARGS:-} >/dev/null
cmake --build "$build" -j "${OCTISO_JOBS:-$(nproc)}" --target octiso_tests
# Every report is printed; any report makes the exit status 66. The tests spawn no tools here (the filter keeps
# to in-process tests), so every access TSan judges is in instrumented octiso code.
TSAN_OPTIONS="halt_on_error=0 exitcode=66 second_deadlock_stack=1 history_size=4 suppressions=$root/scripts/tsan.supp ${TSAN_OPTIONS:-}" \
  "$build/octiso_tests" --gtest_filter="$filter"
