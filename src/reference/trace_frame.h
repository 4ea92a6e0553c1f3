// One depth (+ normal) frame from any tracer with `TraceHit trace(const Ray&, bool want_normal)`,
// with the renderer's tile loop (TBB 16x16 tiles, simple partitioner, work stealing) but no
// Embree and no shading, so the acceleration structures of the grid benchmark are compared on
// equal terms. The caller's task_arena decides the thread count.
#pragma once

#include <atomic>
#include <chrono>
#include <cmath>

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "octiso/render.h"
#include "render/camera.h"
#include "render/traverse.h"

namespace octiso {

/// Frame with depth (world t, +inf on a miss) and, if `want_normal`, normals; stats filled.
template <class Tracer> Frame trace_frame(const Tracer& tracer, const Camera& camera, bool want_normal, int tile_size = 16) {
    const PinholeCamera pinhole(camera);
    const int W = camera.width, H = camera.height;
    Frame frame;
    frame.width = W;
    frame.height = H;
    frame.depth.assign(size_t(W) * H, INFINITY);
    if (want_normal) frame.normal.assign(size_t(W) * H * 3, 0.0f);
    std::atomic<uint64_t> hits{0};
    const auto t0 = std::chrono::steady_clock::now();
    tbb::parallel_for(
        tbb::blocked_range2d<int>(0, H, tile_size, 0, W, tile_size),
        [&](const tbb::blocked_range2d<int>& tile) {
            uint64_t tile_hits = 0;
            for (int py = tile.rows().begin(); py < tile.rows().end(); ++py)
                for (int px = tile.cols().begin(); px < tile.cols().end(); ++px) {
                    const TraceHit hit = tracer.trace(pinhole.ray(px, py), want_normal);
                    const size_t i = size_t(py) * W + px;
                    frame.depth[i] = float(hit.t);
                    if (want_normal && hit.is_hit())
                        for (int a = 0; a < 3; ++a) frame.normal[3 * i + a] = float(hit.normal[a]);
                    tile_hits += hit.is_hit();
                }
            hits += tile_hits;
        },
        tbb::simple_partitioner());
    frame.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    frame.stats.rays = uint64_t(W) * H;
    frame.stats.hits = hits;
    frame.stats.threads = tbb::this_task_arena::max_concurrency();
    return frame;
}

}  // namespace octiso
