// One depth (+ normal) frame from any tracer with `TraceHit trace(const Ray&, bool want_normal)`,
// through the renderer's own tile loop (render/tile_loop.h) but without Embree and shading, so
// the acceleration structures of the grid benchmark and the tests are compared on equal terms.
// The caller's task_arena decides the thread count.
#pragma once

#include <cmath>

#include "math/hit.h"
#include "octiso/camera.h"
#include "octiso/frame.h"
#include "octiso/tiles.h"
#include "render/pinhole_camera.h"
#include "render/tile_loop.h"
#include "util/huge_pages.h"

namespace octiso {

/// Frame with depth (world t, +inf on a miss) and, if `want_normal`, normals; stats filled.
template <class Tracer> Frame trace_frame(const Tracer& tracer, const Camera& camera, bool want_normal, int tile_size = 16) {
    const PinholeCamera pinhole(camera);
    const int W = camera.width, H = camera.height;
    Frame frame;
    frame.width = W;
    frame.height = H;
    assign_on_huge_pages(frame.depth, size_t(W) * H, float(INFINITY));   // as the Renderer's (util/huge_pages.h)
    if (want_normal) assign_on_huge_pages(frame.normal, size_t(W) * H * 3, 0.0f);
    frame.stats = for_each_tile(TileGrid{W, H, tile_size}, {}, true, [&](const PixelRect& rect, TileCounters& counters) {
        for (int py = rect.y0; py < rect.y1; ++py)
            for (int px = rect.x0; px < rect.x1; ++px) {
                const TraceHit hit = tracer.trace(pinhole.ray(px, py), want_normal);
                const size_t i = size_t(py) * W + px;
                frame.depth[i] = float(hit.t);
                if (want_normal && hit.is_hit())
                    for (int a = 0; a < 3; ++a) frame.normal[3 * i + a] = float(hit.normal[a]);
                counters.hits += hit.is_hit();
            }
        counters.rays += uint64_t(rect.x1 - rect.x0) * uint64_t(rect.y1 - rect.y0);
    });
    return frame;
}

}  // namespace octiso
