// slab_bricks (octiso/bricks.h).
#include "octiso/bricks.h"

#include <bit>
#include <cstdint>

#include "octiso/error.h"

namespace octiso {

std::vector<CellBox> slab_bricks(Dims dims, int count) {
    if (count < 1) throw Error("bricks", "need at least one brick, asked for " + std::to_string(count));
    const auto cells = [](uint32_t n) { return n >= 2 ? n - 1 : 0u; };
    const uint64_t nx = cells(dims.x);
    // Faces on multiples of `unit`: the largest power of two with >= 8 units per slab, so that
    // the nodes of that side and finer lie wholly in one slab (see the header).
    uint64_t unit = 1;
    while (unit * 2 * 8 * uint64_t(count) <= nx) unit *= 2;
    std::vector<CellBox> bricks(static_cast<size_t>(count));
    uint64_t lo = 0;
    for (int r = 0; r < count; ++r) {
        uint64_t hi = nx;
        if (r + 1 < count) {
            const uint64_t even = nx * uint64_t(r + 1) / uint64_t(count);
            hi = std::min(nx, std::max(lo, (even + unit / 2) / unit * unit));
        }
        bricks[size_t(r)] = CellBox{{uint32_t(lo), 0, 0}, {uint32_t(hi), cells(dims.y), cells(dims.z)}};
        lo = hi;
    }
    return bricks;
}

}  // namespace octiso
