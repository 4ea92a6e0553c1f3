#!/usr/bin/env bash
# Builds octiso with AddressSanitizer + UndefinedBehaviorSanitizer (-DOCTISO_SANITIZE=ON,
# RelWithDebInfo at -O1 -g1) into build-asan/ (or $OCTISO_ASAN_BUILD_DIR) and runs the test suite
# there. -O1 -g1 in place of RelWithDebInfo's -O2 -g: the sanitizers instrument the same code,
# reports keep function, file and line, and the compile is about half: the AVX2 kernel took
# 124 s against 266 s (one core, g++ 12; BENCHMARKS "CI time").
# OCTISO_SANITIZE_FILTER (a ctest -E regex) leaves out tests too slow under the sanitizers;
# empty by default: the whole suite runs. Measured on 2 cores (2026-12-04): build ~15 min from
# scratch (~25 at -O2 -g; incremental: minutes), ctest ~17 min (~15 at -O2; Release ~6 min).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${OCTISO_ASAN_BUILD_DIR:-$root/build-asan}
jobs=${OCTISO_JOBS:-$(nproc)}
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DOCTISO_SANITIZE=ON -DOCTISO_BUILD_BENCH=OFF -DOCTISO_BUILD_PYTHON=OFF ${OCTISO_CMAKE_ARGS:-} >/dev/null
cmake --build "$build" -j "$jobs"
cd "$build"
# halt_on_error: a report fails the test instead of scrolling past; leaks are real bugs here too.
export ASAN_OPTIONS=${ASAN_OPTIONS:-halt_on_error=1:detect_leaks=1:abort_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
# Leaks inside third-party libraries (listed with their reason in lsan.supp) are not ours to fix.
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$root/scripts/lsan.supp}
filter=()
if [[ -n "${OCTISO_SANITIZE_FILTER:-}" ]]; then filter=(-E "$OCTISO_SANITIZE_FILTER"); fi
ctest --no-tests=error --output-on-failure -j "$jobs" "${filter[@]}"
