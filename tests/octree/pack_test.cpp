// Format 6's 1-byte caps (CapAnchor, octree.h) packed alone, on random cap parents that a build
// meets rarely: caps whose bounds miss a voxel (the last data layer), children with no cells
// (empty bounds), every spread of values from one to 256. Each cap is read back through
// Octree::cap_at from a cap level that ends exactly at its read slack.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "octree/pack.h"

namespace octiso::test {
namespace {

template <typename T> void expect_random_parents_round_trip(uint32_t seed) {
    using K = ScalarKey<T>;
    std::mt19937 rng(seed);
    for (int iter = 0; iter < 20000; ++iter) {
        InteriorNode<T> node{};
        node.child_mask = uint8_t(rng() | 1u);
        Cap<T> caps[8];
        int n = 0;
        const int spread = 1 << (rng() % 9);   // 1 .. 256 values in a cap
        for (int c = 0; c < 8; ++c) {
            const int centre = int(rng() % 256);
            int lo = 255, hi = 0;
            uint8_t keys[8];
            for (int k = 0; k < 8; ++k) {
                keys[k] = uint8_t(std::clamp(centre + int(rng() % unsigned(spread)) - spread / 2, 0, 255));
                lo = std::min(lo, int(keys[k])), hi = std::max(hi, int(keys[k]));
            }
            int bl = std::max(0, lo - int(rng() % 3)), bh = std::min(255, hi + int(rng() % 3));
            switch (rng() % 8) {
                case 0: bl = std::min(255, lo + 1); break;   // misses the lowest voxel
                case 1: bh = std::max(0, hi - 1); break;     // misses the highest
                case 2: bl = 200, bh = 100; break;           // no cells: empty
                default: break;
            }
            node.bounds.min[c] = K::value(uint8_t(bl));
            node.bounds.max[c] = K::value(uint8_t(bh));
            if (node.is_scalar_leaf(c)) continue;
            for (int k = 0; k < 8; ++k) caps[n].voxel[k] = K::value(keys[k]);
            ++n;
        }
        std::vector<uint8_t> out(8 * sizeof(Cap<T>) + kCapReadSlack);
        const uint64_t bytes = detail::pack_caps(node, caps, n, out.data());
        ASSERT_EQ(bytes, node.children_span(true));
        ASSERT_GE(node.cap_width(), 1u);
        ASSERT_LE(node.cap_width(), 8u);
        std::vector<uint8_t> level(bytes + kCapReadSlack, 0);   // ends at the slack: ASan sees a read past it
        std::copy(out.begin(), out.begin() + std::ptrdiff_t(bytes), level.begin());
        OctreeArrays<T> arrays;
        arrays.caps = level.data();
        const Octree<T> tree(arrays);
        const bool upper = node.cap_anchor() == CapAnchor::upper;
        for (int c = 0, j = 0; c < 8; ++c) {
            if (node.is_scalar_leaf(c)) continue;
            const CapRef<T> ref = tree.cap_at(0, node, c);
            for (int k = 0; k < 8; ++k) {
                ASSERT_EQ(ref.voxel(k), caps[j].voxel[k]) << "parent " << iter << " cap " << j << " voxel " << k;
                // A child with cells keeps bounds that enclose its cap on the anchor's side (widened
                // there where they missed a voxel, which only culls less).
                if (!node.bounds.empty(c)) {
                    if (upper) EXPECT_LE(caps[j].voxel[k], node.bounds.max[c]);
                    else EXPECT_GE(caps[j].voxel[k], node.bounds.min[c]);
                }
            }
            ++j;
        }
    }
}

TEST(PackAnchoredCaps, RandomParentsComeBackExactlyWithBordersAndEmptyBounds) {
    expect_random_parents_round_trip<uint8_t>(1);
    expect_random_parents_round_trip<int8_t>(2);
}

}  // namespace
}  // namespace octiso::test
