// build_sparse_octree: the top-down twin of build.cpp for an analytic sparse field. It follows
// the builder's rules exactly (DFS post-order appends, leaf merging with tolerance 0, cap parents
// from their 5^3 clamped neighbourhood, corner-voxel scalars, padding summaries), so the arrays are
// the ones build_octree would produce from the dense grid. The one addition: a node whose own
// voxels miss every blob support is uniform, so it is a leaf without descending; its cell range
// is the background plus the blob values on its forward layer, enumerated from the supports.
#include "octree/sparse_synthetic.h"
#include "octree/child_groups.h"
#include "octree/summary.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "octiso/error.h"
#include "util/check.h"

namespace octiso {

template <typename T> T SparseSpheres::value(uint32_t x, uint32_t y, uint32_t z) const {
    double v = background;
    for (const SparseBlob& b : blobs) {
        const double dx = double(x) - b.centre[0], dy = double(y) - b.centre[1], dz = double(z) - b.centre[2];
        const double d2 = dx * dx + dy * dy + dz * dz, r2 = b.radius * b.radius;
        if (d2 < r2) {
            v = background + b.peak * (1 - d2 / r2);
            break;
        }
    }
    if constexpr (std::is_floating_point_v<T>) {
        return T(v);
    } else {
        v = std::round(v);
        v = std::clamp(v, double(std::numeric_limits<T>::lowest()), double(std::numeric_limits<T>::max()));
        return T(v);
    }
}

std::array<std::array<int64_t, 3>, 2> SparseSpheres::support(size_t i) const {
    const SparseBlob& b = blobs[i];
    const uint32_t n[3] = {dims.x, dims.y, dims.z};
    std::array<std::array<int64_t, 3>, 2> box;
    for (int a = 0; a < 3; ++a) {
        // One voxel of slack on each side: a superset of {d2 < r2} is all correctness needs.
        box[0][a] = std::max<int64_t>(0, int64_t(std::floor(b.centre[a] - b.radius)) - 1);
        box[1][a] = std::min<int64_t>(int64_t(n[a]) - 1, int64_t(std::ceil(b.centre[a] + b.radius)) + 1);
    }
    return box;
}

SparseSpheres sparse_spheres_layout(uint32_t n) {
    const double N = double(n);
    SparseSpheres f;
    f.dims = {n, n, n};
    f.background = 0;
    f.blobs = {
        {{9.3, 11.7, 8.4}, 6.5, 100},                                  // near the origin
        {{N - 7.6, N - 8.2, N - 6.9}, 5.3, 100},                       // far corner: cells ~N-13 .. N-2
        {{N - 2.4, N / 2 + 0.37, N - 3.1}, 7.7, 100},                  // cut by the far x and z faces
        {{N / 2 + 0.41, N / 3 + 0.13, 2 * N / 3 + 0.77}, 11.3, 100},   // straddles the x mid-plane
        {{N / 4 + 0.5, 3 * N / 4 + 0.25, N / 8 + 0.125}, 4.2, 100},
    };
    return f;
}

uint32_t parse_sparse_spheres(std::string_view text, const std::string& flag) {
    constexpr std::string_view kName = "sparse-spheres";
    if (text.substr(0, kName.size()) != kName) return 0;
    if (text.size() == kName.size() || text[kName.size()] != ':')
        throw Error(flag, "expected sparse-spheres:N, found '" + std::string(text) + "'");
    const std::string n_text(text.substr(kName.size() + 1));
    char* end = nullptr;
    const unsigned long long n = std::strtoull(n_text.c_str(), &end, 10);
    if (n_text.empty() || *end != '\0' || n_text[0] == '-' || n < 64 || n > Dims::kMaxExtent)
        throw Error(flag, "sparse-spheres:N needs an integer N in [64, " + std::to_string(Dims::kMaxExtent) +
                              "], found '" + n_text + "'");
    return uint32_t(n);
}

namespace {

/// What a finished subtree tells its parent (the same fields as build.cpp's Summary).
using detail::Summary;

template <typename T> class SparseBuilder {
public:
    explicit SparseBuilder(const SparseSpheres& f) : f_(f), dims_(f.dims), dmax_(dmax_for(f.dims)) {
        for (size_t i = 0; i < f.blobs.size(); ++i) supports_.push_back(f.support(i));
        nodes_.resize(size_t(dmax_));
        leaves_.assign(size_t(dmax_), 0);
        background_ = convert(f.background);
    }

    OctreeData<T> run() {
        build(0, Coord{});
        OctreeData<T> out;
        out.dims = dims_;
        out.dmax = dmax_;
        out.nodes.resize(size_t(dmax_ - 1));
        out.group_bases.resize(size_t(dmax_ - 1));
        out.stats.nodes_per_depth.assign(size_t(dmax_), 0);
        out.stats.scalar_leaves_per_depth = leaves_;
        for (int d = 0; d <= dmax_ - 2; ++d) {
            const auto& v = nodes_[size_t(d)];
            const bool caps_below = d + 1 == dmax_ - 1;
            const uint64_t next = caps_below ? caps_.size() : nodes_[size_t(d + 1)].size();
            if (next > (caps_below ? kMaxCapByteOffset : uint64_t(1) << 32))
                throw Error("sparse-spheres", caps_below ? "octree too large: more than 2^48 bytes of caps"
                                                         : "octree too large: more than 2^32 nodes at depth " + std::to_string(d + 1));
            out.nodes[size_t(d)] = UninitArray<InteriorNode<T>>::make(v.size());
            std::copy(v.begin(), v.end(), out.nodes[size_t(d)].data.get());
            out.group_bases[size_t(d)] = UninitArray<uint64_t>::make(node_groups(v.size()));
            // Every stored node's children must lie in the next depth's array (the loader would
            // refuse the file; an in-memory octree would be traversed out of bounds).
            const uint64_t children = detail::place_children(out.nodes[size_t(d)].data.get(), v.size(), caps_below,
                                                             out.group_bases[size_t(d)].data.get());
            OCTISO_CHECK(children == next, "depth ", d, ": children for ", children, " of ", next, " at depth ", d + 1);
            out.stats.nodes_per_depth[size_t(d)] = v.size();
            out.stats.interior_bytes += interior_level_bytes<T>(v.size());
            out.stats.minmax_bytes += v.size() * sizeof(ChildBounds<T>);
        }
        out.caps = UninitArray<uint8_t>::make(caps_.size() + kCapReadSlack);
        std::copy(caps_.begin(), caps_.end(), out.caps.data.get());
        std::fill_n(out.caps.data.get() + caps_.size(), kCapReadSlack, uint8_t(0));
        out.cap_count = cap_count_;
        out.cap_bytes = caps_.size();
        out.stats.nodes_per_depth[size_t(dmax_ - 1)] = cap_count_;
        out.stats.cap_bytes = caps_.size();
        return out;
    }

private:
    using Box = std::array<std::array<int64_t, 3>, 2>;

    static T convert(double v) {
        if constexpr (std::is_floating_point_v<T>) return T(v);
        else return T(std::clamp(std::round(v), double(std::numeric_limits<T>::lowest()), double(std::numeric_limits<T>::max())));
    }

    uint32_t child_bit(int d) const { return 1u << (dmax_ - d - 1); }
    bool outside(Coord o) const { return o.x >= dims_.x || o.y >= dims_.y || o.z >= dims_.z; }
    static Coord child_origin(Coord o, int c, uint32_t half) { return detail::child_origin(o, c, half); }
    static Summary<T> padding() { return Summary<T>::padding(); }
    /// Lossless: only identical values merge (build_octree with tolerance 0).
    static bool mergeable(T lo, T hi, T& rep) {
        rep = lo;
        return lo == hi;
    }

    /// The node's data voxels [o, o + side) clipped to the data.
    Box voxel_box(Coord o, uint64_t side) const {
        const uint64_t n[3] = {dims_.x, dims_.y, dims_.z}, lo[3] = {o.x, o.y, o.z};
        Box b;
        for (int a = 0; a < 3; ++a) b[0][a] = int64_t(lo[a]), b[1][a] = int64_t(std::min(lo[a] + side, n[a]) - 1);
        return b;
    }
    static bool overlap(const Box& a, const Box& b) {
        for (int i = 0; i < 3; ++i)
            if (a[1][i] < b[0][i] || b[1][i] < a[0][i] || a[0][i] > a[1][i] || b[0][i] > b[1][i]) return false;
        return true;
    }
    bool touches_blob(const Box& b) const {
        for (const Box& s : supports_)
            if (overlap(b, s)) return true;
        return false;
    }

    /// A node (depth > 0) whose data voxels are all background: a leaf. Its cell range covers the
    /// voxels [o, min(o + side, dims - 1)] (its cells plus the forward layer) when it has a cell.
    Summary<T> uniform_leaf(Coord o, uint64_t side) const {
        Summary<T> s{background_, std::numeric_limits<T>::max(), std::numeric_limits<T>::lowest(),
                     background_, background_, true, false};
        const uint32_t n[3] = {dims_.x, dims_.y, dims_.z}, lo[3] = {o.x, o.y, o.z};
        Box e;
        for (int a = 0; a < 3; ++a) {
            if (n[a] < 2 || lo[a] > n[a] - 2) return s;   // no data cell: empty range
            e[0][a] = lo[a];
            e[1][a] = int64_t(std::min<uint64_t>(uint64_t(lo[a]) + side, n[a] - 1));
        }
        s.cell_min = s.cell_max = background_;   // the node's own voxels are background
        for (const Box& sup : supports_) {
            if (!overlap(e, sup)) continue;
            for (int64_t z = std::max(e[0][2], sup[0][2]); z <= std::min(e[1][2], sup[1][2]); ++z)
                for (int64_t y = std::max(e[0][1], sup[0][1]); y <= std::min(e[1][1], sup[1][1]); ++y)
                    for (int64_t x = std::max(e[0][0], sup[0][0]); x <= std::min(e[1][0], sup[1][0]); ++x) {
                        const T v = f_.value<T>(uint32_t(x), uint32_t(y), uint32_t(z));
                        s.cell_min = std::min(s.cell_min, v);
                        s.cell_max = std::max(s.cell_max, v);
                    }
        }
        return s;
    }

    Summary<T> build(int d, Coord o) {
        if (outside(o)) return padding();
        const uint64_t side = uint64_t(1) << (dmax_ - d);
        if (d > 0 && !touches_blob(voxel_box(o, side))) return uniform_leaf(o, side);
        if (d == dmax_ - 2) return build_cap_parent(o);
        Summary<T> ch[8];
        for (int c = 0; c < 8; ++c) ch[c] = build(d + 1, child_origin(o, c, child_bit(d)));
        return combine(d, ch);
    }

    // The same rules as build_octree with tolerance 0 (summary.h); the tests compare the arrays
    // node for node.
    Summary<T> combine(int d, const Summary<T>* ch, const Cap<T>* caps = nullptr, int n_caps = 0) {
        Summary<T> out;
        InteriorNode<T> n;
        if (detail::fold_children(d, ch, &SparseBuilder::mergeable, out, n)) return out;
        if (n_caps) {
            detail::append_caps(n, caps, n_caps, caps_);
            cap_count_ += uint64_t(n_caps);
        }
        nodes_[size_t(d)].push_back(n);
        leaves_[size_t(d)] += uint64_t(8 - std::popcount(unsigned(n.child_mask)));
        return out;
    }

    Summary<T> build_cap_parent(Coord o) {
        T L[5][5][5];
        detail::load_neighbourhood(o, dims_, [this](uint32_t x, uint32_t y, uint32_t z) { return f_.value<T>(x, y, z); }, L);
        Summary<T> ch[8];
        Cap<T> caps[8];
        int n_caps = 0;
        detail::cap_parent_children(
            L, o, dims_, &SparseBuilder::mergeable, [](T&, T&) {}, [&](const Cap<T>& cap) { caps[n_caps++] = cap; }, ch);
        return combine(dmax_ - 2, ch, caps, n_caps);
    }

    const SparseSpheres& f_;
    const Dims dims_;
    const int dmax_;
    T background_{};
    std::vector<Box> supports_;
    std::vector<std::vector<InteriorNode<T>>> nodes_;   // by depth, DFS post-order
    std::vector<uint8_t> caps_;   // packed cap records
    uint64_t cap_count_ = 0;
    std::vector<uint64_t> leaves_;
};

}  // namespace

template <typename T> OctreeData<T> build_sparse_octree(const SparseSpheres& field) {
    const Dims d = field.dims;
    if (d.x == 0 || d.y == 0 || d.z == 0 || d.max_extent() > Dims::kMaxExtent)
        throw Error("sparse-spheres", "dims out of range (expected 1 .. " + std::to_string(Dims::kMaxExtent) + ")");
    bool finite = std::isfinite(field.background);
    for (const SparseBlob& b : field.blobs)
        finite &= std::isfinite(b.peak) && std::isfinite(b.radius) && b.radius > 0 && std::isfinite(b.centre[0]) &&
                  std::isfinite(b.centre[1]) && std::isfinite(b.centre[2]);
    if (!finite) throw Error("sparse-spheres", "background, centres, radii and peaks must be finite, radii > 0");
    return SparseBuilder<T>(field).run();
}

#define OCTISO_INSTANTIATE(T)                                                        \
    template T SparseSpheres::value<T>(uint32_t, uint32_t, uint32_t) const;          \
    template OctreeData<T> build_sparse_octree<T>(const SparseSpheres&);
OCTISO_INSTANTIATE(uint8_t)
OCTISO_INSTANTIATE(int8_t)
OCTISO_INSTANTIATE(uint16_t)
OCTISO_INSTANTIATE(int16_t)
OCTISO_INSTANTIATE(uint32_t)
OCTISO_INSTANTIATE(int32_t)
OCTISO_INSTANTIATE(float)
OCTISO_INSTANTIATE(double)
#undef OCTISO_INSTANTIATE

}  // namespace octiso
