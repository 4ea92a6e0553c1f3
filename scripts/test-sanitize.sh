#!/usr/bin/env bash
# Builds octiso with AddressSanitizer + UndefinedBehaviorSanitizer (-DOCTISO_SANITIZE=ON,
# RelWithDebInfo at -O1 -g1) into build-asan/ (or $OCTISO_ASAN_BUILD_DIR) and runs the test suite
# there. -O1 -g1 in place of RelWithDebInfo's -O2 -g: the sanitizers instrument the same code,
# reports keep function, file and line, and the compile is about half: the AVX2 kernel took
# 124 s against 266 s (one core, g++ 12; BENCHMARKS "CI time").
# OCTISO_SANITIZE_FILTER (a ctest -E regex) leaves out tests too slow under the sanitizers;
# by default the whole suite runs but for IsaKernelsSeparate (below). Measured on 2 cores: build
# ~15 min from scratch (~25 at -O2 -g; incremental: minutes), ctest ~11 min (2026-12-05; ~17 min
# before OpenImageIO became a module loaded on the first image, BENCHMARKS "CI time").
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${OCTISO_ASAN_BUILD_DIR:-$root/build-asan}
jobs=${OCTISO_JOBS:-$(nproc)}
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DOCTISO_SANITIZE=ON -DOCTISO_BUILD_BENCH=OFF -DOCTISO_BUILD_PYTHON=OFF ${OCTISO_CMAKE_ARGS:-} >/dev/null
cmake --build "$build" -j "$jobs"
cd "$build"
# halt_on_error: a report fails the test instead of scrolling past; leaks are real bugs here too.
# intercept_tls_get_addr=0: OpenImageIO and its libraries are dlopened (src/io/image_codec.h), so
# their thread-locals are dynamic TLS, and GCC 12's interceptor of __tls_get_addr takes a block
# that happens to start 16 bytes past a page boundary for one with a pre-2.25 glibc header: the
# leak checker's tracer then segfaults at exit ("Tracer caught signal 11"; seen once in 676
# tests; Mudlet/Mudlet#9930 traced it). Without the interceptor, dynamic TLS is not scanned
# for pointers; octiso's own thread-locals are static TLS, which still is.
export ASAN_OPTIONS=${ASAN_OPTIONS:-halt_on_error=1:detect_leaks=1:abort_on_error=1:intercept_tls_get_addr=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
# Leaks inside third-party libraries (listed with their reason in lsan.supp) are not ours to fix.
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$root/scripts/lsan.supp}
# IsaKernelsSeparate only disassembles the binaries (no octiso code runs, nothing for a sanitizer
# to see); the Release suite runs it on the binaries that ship. Under ASan it took 177 s of CPU.
filter=(-E "^IsaKernelsSeparate\$${OCTISO_SANITIZE_FILTER:+|$OCTISO_SANITIZE_FILTER}")
ctest --no-tests=error --output-on-failure -j "$jobs" "${filter[@]}"
