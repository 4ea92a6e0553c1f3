// TileGrid: how a frame is cut into square tiles, the unit of parallel work (TBB) and of
// partial renders (a subset of tiles into a caller's buffer, for distributed rendering).
// Tiles are numbered row-major from the top-left; edge tiles are cut to the frame.
#pragma once

#include <algorithm>
#include <cstdint>

namespace octiso {

struct PixelRect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;   ///< pixels [x0, x1) x [y0, y1), row 0 at the top
};

/// How the tile loop hands tiles to threads (issue 12; both give the same pixels). split: TBB's
/// recursive halving of the tile range, so each thread works through its own stretch of the
/// image (the default, measured since issue 5). sweep: one shared counter in row-major order, so
/// all threads trace neighbouring tiles at the same time and share the octree nodes in the
/// caches they have in common. Which scales better on many cores is for the 16-core machine to
/// tell (octiso-bench scaling --tile-order both); on 2 threads sweep is 0.88-1.05 x split, alike
/// within noise (BENCHMARKS.md "Many-core").
enum class TileOrder { split, sweep };

struct TileGrid {
    int width = 0, height = 0, side = 16;

    int columns() const { return (width + side - 1) / side; }
    int rows() const { return (height + side - 1) / side; }
    int count() const { return columns() * rows(); }
    PixelRect rect(int tile) const {
        const int tx = tile % columns(), ty = tile / columns();
        return {tx * side, ty * side, std::min(width, (tx + 1) * side), std::min(height, (ty + 1) * side)};
    }
};

/// The tile side for a frame of width x height under `requested` (> 0: taken as given; 0: 16 when
/// the frame holds at least 4096 such tiles, else 8, so even 512^2 frames have enough tiles to
/// balance many cores; octiso-bench scaling, simulated 64-thread efficiency at 512^2: 82 % with
/// 16x16 tiles, 96 % with 8x8).
inline int tile_size_for(int width, int height, int requested) {
    if (requested > 0) return requested;
    return int64_t(width) * height / (16 * 16) >= 4096 ? 16 : 8;
}

inline TileGrid tile_grid_for(int width, int height, int requested) {
    return TileGrid{width, height, tile_size_for(width, height, requested)};
}

}  // namespace octiso
