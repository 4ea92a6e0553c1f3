// TraceHit: what tracing one ray returns, shared by the octree traversal, the reference tracers,
// the Embree scene and the frame loop.
#pragma once

#include <array>
#include <limits>

namespace octiso {

struct TraceHit {
    double t = std::numeric_limits<double>::infinity();   ///< world distance; +inf: miss
    std::array<double, 3> normal{0, 0, 0};                 ///< world unit normal facing the ray
    int iso_index = -1;                                    ///< which isovalue; -1: miss
    /// log2 of the side, in voxels, of the cell the hit lies in: 0 at full resolution, more where
    /// level of detail stopped the descent above the voxels (RenderOptions::lod).
    int cell_log2 = 0;
    bool is_hit() const { return iso_index >= 0; }
};

}  // namespace octiso
