// Value statistics of one octree step (octiso-info): the exact voxel min/max, exact percentiles
// and a histogram, computed from the tree itself. A scalar leaf stands for every data voxel of
// its cube (counted once, weighted by that count), so only the caps are read voxel by voxel:
// the cost is the stored size of the step, never the dense size. Padding voxels beyond the data
// are never counted.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "octiso/any_octree.h"

namespace octiso {

struct ValueStats {
    uint64_t voxels = 0;                ///< data voxels with a finite value
    uint64_t non_finite = 0;            ///< NaN or +-inf voxels (not in any of the figures below)
    std::array<double, 2> range{0, 0};  ///< exact [min, max] over the finite voxels (0, 0 if none)
    /// Nearest-rank percentiles: percentiles[i] is the smallest stored value v with at least
    /// ceil(percentile_levels[i] / 100 * voxels) finite voxels <= v (exact, not binned).
    static constexpr std::array<double, 7> percentile_levels{1, 5, 25, 50, 75, 95, 99};
    std::array<double, 7> percentiles{};
    /// counts[b]: finite voxels with bin_of(v) == b; bins of equal width over [range[0], range[1]],
    /// the last one closed.
    std::vector<uint64_t> counts;

    /// The bin of value v (precondition: range[0] <= v <= range[1]); the one rule the counts follow.
    int bin_of(double v) const;
    /// Lower edge of bin b (b == bins: the upper end of the range).
    double bin_edge(int b) const;
};

/// The statistics of `tree` with `bins` histogram bins (1 .. 4096). Reads every node and cap of
/// the step once per pass (three passes); no dense array. Thread-safe.
ValueStats value_stats(const AnyOctree& tree, int bins = 16);

}  // namespace octiso
