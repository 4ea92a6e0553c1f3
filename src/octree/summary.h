// The bottom-up rules both octree builders share (build.cpp from a dense array, sparse_synthetic.cpp
// from an analytic field): what a finished subtree tells its parent (Summary), how 8 children fold
// into a scalar leaf or a stored InteriorNode, and how a depth dmax-2 node's 8 blocks of 2^3 become
// leaves or caps from its 5^3 voxel neighbourhood, loaded by the one clamped load both use
// (Knoll et al. 2006, Sec. 3.3, 4.1).
#pragma once

#include <algorithm>
#include <bit>
#include <limits>
#include <vector>

#include "octiso/octree.h"
#include "octree/pack.h"
#include "util/check.h"

namespace octiso::detail {

/// What a finished subtree tells its parent.
template <typename T> struct Summary {
    T scalar;              ///< the value of a leaf; otherwise the voxel at the subtree's lower corner
                           ///< (format 4: the level-of-detail lattice sample, octree.h)
    T cell_min, cell_max;  ///< range over the data cells with lower corner inside; empty: min > max
    T data_lo, data_hi;    ///< range of the data voxels inside (meaningless when is_padding)
    bool is_leaf;
    bool is_padding;       ///< no data voxel inside at all

    static Summary padding() {
        return {T{}, std::numeric_limits<T>::max(), std::numeric_limits<T>::lowest(), T{}, T{}, true, true};
    }
};

inline Coord child_origin(Coord o, int c, uint32_t half) {
    return {o.x + ((c & 4) ? half : 0), o.y + ((c & 2) ? half : 0), o.z + ((c & 1) ? half : 0)};
}

/// Folds the 8 child summaries of a node at depth d. Returns true with `out` = the merged scalar
/// leaf when all children are leaves whose data ranges `mergeable(lo, hi, rep)` accepts (never at
/// d == 0: the root is always stored). Otherwise fills `node` (bounds packed, pack.h; a cap
/// parent's caps are packed by pack_caps after; its children are placed when its level is
/// complete, child_groups.h) and `out` with the stored node's summary, and returns false.
template <typename T, class Mergeable>
bool fold_children(int d, const Summary<T>* ch, const Mergeable& mergeable, Summary<T>& out, InteriorNode<T>& node) {
    bool all_leaves = true, any_data = false;
    T lo = std::numeric_limits<T>::max(), hi = std::numeric_limits<T>::lowest();
    T cmin = std::numeric_limits<T>::max(), cmax = std::numeric_limits<T>::lowest();
    for (int c = 0; c < 8; ++c) {
        all_leaves &= ch[c].is_leaf;
        if (!ch[c].is_padding) {
            any_data = true;
            lo = std::min(lo, ch[c].data_lo);
            hi = std::max(hi, ch[c].data_hi);
        }
        if (ch[c].cell_min <= ch[c].cell_max) {
            cmin = std::min(cmin, ch[c].cell_min);
            cmax = std::max(cmax, ch[c].cell_max);
        }
    }
    if (d > 0 && all_leaves) {
        if (!any_data) {
            out = Summary<T>::padding();
            return true;
        }
        T rep;
        if (mergeable(lo, hi, rep)) {
            out = {rep, cmin, cmax, lo, hi, true, false};
            return true;
        }
    }
    node = InteriorNode<T>{};
    uint8_t mask = 0;
    T mn[8], mx[8];
    for (int c = 0; c < 8; ++c) {
        node.scalar[c] = ch[c].scalar;
        mn[c] = ch[c].cell_min;
        mx[c] = ch[c].cell_max;
        if (!ch[c].is_leaf) mask = uint8_t(mask | (1u << c));
    }
    node.child_mask = mask;
    node.bounds = pack_bounds(mn, mx);
    // The lower corner voxel lies in child 0, which holds data whenever the node does.
    out = {any_data ? ch[0].scalar : T{}, cmin, cmax, lo, hi, false, !any_data};
    return false;
}

/// A cap parent just stored: packs its `n` caps (its stored children in order, pack.h) into the
/// node and appends their records to `bytes`, the caller's cap level.
template <typename T> void append_caps(InteriorNode<T>& node, const Cap<T>* caps, int n, std::vector<uint8_t>& bytes) {
    uint8_t buf[8 * sizeof(Cap<T>) + kCapReadSlack];
    const uint64_t written = pack_caps(node, caps, n, buf);
    bytes.insert(bytes.end(), buf, buf + written);
}

/// The 5^3 voxel neighbourhood L[z][y][x] = voxel(o + (x, y, z)) of a node at depth dmax-2 with
/// origin o (inside the data), coordinates clamped into the data: clamped slots replicate the
/// border. They fill padding slots of caps and never enter a range, because the extents of
/// cap_parent_children stop at the data. `voxel(x, y, z) -> T` reads one data voxel.
template <typename T, class Voxel> void load_neighbourhood(Coord o, Dims dims, const Voxel& voxel, T (&L)[5][5][5]) {
    OCTISO_DCHECK(o.x < dims.x && o.y < dims.y && o.z < dims.z, "cap parent (", o.x, ",", o.y, ",", o.z, ") outside the data");
    uint32_t xs[5], ys[5], zs[5];
    for (uint32_t i = 0; i < 5; ++i) {
        xs[i] = std::min(o.x + i, dims.x - 1);
        ys[i] = std::min(o.y + i, dims.y - 1);
        zs[i] = std::min(o.z + i, dims.z - 1);
    }
    for (int z = 0; z < 5; ++z)
        for (int y = 0; y < 5; ++y)
            for (int x = 0; x < 5; ++x) L[z][y][x] = voxel(xs[x], ys[y], zs[z]);
}

/// The 8 children of a node at depth dmax-2 with origin o, from its 5^3 voxel neighbourhood L[z][y][x]
/// (coordinates clamped into the data, so clamped slots replicate the border). Per block: the data
/// range over its data voxels, the cell range over the 3^3 box clipped to the data (then
/// `widen(lo, hi)`), a scalar leaf if `mergeable` accepts the data range, else a cap handed to
/// `emit_cap`. Padding never enters a range.
template <typename T, class Mergeable, class Widen, class EmitCap>
void cap_parent_children(const T (&L)[5][5][5], Coord o, Dims dims, const Mergeable& mergeable, const Widen& widen,
                         EmitCap&& emit_cap, Summary<T> (&ch)[8]) {
    for (int c = 0; c < 8; ++c) {
        const int bx = (c & 4) ? 2 : 0, by = (c & 2) ? 2 : 0, bz = (c & 1) ? 2 : 0;
        const Coord g{o.x + uint32_t(bx), o.y + uint32_t(by), o.z + uint32_t(bz)};
        if (g.x >= dims.x || g.y >= dims.y || g.z >= dims.z) {
            ch[c] = Summary<T>::padding();
            continue;
        }
        const int ex = int(std::min<uint32_t>(2, dims.x - g.x));
        const int ey = int(std::min<uint32_t>(2, dims.y - g.y));
        const int ez = int(std::min<uint32_t>(2, dims.z - g.z));
        T lo = L[bz][by][bx], hi = lo;
        for (int z = 0; z < ez; ++z)
            for (int y = 0; y < ey; ++y)
                for (int x = 0; x < ex; ++x) {
                    const T v = L[bz + z][by + y][bx + x];
                    lo = std::min(lo, v);
                    hi = std::max(hi, v);
                }
        T cmin = std::numeric_limits<T>::max(), cmax = std::numeric_limits<T>::lowest();
        if (dims.x - g.x >= 2 && dims.y - g.y >= 2 && dims.z - g.z >= 2) {
            const int cx = int(std::min<uint32_t>(3, dims.x - g.x));
            const int cy = int(std::min<uint32_t>(3, dims.y - g.y));
            const int cz = int(std::min<uint32_t>(3, dims.z - g.z));
            for (int z = 0; z < cz; ++z)
                for (int y = 0; y < cy; ++y)
                    for (int x = 0; x < cx; ++x) {
                        const T v = L[bz + z][by + y][bx + x];
                        cmin = std::min(cmin, v);
                        cmax = std::max(cmax, v);
                    }
            widen(cmin, cmax);
        }
        T rep;
        if (mergeable(lo, hi, rep)) {
            ch[c] = {rep, cmin, cmax, lo, hi, true, false};
            continue;
        }
        Cap<T> cap;
        for (int k = 0; k < 8; ++k) cap.voxel[k] = L[bz + (k & 1)][by + ((k >> 1) & 1)][bx + ((k >> 2) & 1)];
        emit_cap(cap);
        ch[c] = {cap.voxel[0], cmin, cmax, lo, hi, false, false};   // its corner; pack_caps stores the base
    }
}

}  // namespace octiso::detail
