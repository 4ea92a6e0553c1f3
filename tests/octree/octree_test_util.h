// Test helpers for octree suites: seeded dense volumes of every scalar type, a walker that visits
// every stored node with its origin, and the exact cell range of a box computed from the array.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "octiso/octree.h"
#include "octiso/volume.h"

namespace octiso::test {

using AllScalarTypes = ::testing::Types<uint8_t, int8_t, uint16_t, int16_t, uint32_t, int32_t, float, double>;

/// An owned dense volume plus its view.
template <typename T> struct DenseVolume {
    Dims dims;
    std::vector<T> values;
    VolumeView<T> view() const { return {reinterpret_cast<const std::byte*>(values.data()), dims, false}; }
    T at(uint32_t x, uint32_t y, uint32_t z) const { return values[x + uint64_t(dims.x) * (y + uint64_t(dims.y) * z)]; }
};

enum class Pattern { Random, Constant, Sparse, Blocky };

/// Values chosen so that merges happen (Sparse, Blocky) and do not (Random).
template <typename T> DenseVolume<T> make_volume(Dims dims, Pattern pattern, uint32_t seed) {
    DenseVolume<T> v{dims, std::vector<T>(dims.voxels())};
    std::mt19937 rng(seed);
    const double span = std::is_floating_point_v<T> ? 1e6 : double(std::numeric_limits<T>::max()) - double(std::numeric_limits<T>::lowest());
    const double base = std::is_floating_point_v<T> ? -5e5 : double(std::numeric_limits<T>::lowest());
    auto pick = [&](uint32_t r) {
        double x = base + span * (double(r) / 4294967296.0);
        if constexpr (!std::is_floating_point_v<T>) x = std::floor(x);
        return T(x);
    };
    for (uint64_t i = 0; i < v.values.size(); ++i) {
        const uint32_t x = uint32_t(i % dims.x), y = uint32_t(i / dims.x % dims.y), z = uint32_t(i / (uint64_t(dims.x) * dims.y));
        switch (pattern) {
            case Pattern::Random: v.values[i] = pick(rng()); break;
            case Pattern::Constant: v.values[i] = T(7); break;
            case Pattern::Sparse: v.values[i] = (rng() % 97 == 0) ? pick(rng()) : T(3); break;
            case Pattern::Blocky: v.values[i] = T(((x / 4) ^ (y / 2) ^ (z / 8)) % 5); break;
        }
    }
    return v;
}

/// Labels 0, 10, 20, 30 in uniform blocks, as in an atlas: 8^3 blocks, a third of whose 4^3 blocks
/// take a label of their own, drawn from `seed`. Their trees hold scalar leaves of side 4 and 8
/// whose shell cells meet neighbours of every label.
template <typename T> DenseVolume<T> label_blocks(Dims dims, uint32_t seed) {
    DenseVolume<T> v{dims, std::vector<T>(dims.voxels())};
    std::mt19937 rng(seed);
    const uint32_t coarse_x = (dims.x + 7) / 8, coarse_y = (dims.y + 7) / 8, coarse_z = (dims.z + 7) / 8;
    const uint32_t fine_x = (dims.x + 3) / 4, fine_y = (dims.y + 3) / 4, fine_z = (dims.z + 3) / 4;
    std::vector<int> coarse(size_t(coarse_x) * coarse_y * coarse_z), fine(size_t(fine_x) * fine_y * fine_z);
    for (int& l : coarse) l = int(rng() % 4u);
    for (int& l : fine) l = rng() % 3u == 0 ? int(rng() % 4u) : -1;
    for (uint32_t z = 0; z < dims.z; ++z)
        for (uint32_t y = 0; y < dims.y; ++y)
            for (uint32_t x = 0; x < dims.x; ++x) {
                const int f = fine[(x >> 2) + fine_x * ((y >> 2) + fine_y * size_t(z >> 2))];
                const int label = f >= 0 ? f : coarse[(x >> 3) + coarse_x * ((y >> 3) + coarse_y * size_t(z >> 3))];
                v.values[x + size_t(dims.x) * (y + size_t(dims.y) * z)] = T(10 * label);
            }
    return v;
}

/// Labels 0, 10, 20, 30 in uniform blocks of every side from 32 down to 4, as in an atlas with
/// large regions: each 32^3 block, drawn from `seed`, is one label with probability 2/5, else its
/// eight halves are drawn the same way, down to 4^3 blocks that are always uniform. Their trees
/// hold scalar leaves of side 4 to 32 whose shell cells meet neighbours of every label and side.
template <typename T> DenseVolume<T> nested_label_blocks(Dims dims, uint32_t seed) {
    DenseVolume<T> v{dims, std::vector<T>(dims.voxels())};
    std::mt19937 rng(seed);
    const std::function<void(uint32_t, uint32_t, uint32_t, uint32_t)> fill = [&](uint32_t x0, uint32_t y0, uint32_t z0,
                                                                                  uint32_t side) {
        if (side > 4 && rng() % 5u >= 2u) {
            const uint32_t h = side / 2;
            for (int c = 0; c < 8; ++c) fill(x0 + ((c & 4) ? h : 0), y0 + ((c & 2) ? h : 0), z0 + ((c & 1) ? h : 0), h);
            return;
        }
        const T label = T(10 * (rng() % 4u));
        for (uint32_t z = z0; z < std::min(z0 + side, dims.z); ++z)
            for (uint32_t y = y0; y < std::min(y0 + side, dims.y); ++y)
                for (uint32_t x = x0; x < std::min(x0 + side, dims.x); ++x) v.values[v.view().index(x, y, z)] = label;
    };
    for (uint32_t z = 0; z < dims.z; z += 32)
        for (uint32_t y = 0; y < dims.y; y += 32)
            for (uint32_t x = 0; x < dims.x; x += 32) fill(x, y, z, 32);
    return v;
}

/// Calls visit(depth, node_index, origin) for every stored interior node, parents first.
template <typename T>
void for_each_node(const Octree<T>& tree, const std::function<void(int, uint32_t, Coord)>& visit) {
    std::function<void(int, uint32_t, Coord)> rec = [&](int d, uint32_t i, Coord o) {
        visit(d, i, o);
        if (d == tree.dmax() - 2) return;
        const InteriorNode<T>& n = tree.node(d, i);
        const uint32_t half = tree.child_bit(d);
        for (int c = 0; c < 8; ++c)
            if (!n.is_scalar_leaf(c))
                rec(d + 1, tree.child_index(d, i, n, c), Coord{o.x + ((c & 4) ? half : 0), o.y + ((c & 2) ? half : 0), o.z + ((c & 1) ? half : 0)});
    };
    rec(0, 0, Coord{});
}

/// Exact [min, max] of the corner values of every data cell whose lower corner lies in the box
/// [o, o+side)^3; returns false when there is no such cell.
template <typename T, typename Get>
bool exact_cell_range(Dims dims, Coord o, uint32_t side, Get&& get, double& lo, double& hi) {
    if (dims.x < 2 || dims.y < 2 || dims.z < 2) return false;
    const uint64_t ex = std::min<uint64_t>(uint64_t(o.x) + side, dims.x - 1);
    const uint64_t ey = std::min<uint64_t>(uint64_t(o.y) + side, dims.y - 1);
    const uint64_t ez = std::min<uint64_t>(uint64_t(o.z) + side, dims.z - 1);
    if (o.x >= ex || o.y >= ey || o.z >= ez) return false;
    lo = std::numeric_limits<double>::infinity();
    hi = -lo;
    for (uint64_t z = o.z; z <= ez; ++z)
        for (uint64_t y = o.y; y <= ey; ++y)
            for (uint64_t x = o.x; x <= ex; ++x) {
                const double v = double(get(uint32_t(x), uint32_t(y), uint32_t(z)));
                lo = std::min(lo, v);
                hi = std::max(hi, v);
            }
    return true;
}

}  // namespace octiso::test
