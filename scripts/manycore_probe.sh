#!/usr/bin/env bash
# The many-core scaling probe (issue 12): octiso-probe is the scaling benchmark linked with the core
# library alone (TBB and Embree), so it runs on a machine that has nothing installed.
#
#   scripts/manycore_probe.sh pack [BUILD_DIR] [KIT_DIR]   here: copy build/octiso-probe and the shared
#                                                         libraries it needs (not the C/C++ runtimes)
#                                                         into KIT_DIR (default .probe, git-ignored)
#   scripts/manycore_probe.sh run [KIT_DIR] [RESULTS_DIR] there: plume and mixing 512^3 at 512^2 and
#                                                         1024^2 on 1..16 threads, both tile orders,
#                                                         the build on the same counts, the machine's
#                                                         compute ceiling;
#                                                         tables on stdout, scaling_*.json in RESULTS_DIR
#
# With the device tool: pack here, then run with carry [".probe"] and RESULTS_DIR=$OUT. One run of
# both datasets takes about 4-6 minutes of a 16-core machine (THREADS, SIZE, IMAGES, REPEATS and
# ORDER override the defaults below).
set -euo pipefail
mode=${1:-}
case $mode in
  pack)
    build=${2:-build}; kit=${3:-.probe}
    [[ -x $build/octiso-probe ]] || { echo "manycore_probe: $build/octiso-probe not built (scripts/build.sh)" >&2; exit 2; }
    rm -rf "$kit"; mkdir -p "$kit/lib"
    cp "$build/octiso-probe" "$kit/"
    strip "$kit/octiso-probe"   # symbols are not needed there, and the kit travels within 64 MiB
    for lib in $(ldd "$kit/octiso-probe" | awk '/=>/ {print $3}'); do
      case $(basename "$lib") in
        libc.so*|libm.so*|libstdc++*|libgcc_s*|libpthread*|libdl*|librt*|ld-linux*) ;;
        *) cp -L "$lib" "$kit/lib/" ;;
      esac
    done
    grep -qxF "/$kit/" .git/info/exclude 2>/dev/null || echo "/$kit/" >> .git/info/exclude
    du -sh "$kit"; ls "$kit/lib"
    ;;
  run)
    kit=${2:-.probe}; results=${3:-/tmp/octiso-probe-results}
    threads=${THREADS:-1,2,4,8,12,16}; size=${SIZE:-512}; images=${IMAGES:-512,1024}; repeats=${REPEATS:-3}
    mkdir -p "$results"
    export LD_LIBRARY_PATH=$kit/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
    nproc; grep -m1 'model name' /proc/cpuinfo || true
    for data in plume mixing; do
      "$kit/octiso-probe" scaling --dataset "$data" --size "$size" --images "$images" --threads "$threads" \
        --repeats "$repeats" --tile-order "${ORDER:-both}" --results "$results/$data" 2>&1
      cp "$results/$data"/scaling_*.json "$results/"
    done
    ;;
  *)
    echo "usage: scripts/manycore_probe.sh pack [BUILD_DIR] [KIT_DIR] | run [KIT_DIR] [RESULTS_DIR]" >&2
    exit 2
    ;;
esac
