// decode_to_dense and decode_layers (decode.h): walks the octree once, filling each scalar leaf's
// block (clipped to the data and to the layers asked for) with x-runs and each cap's 2x2x2
// voxels, instead of one point location per voxel. Subtrees below or above the layers are not
// entered. The top levels are expanded serially into disjoint subtrees, filled in parallel.
#include "octiso/decode.h"

#include <algorithm>
#include <vector>

#include <tbb/parallel_for.h>

namespace octiso {

namespace {

/// A piece of the cube: either a subtree rooted at node `index` of `depth`, or (depth < 0) a
/// uniform block of `value`. `corner` is its lower corner, `side` its edge length in voxels.
template <typename T> struct Piece {
    int depth;
    uint32_t index;
    T value;
    Coord corner;
    uint32_t side;
};

template <typename T> class Decoder {
public:
    /// Writes layers [z0, z1) (z1 <= dims.z) to out, layer z0 first.
    Decoder(const Octree<T>& o, T* out, uint32_t z0, uint32_t z1) : o_(o), out_(out), dims_(o.dims()), z0_(z0), z1_(z1) {}

    /// Whether the cube at c of edge `side` holds a voxel of the data inside the layers.
    bool wanted(Coord c, uint32_t side) const {
        return c.x < dims_.x && c.y < dims_.y && c.z < z1_ && uint64_t(c.z) + side > z0_;
    }

    void fill_block(Coord c, uint32_t side, T value) const {
        if (!wanted(c, side)) return;   // padding, or outside the layers
        const uint32_t x1 = std::min<uint64_t>(uint64_t(c.x) + side, dims_.x);
        const uint32_t y1 = std::min<uint64_t>(uint64_t(c.y) + side, dims_.y);
        const uint32_t z1 = std::min<uint64_t>(uint64_t(c.z) + side, z1_);
        for (uint32_t z = std::max(c.z, z0_); z < z1; ++z)
            for (uint32_t y = c.y; y < y1; ++y) std::fill(out_ + index(c.x, y, z), out_ + index(x1, y, z), value);
    }

    void fill_cap(Coord c, const CapRef<T>& cap) const {
        T v[8];
        cap.decode(v);
        for (int o = 0; o < 8; ++o) {
            const uint32_t x = c.x + uint32_t(o >> 2), y = c.y + uint32_t((o >> 1) & 1), z = c.z + uint32_t(o & 1);
            if (x < dims_.x && y < dims_.y && z >= z0_ && z < z1_) out_[index(x, y, z)] = v[o];
        }
    }

    /// Fills the subtree at node `index` of `depth` (<= dmax-2) whose cube starts at `c`.
    void fill_node(int depth, uint32_t index, Coord c) const {
        const uint32_t half = o_.child_bit(depth);
        if (!wanted(c, 2 * half)) return;
        const InteriorNode<T>& n = o_.node(depth, index);
        for (int ch = 0; ch < 8; ++ch) {
            const Coord cc = child_corner(c, ch, half);
            if (n.is_scalar_leaf(ch)) fill_block(cc, half, n.scalar[ch]);
            else if (depth + 1 == o_.cap_depth()) fill_cap(cc, o_.cap(index, n, ch));
            else fill_node(depth + 1, o_.child_index(depth, index, n, ch), cc);
        }
    }

    void fill(const Piece<T>& p) const {
        if (p.depth < 0) fill_block(p.corner, p.side, p.value);
        else fill_node(p.depth, p.index, p.corner);
    }

    static Coord child_corner(Coord c, int ch, uint32_t half) {
        return {c.x + ((ch & 4) ? half : 0), c.y + ((ch & 2) ? half : 0), c.z + ((ch & 1) ? half : 0)};
    }

private:
    uint64_t index(uint32_t x, uint32_t y, uint32_t z) const {
        return uint64_t(x) + uint64_t(dims_.x) * (uint64_t(y) + uint64_t(dims_.y) * (z - z0_));
    }
    const Octree<T>& o_;
    T* out_;
    Dims dims_;
    uint32_t z0_, z1_;
};

}  // namespace

template <typename T> void decode_to_dense(const Octree<T>& octree, T* out) {
    decode_layers(octree, 0, octree.dims().z, out);
}

template <typename T> void decode_layers(const Octree<T>& octree, uint32_t z0, uint32_t z1, T* out) {
    if (z0 >= z1) return;
    const Decoder<T> dec(octree, out, z0, z1);
    // Expand the top of the tree breadth-first until there are enough disjoint pieces to keep
    // every core busy (or the caps are reached); pieces outside the data are dropped.
    constexpr size_t kPieces = 512;
    std::vector<Piece<T>> pieces{{0, 0, T{}, Coord{}, octree.side()}};
    for (int d = 0; d + 1 < octree.cap_depth() && pieces.size() < kPieces; ++d) {   // pieces stop at the cap parents
        std::vector<Piece<T>> next;
        for (const Piece<T>& p : pieces) {
            if (p.depth != d) {
                next.push_back(p);
                continue;
            }
            const InteriorNode<T>& n = octree.node(d, p.index);
            const uint32_t half = octree.child_bit(d);
            for (int ch = 0; ch < 8; ++ch) {
                const Coord cc = Decoder<T>::child_corner(p.corner, ch, half);
                if (!dec.wanted(cc, half)) continue;
                if (n.is_scalar_leaf(ch)) next.push_back({-1, 0, n.scalar[ch], cc, half});
                else next.push_back({d + 1, octree.child_index(d, p.index, n, ch), T{}, cc, half});
            }
        }
        pieces.swap(next);
    }
    tbb::parallel_for(size_t(0), pieces.size(), [&](size_t i) { dec.fill(pieces[i]); });
}

#define OCTISO_INSTANTIATE(T)                                               \
    template void decode_to_dense<T>(const Octree<T>&, T*);                 \
    template void decode_layers<T>(const Octree<T>&, uint32_t, uint32_t, T*);
OCTISO_FOR_EACH_SCALAR_TYPE(OCTISO_INSTANTIATE)
#undef OCTISO_INSTANTIATE

}  // namespace octiso
