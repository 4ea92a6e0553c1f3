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
#                                                         compute ceiling; plume 128^3 (cache-resident)
#                                                         render only; plume 2048^3 build and render on
#                                                         1, 4 and all cores where memory allows;
#                                                         tables on stdout and in NAME.txt, JSON in
#                                                         RESULTS_DIR/NAME/
#
# With the device tool: pack here, then run with carry [".probe"], e.g.
#   TARBALL=$OUT/probe.tgz scripts/manycore_probe.sh run .probe /tmp/probe
# (the tool brings back 8 files at most; the tarball holds them all). THREADS, SIZE, IMAGES, REPEATS,
# ORDER, LIMIT (seconds per 512^3 step), BIG (0: no 2048^3 step) and BIG_LIMIT override the defaults.
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
    kit=${2:-.probe}; results=${3:-/tmp/octiso-probe-results}; tarball=${TARBALL:-}
    threads=${THREADS:-1,2,4,8,12,16}; size=${SIZE:-512}; images=${IMAGES:-512,1024}; repeats=${REPEATS:-3}
    cores=$(nproc); big=${BIG:-2048}
    mkdir -p "$results"
    export LD_LIBRARY_PATH=$kit/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
    { nproc; lscpu || grep -m1 'model name' /proc/cpuinfo; free -g; } > "$results/machine.txt" 2>&1 || true
    cat "$results/machine.txt"
    # Each step runs under its own time limit, and the results so far are packed after each one
    # (TARBALL), so a step that overruns still leaves the earlier ones behind.
    step() {   # step NAME LIMIT_S ARGS...: one probe run, its tables in NAME.txt, its JSON in NAME/
      local name=$1 limit=$2; shift 2
      timeout "$limit" "$kit/octiso-probe" scaling "$@" --results "$results/$name" 2>&1 | tee "$results/$name.txt" || true
      if [[ -n $tarball ]]; then tar czf "$tarball" -C "$results" .; fi
    }
    for data in plume mixing; do
      step "${data}_$size" "${LIMIT:-150}" --dataset "$data" --size "$size" --images "$images" --threads "$threads" \
        --repeats "$repeats" --tile-order "${ORDER:-both}"
    done
    # Contrast: a field small enough to stay in the caches (128^3, a 2 MB octree), render only. If it
    # scales where 512^3 does not, the loss is memory, not clocks or scheduling.
    step plume_128_cached 60 --dataset plume --size 128 --images 1024 --threads "$threads" --repeats "$repeats" --no-build
    # The large case: build and render 2048^3 in memory on 1, 4 and all cores, where the
    # machine has the memory for it (8 GiB of voxels, a few GiB of octree and the build's pieces).
    if [[ $big != 0 ]] && (( $(awk '/MemTotal/ {print int($2 / 1048576)}' /proc/meminfo) >= 48 )); then
      step "plume_$big" "${BIG_LIMIT:-270}" --dataset plume --size "$big" --images 1024 --threads "$( ((cores > 4)) && echo "1,4,$cores" || echo "1,$cores")" --repeats 1 \
        --tile-order split
    fi
    ;;
  *)
    echo "usage: scripts/manycore_probe.sh pack [BUILD_DIR] [KIT_DIR] | run [KIT_DIR] [RESULTS_DIR]" >&2
    exit 2
    ;;
esac
