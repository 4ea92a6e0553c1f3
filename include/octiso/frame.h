// Frame: one rendered image (8-bit sRGB colour and the depth and normal AOVs of CONVENTIONS 2)
// and what rendering it cost. Row 0 is the top row; pixel (x, y) is element y * width + x.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace octiso {

struct RenderStats {
    double seconds = 0;                 ///< wall time of the tile loop
    /// Thread seconds spent inside tiles, summed over the tiles (issue 12). busy_seconds /
    /// (threads x seconds) is the loop's utilisation: what it lacks is waiting (start-up, the
    /// last tiles, stealing); a busy time that grows with the thread count at the same rays is
    /// each ray costing more (shared caches, memory bandwidth), not scheduling.
    double busy_seconds = 0;
    uint64_t rays = 0, hits = 0;
    int threads = 0;
    /// Hits by the side of the cell they lie in: hits_by_cell_log2[k] counts cells of 2^k voxels
    /// (k = 0: full resolution; more only with level of detail, RenderOptions::lod).
    std::array<uint64_t, 32> hits_by_cell_log2{};
    double mrays_per_second() const { return seconds > 0 ? double(rays) / seconds * 1e-6 : 0; }
};

/// Empty vectors for outputs not asked for.
struct Frame {
    int width = 0, height = 0;
    std::vector<uint8_t> rgb;           ///< 8-bit sRGB, 3 per pixel
    std::vector<float> depth;           ///< world distance t, +inf on a miss
    std::vector<float> normal;          ///< world unit normal facing the ray, 0,0,0 on a miss
    RenderStats stats;
};

}  // namespace octiso
