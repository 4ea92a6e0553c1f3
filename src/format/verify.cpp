// verify_octree(): walks each step's tree from the root with the cube of every node, and compares
// each child's stored range with a brute-force range over the decoded voxels of its cells (the
// child cube plus the one-voxel forward layer, clipped to the data). Cost: one dense step in
// memory and about dmax passes over it; meant for tests and audits, not for every load.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "octiso/decode.h"
#include "octiso/error.h"
#include "octiso/verify.h"

namespace octiso {

namespace {

template <typename T> struct Walker {
    const OctFile& file;
    const Octree<T>& tree;
    const std::vector<T>& dense;
    uint32_t step;
    VerifyStats& stats;
    const OctInfo& info;

    [[noreturn]] void lie(int d, uint64_t i, int c, const std::string& what) const {
        throw Error(file.path(), "step " + std::to_string(step) + ", depth " + std::to_string(d) + ", node " +
                                     std::to_string(i) + ", child " + std::to_string(c) + ": " + what +
                                     " (the derived metadata does not match the leaves)");
    }

    T at(uint64_t x, uint64_t y, uint64_t z) const { return dense[x + info.dims.x * (y + uint64_t(info.dims.y) * z)]; }

    /// Range of the values of the cells whose lower corner lies in [lo, lo + side)^3 (their 8
    /// corners reach one voxel further: the forward layer); cells with a non-finite corner are
    /// skipped as the tracer skips them. False if no such cell exists.
    bool cell_range(const uint64_t lo[3], uint64_t side, double& vmin, double& vmax) const {
        const uint64_t n[3] = {info.dims.x, info.dims.y, info.dims.z};
        uint64_t last[3];   // inclusive upper cell corner
        for (int a = 0; a < 3; ++a) {
            if (n[a] < 2 || lo[a] > n[a] - 2) return false;
            last[a] = std::min(lo[a] + side - 1, n[a] - 2);
        }
        bool any = false;
        vmin = INFINITY, vmax = -INFINITY;
        for (uint64_t z = lo[2]; z <= last[2]; ++z)
            for (uint64_t y = lo[1]; y <= last[1]; ++y)
                for (uint64_t x = lo[0]; x <= last[0]; ++x) {
                    double v[8];
                    bool finite = true;
                    for (int k = 0; k < 8; ++k) {
                        v[k] = double(at(x + (k & 1), y + ((k >> 1) & 1), z + ((k >> 2) & 1)));
                        finite &= std::isfinite(v[k]);
                    }
                    if (!finite) continue;
                    for (double q : v) vmin = std::min(vmin, q), vmax = std::max(vmax, q);
                    any = true;
                }
        return any;
    }

    void walk(int d, uint64_t i, const uint64_t origin[3]) {
        const InteriorNode<T>& node = tree.node(d, i);
        ++stats.nodes;
        const uint64_t side = tree.child_bit(d);
        for (int c = 0; c < 8; ++c) {
            const uint64_t lo[3] = {origin[0] + ((c & 4) ? side : 0), origin[1] + ((c & 2) ? side : 0),
                                    origin[2] + ((c & 1) ? side : 0)};
            double vmin, vmax;
            const bool has_cells = cell_range(lo, side, vmin, vmax);
            ++stats.ranges;
            if (has_cells) {
                bool check = true;
                if (info.iso_range) {   // only what an allowed isovalue could hit must be covered
                    const double a = (*info.iso_range)[0], b = (*info.iso_range)[1];
                    if (vmax < a || vmin > b) check = false;
                    vmin = std::max(vmin, a), vmax = std::min(vmax, b);
                }
                const double smin = node.bounds.empty(c) ? INFINITY : node.bounds.lower(c);
                const double smax = node.bounds.empty(c) ? -INFINITY : node.bounds.upper(c);
                const double tol = info.tolerance;   // lossy files: leaves are within tol of the data
                if (check && !(smin - tol <= vmin && vmax <= smax + tol))
                    lie(d, i, c, "stored range [" + std::to_string(smin) + ", " + std::to_string(smax) +
                                     "] does not contain the values of its cells [" + std::to_string(vmin) + ", " +
                                     std::to_string(vmax) + "]");
            }
            if (node.is_scalar_leaf(c) || d + 1 == tree.cap_depth()) continue;   // a cap's scalar is its base
            // An interior child's scalar is the voxel at its lower corner (format 4, the level-of-
            // detail sample), bit for bit; a child with no data voxel keeps any value.
            if (lo[0] < info.dims.x && lo[1] < info.dims.y && lo[2] < info.dims.z) {
                const T want = at(lo[0], lo[1], lo[2]);
                if (ScalarKey<T>::of(node.scalar[c]) != ScalarKey<T>::of(want))
                    lie(d, i, c, "scalar " + std::to_string(double(node.scalar[c])) + " is not the voxel at its corner (" +
                                     std::to_string(double(want)) + ")");
            }
            walk(d + 1, tree.child_index(d, i, node, c), lo);
        }
    }
};

}  // namespace

VerifyStats verify_octree(const OctFile& file) {
    const OctInfo& info = file.info();
    VerifyStats stats;
    dispatch_scalar_type(info.type, [&](auto tag) {
        using T = decltype(tag);
        std::vector<T> dense;
        try {
            dense.resize(size_t(info.dims.voxels()));
        } catch (const std::bad_alloc&) {
            throw Error(file.path(), "out of memory: --verify needs one step as a dense array (" +
                                         std::to_string(info.dims.voxels() * sizeof(T)) + " bytes)");
        }
        for (uint32_t k = 0; k < info.step_count; ++k) {
            const Octree<T> tree = file.step<T>(k);
            decode_to_dense(tree, dense.data());
            Walker<T> w{file, tree, dense, k, stats, info};
            const uint64_t origin[3] = {0, 0, 0};
            w.walk(0, 0, origin);
        }
    });
    return stats;
}

}  // namespace octiso
