// The piece builder both dense builders share (build.cpp over a whole array, the streaming
// converter over slabs of layers, src/convert/stream_build.cpp): one subtree built depth-first
// into its own Sink, Knoll et al. 2006, Sec. 3.1, 3.3, 4.1. Voxels are read through a VolumeView
// whose first layer is global layer `z_first`, so a slab of layers serves as well as the whole grid;
// the grid's own dims decide padding and the clamped 5^3 neighbourhood either way.
#pragma once

#include <bit>
#include <cmath>
#include <limits>
#include <type_traits>
#include <vector>

#include "octiso/octree.h"
#include "octiso/volume.h"
#include "octree/summary.h"

namespace octiso::detail {

/// One piece's output: node records by absolute depth, packed caps (bytes) and their count, leaf
/// counts by depth.
template <typename T> struct Sink {
    std::vector<std::vector<InteriorNode<T>>> nodes;
    std::vector<uint8_t> caps;
    uint64_t cap_count = 0;
    std::vector<uint64_t> leaves;
    explicit Sink(int dmax) : nodes(size_t(dmax)), leaves(size_t(dmax), 0) {}
};

template <typename T> class Builder {
public:
    /// `v` holds layers [z_first, z_first + v.dims.z) of a grid of `dims`; a piece built from it
    /// may read only those layers (its cube plus the forward layer, clamped into the data).
    Builder(const VolumeView<T>& v, Dims dims, int dmax, double tolerance, uint32_t z_first = 0)
        : v_(v), dims_(dims), dmax_(dmax), tolerance_(tolerance), z_first_(z_first) {}

    uint32_t child_bit(int d) const { return 1u << (dmax_ - d - 1); }

    static Summary<T> padding() { return Summary<T>::padding(); }

    bool outside(Coord o) const { return o.x >= dims_.x || o.y >= dims_.y || o.z >= dims_.z; }

    static Coord child_origin(Coord o, int c, uint32_t half) { return ::octiso::detail::child_origin(o, c, half); }

    /// Whether values in [lo, hi] may become one value `rep` with |v - rep| <= tolerance for all.
    bool mergeable(T lo, T hi, T& rep) const {
        if (lo == hi) { rep = lo; return true; }
        if (tolerance_ <= 0) return false;
        const double a = double(lo), b = double(hi);
        if (b - a > 2 * tolerance_) return false;
        double m = a + (b - a) / 2;
        if constexpr (!std::is_floating_point_v<T>) m = std::round(m);
        const T r = T(m);
        if (double(r) - a > tolerance_ || b - double(r) > tolerance_) return false;
        rep = r;
        return true;
    }

    /// Widening of a cell range by the tolerance, so that it also bounds the stored (lossy) values.
    void widen(T& lo, T& hi) const {
        if (tolerance_ <= 0 || lo > hi) return;
        const double l = std::floor(double(lo) - tolerance_), h = std::ceil(double(hi) + tolerance_);
        lo = l <= double(std::numeric_limits<T>::lowest()) ? std::numeric_limits<T>::lowest() : T(l);
        hi = h >= double(std::numeric_limits<T>::max()) ? std::numeric_limits<T>::max() : T(h);
    }

    /// Subtree of the node at depth d (d <= dmax-2) with origin o, into `sink`.
    Summary<T> build(int d, Coord o, Sink<T>& sink) const {
        if (outside(o)) return padding();
        if (d == dmax_ - 2) return build_cap_parent(o, sink);
        Summary<T> ch[8];
        const uint32_t half = child_bit(d);
        for (int c = 0; c < 8; ++c) ch[c] = build(d + 1, child_origin(o, c, half), sink);
        return combine(d, ch, sink);
    }

    /// Folds 8 child summaries into a leaf, or stores an interior node at depth d.
    /// `caps` are a cap parent's `n_caps` caps in order.
    Summary<T> combine(int d, const Summary<T>* ch, Sink<T>& sink, const Cap<T>* caps = nullptr, int n_caps = 0) const {
        Summary<T> out;
        InteriorNode<T> n;
        auto merge = [this](T lo, T hi, T& rep) { return mergeable(lo, hi, rep); };
        if (fold_children(d, ch, merge, out, n)) return out;
        if (n_caps) {
            append_caps(n, caps, n_caps, sink.caps);
            sink.cap_count += uint64_t(n_caps);
        }
        sink.nodes[size_t(d)].push_back(n);
        sink.leaves[size_t(d)] += uint64_t(8 - std::popcount(unsigned(n.child_mask)));
        return out;
    }

    /// A node at depth dmax-2: 4^3 voxels in 8 blocks of 2^3, each a scalar leaf or a cap.
    Summary<T> build_cap_parent(Coord o, Sink<T>& sink) const {
        // 1. The 5^3 neighbourhood from o, clamped into the data (summary.h).
        T L[5][5][5];
        load_neighbourhood(o, dims_, [this](uint32_t x, uint32_t y, uint32_t z) { return v_.at(x, y, z - z_first_); }, L);

        // 2. Each block: a scalar leaf or a cap (summary.h).
        Summary<T> ch[8];
        Cap<T> caps[8];
        int n_caps = 0;
        cap_parent_children(
            L, o, dims_, [this](T lo, T hi, T& rep) { return mergeable(lo, hi, rep); },
            [this](T& lo, T& hi) { widen(lo, hi); }, [&](const Cap<T>& cap) { caps[n_caps++] = cap; }, ch);
        return combine(dmax_ - 2, ch, sink, caps, n_caps);
    }

    const VolumeView<T> v_;
    const Dims dims_;
    const int dmax_;
    const double tolerance_;
    const uint32_t z_first_;
};

}  // namespace octiso::detail
