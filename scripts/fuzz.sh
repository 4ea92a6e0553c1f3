#!/usr/bin/env bash
# Builds the libFuzzer targets in fuzz/ with clang (ASan+UBSan, in build-fuzz/ or
# $OCTISO_FUZZ_BUILD_DIR) and runs each one on a scratch copy of its committed seed corpus.
#   scripts/fuzz.sh [SECONDS]        each target for SECONDS (default 45: the CI smoke run)
#   FUZZ_RUNS=1000000 scripts/fuzz.sh  each target for exactly that many executions instead
# Exit status: non-zero if any target found a crash, leak, timeout or sanitizer report; the
# reproducer is left in build-fuzz/findings/<target>/.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${OCTISO_FUZZ_BUILD_DIR:-$root/build-fuzz}
seconds=${1:-45}
targets="oct_loader raw_reader nifti_header render view_request"
# -O1 with line tables (libFuzzer's own suggestion, -g -O1) in place of RelWithDebInfo's -O2 -g:
# the AVX2 kernel compiled in 104 s against 145 s (BENCHMARKS "CI time"); findings keep file:line.
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=${CXX_FUZZ:-clang++} \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG" -DOCTISO_FUZZ=ON -DOCTISO_BUILD_BENCH=OFF -DOCTISO_BUILD_PYTHON=OFF ${OCTISO_CMAKE_ARGS:-} >/dev/null
cmake --build "$build" -j "${OCTISO_JOBS:-$(nproc)}" $(for t in $targets; do echo --target fuzz_$t; done)
# One target per core at a time: libFuzzer runs a target on one thread, so on 2 cores the five
# smoke runs take three rounds of SECONDS instead of five (CI time, BENCHMARKS "CI time").
run_target() {   # TARGET: one fuzzer run; its report and summary printed when it ends
  local t=$1 work="$build/corpus/$1" findings="$build/findings/$1" limit=(-max_total_time="$seconds") result=0
  rm -rf "$work" && mkdir -p "$work" "$findings"
  [ -n "${FUZZ_RUNS:-}" ] && limit=(-runs="$FUZZ_RUNS")
  # detect_leaks=0: TBB's and Embree's process-lifetime allocations are not findings.
  if ! ASAN_OPTIONS=detect_leaks=0:${ASAN_OPTIONS:-} "$build/fuzz/fuzz_$t" "${limit[@]}" -timeout=10 -rss_limit_mb=4096 \
      -print_final_stats=1 -artifact_prefix="$findings/" "$work" "$root/fuzz/corpus/$t" 2>"$build/fuzz_$t.log"; then
    result=1
  fi
  {
    echo "== fuzz_$t ${limit[*]}"
    [ $result = 0 ] || echo "fuzz_$t: FINDING (see $build/fuzz_$t.log and $findings/)"
    grep -E "stat::number_of_executed_units|stat::peak_rss_mb|Done [0-9]+ runs" "$build/fuzz_$t.log" || true
  }
  return $result
}
status=0
pids=()
for t in $targets; do
  run_target "$t" &
  pids+=($!)
  if (( ${#pids[@]} >= ${OCTISO_JOBS:-$(nproc)} )); then
    wait "${pids[0]}" || status=1
    pids=("${pids[@]:1}")
  fi
done
for p in "${pids[@]}"; do wait "$p" || status=1; done
exit $status
