// Octree<T>: the read-only view of a lossless octree volume (Knoll et al. 2006, Sec. 4.1, App. A),
// over memory owned elsewhere (an OctreeData built in memory, or an mmap'd .oct file). It owns the
// node layout and the octree hashing of App. B: point location and neighbour finding with a
// parent trace. Building lives in build.h, files in oct_file.h.
//
// Index space: voxel (x,y,z) of the data, 0 <= x < dims.x (likewise y, z); the tree spans the
// power-of-two cube [0, N)^3, N = 2^dmax >= max(dims), N >= 4. Depth d runs from 0 (root) to
// dmax-1 (caps). A node at depth d covers a cube of side 2^(dmax-d); its children have side
// child_bit(d) = 2^(dmax-d-1). Child octant c = x<<2 | y<<1 | z, where x = 1 for the upper half.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <limits>

#include "octiso/inline.h"
#include "octiso/volume.h"

namespace octiso {

inline constexpr int kMaxDepth = 31;   ///< dmax <= 30 because extents are <= 2^30; one spare

/// InteriorNode<T>: a node at depth d, 0 <= d <= dmax-2. For each child octant c:
///   child_mask bit c clear: child c is a scalar leaf; every voxel of it equals scalar[c]
///                           (padding beyond the data excepted: it is "don't care").
///   child_mask bit c set:   child c is stored at depth d+1 (an InteriorNode, or a Cap when
///                           d+1 == dmax-1) at index child_start + popcount(child_mask & ((1<<c)-1));
///                           scalar[c] is then the midpoint of the child's data range.
///   [min[c], max[c]] bounds the trilinear interpolant on every data cell whose lower corner lies
///   in child c (so the one-voxel forward layer +x,+y,+z counts). With no such cell (pure padding
///   or the last data layer) the range is empty: min[c] > max[c], and traversal skips the child.
/// The loader validates child_start + popcount(child_mask) <= count at depth d+1 for every node.
template <typename T> struct InteriorNode {
    T scalar[8];
    T min[8];
    T max[8];
    uint32_t child_start;
    uint8_t child_mask;
    uint8_t reserved[3];

    OCTISO_ALWAYS_INLINE bool is_scalar_leaf(int c) const { return ((child_mask >> c) & 1u) == 0; }
    OCTISO_ALWAYS_INLINE uint32_t child_index(int c) const {
        return child_start + uint32_t(std::popcount(unsigned(child_mask) & ((1u << c) - 1u)));
    }
    OCTISO_ALWAYS_INLINE bool may_contain(int c, double iso) const { return double(min[c]) <= iso && iso <= double(max[c]); }
    OCTISO_ALWAYS_INLINE bool may_contain_any(int c, const double* isos, int count) const {
        for (int i = 0; i < count; ++i)
            if (may_contain(c, isos[i])) return true;
        return false;
    }
};

/// Cap<T>: the 2x2x2 voxels of a node at depth dmax-1, octant order as above.
template <typename T> struct Cap {
    T voxel[8];
};

/// Integer point in index space.
struct Coord {
    uint32_t x = 0, y = 0, z = 0;
    bool operator==(const Coord&) const = default;
};

/// Octant of `p` inside a node whose children have side `child_bit` (a power of two).
OCTISO_ALWAYS_INLINE int octant_of(Coord p, uint32_t child_bit) {
    return ((p.x & child_bit) ? 4 : 0) | ((p.y & child_bit) ? 2 : 0) | ((p.z & child_bit) ? 1 : 0);
}

/// Where point location ended: the value, the depth of the node that holds it, and whether it is
/// a cap voxel (side 1) or a scalar leaf child of an interior node (side child_bit(depth)).
template <typename T> struct LeafRef {
    T value;
    int depth;          ///< depth of the holding node (cap: dmax-1)
    uint32_t index;     ///< index of the holding node at that depth
    bool in_cap;
};

/// Per-depth arrays of one octree; the view's raw material. Pointers stay owned by the creator.
template <typename T> struct OctreeArrays {
    Dims dims;
    int dmax = 0;
    std::array<const InteriorNode<T>*, kMaxDepth> nodes{};   ///< depth 0 .. dmax-2
    std::array<uint64_t, kMaxDepth> node_count{};
    const Cap<T>* caps = nullptr;                            ///< depth dmax-1
    uint64_t cap_count = 0;
};

template <typename T> class Octree {
public:
    Octree() = default;
    explicit Octree(const OctreeArrays<T>& arrays) : a_(arrays) {}

    Dims dims() const { return a_.dims; }
    int dmax() const { return a_.dmax; }
    int cap_depth() const { return a_.dmax - 1; }
    uint32_t side() const { return 1u << a_.dmax; }
    /// Side of a child of a node at depth d: 2^(dmax-d-1) (App. A's child_bit_depth[d]).
    uint32_t child_bit(int d) const { return 1u << (a_.dmax - d - 1); }
    uint64_t node_count(int d) const { return a_.node_count[size_t(d)]; }
    uint64_t cap_count() const { return a_.cap_count; }
    const InteriorNode<T>& node(int d, uint64_t i) const { return a_.nodes[size_t(d)][i]; }
    const Cap<T>& cap(uint64_t i) const { return a_.caps[i]; }
    const OctreeArrays<T>& arrays() const { return a_; }

    /// Value of voxel p, starting the descent at node `index` of depth `depth` (a cap when depth
    /// == dmax-1). Precondition: p lies inside that node's cube. Knoll 2006 App. B.1, with the
    /// child octant built by bitwise or (the paper's `||` is a slip).
    OCTISO_ALWAYS_INLINE LeafRef<T> locate_from(Coord p, int depth, uint32_t index) const {
        const int caps_at = a_.dmax - 1;
        for (;;) {
            if (depth == caps_at) return {a_.caps[index].voxel[octant_of(p, 1u)], depth, index, true};
            const InteriorNode<T>& n = a_.nodes[size_t(depth)][index];
            const int c = octant_of(p, child_bit(depth));
            if (n.is_scalar_leaf(c)) return {n.scalar[c], depth, index, false};
            index = n.child_index(c);
            ++depth;
        }
    }
    LeafRef<T> locate(Coord p) const { return locate_from(p, 0, 0); }
    T point_locate(Coord p) const { return locate_from(p, 0, 0).value; }

    /// Value at `dest`, given the trace of node indices from the root down to the node that holds
    /// `start`: parent_trace[d] is the node at depth d containing `start`, for d = 0 .. depth.
    /// Climbs to the deepest traced node whose cube also contains `dest`, then locates down
    /// (Knoll 2006 App. B.2; the paper's trailing root check is folded into the loop at d = 0).
    OCTISO_ALWAYS_INLINE T neighbour_find(Coord start, Coord dest, int depth, const uint32_t* parent_trace) const {
        return neighbour_locate(start, dest, depth, parent_trace).value;
    }
    /// The same, returning where the descent ended (the traversal then reads a whole forward
    /// neighbour block directly).
    OCTISO_ALWAYS_INLINE LeafRef<T> neighbour_locate(Coord start, Coord dest, int depth, const uint32_t* parent_trace) const {
        for (int d = depth; d > 0; --d) {
            const int shift = a_.dmax - d;   // cube side of a depth-d node is 2^shift
            if (((start.x ^ dest.x) >> shift) == 0 && ((start.y ^ dest.y) >> shift) == 0 &&
                ((start.z ^ dest.z) >> shift) == 0)
                return locate_from(dest, d, parent_trace[d]);
        }
        return locate_from(dest, 0, 0);
    }

private:
    OctreeArrays<T> a_;
};

/// dmax for a grid: log2 of the smallest power of two >= the largest extent, at least 2 so that
/// the root is always an interior node and caps sit below it.
inline int dmax_for(Dims dims) {
    const uint32_t n = std::bit_ceil(dims.max_extent());
    const int d = std::countr_zero(n);
    return d < 2 ? 2 : d;
}

}  // namespace octiso
