// The one tile loop: every frame (the renderer's and the references') is cut into a TileGrid and
// its tiles are handed to TBB one by one (simple partitioner, work stealing). The caller's
// task_arena decides the thread count. Per tile, `body(rect, stats)` traces the pixels of `rect`
// into plain local counters, folded into the shared ones once per tile (no shared atomics per ray).
// Each tile's own wall time is summed too (two clock reads per tile, ~40 ns against the 0.1-1 ms a
// 16x16 tile takes), so the loop's utilisation is measured on every frame (issue 12).
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <span>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "octiso/frame.h"
#include "octiso/tiles.h"
#include "util/check.h"

namespace octiso {

struct TileCounters {
    uint64_t rays = 0, hits = 0;
    std::array<uint64_t, 32> hits_by_cell_log2{};   ///< RenderStats::hits_by_cell_log2
};

/// Runs body(const PixelRect&, TileCounters&) for the tiles `tiles` of `grid` (all tiles when
/// `all`), in parallel, handed out in `order`; returns the wall time and the summed counters.
template <class Body>
RenderStats for_each_tile(const TileGrid& grid, std::span<const int> tiles, bool all, Body&& body,
                          TileOrder order = TileOrder::split) {
    std::atomic<uint64_t> rays{0}, hits{0}, busy_ns{0};
    std::array<std::atomic<uint64_t>, 32> by_cell{};
    const int n = all ? grid.count() : int(tiles.size());
    const auto run_tile = [&](int i) {
        TileCounters local;
        const int tile = all ? i : tiles[size_t(i)];
        OCTISO_DCHECK(tile >= 0 && tile < grid.count(), "tile ", tile, " of ", grid.count());
        const auto started = std::chrono::steady_clock::now();
        body(grid.rect(tile), local);
        busy_ns += uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - started).count());
        rays += local.rays;
        hits += local.hits;
        for (size_t k = 0; k < by_cell.size(); ++k)
            if (local.hits_by_cell_log2[k]) by_cell[k] += local.hits_by_cell_log2[k];
    };
    const auto t0 = std::chrono::steady_clock::now();
    if (order == TileOrder::sweep) {
        // One task per thread of the arena, each taking the next tile of one shared counter until
        // none is left: whichever threads join do all the work, in row-major order.
        std::atomic<int> next{0};
        const int workers = std::max(1, std::min(n, tbb::this_task_arena::max_concurrency()));
        tbb::parallel_for(0, workers, [&](int) {
            for (int i = next++; i < n; i = next++) run_tile(i);
        }, tbb::static_partitioner());
    } else {
        tbb::parallel_for(
            tbb::blocked_range<int>(0, n, 1),
            [&](const tbb::blocked_range<int>& range) {
                for (int i = range.begin(); i < range.end(); ++i) run_tile(i);
            },
            tbb::simple_partitioner());
    }
    RenderStats stats;
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    stats.busy_seconds = double(busy_ns.load()) * 1e-9;
    stats.rays = rays;
    stats.hits = hits;
    for (size_t k = 0; k < by_cell.size(); ++k) stats.hits_by_cell_log2[k] = by_cell[k];
    stats.threads = tbb::this_task_arena::max_concurrency();
    return stats;
}

}  // namespace octiso
