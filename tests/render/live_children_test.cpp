// LiveChildren<T> (src/render/live_children.h): the byte-compare cull of a node's 8 children is
// InteriorNode::may_contain_any for every child, bit for bit, on random and edge-case bounds
// (empty children, 0 and 255, -128 and 127) and isovalue sets (integers, halves, values outside
// the type's range, several at once), through of() and through the traversal's predicate holds();
// wider types cull through the per-child test.
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <vector>

#include "render/live_children.h"

namespace octiso::test {
namespace {

template <typename T> void expect_same_cull(uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> byte(std::numeric_limits<T>::lowest(), std::numeric_limits<T>::max());
    const double lowest = double(std::numeric_limits<T>::lowest()), top = double(std::numeric_limits<T>::max());
    std::vector<double> candidates = {lowest - 3.5, lowest - 0.5, lowest, lowest + 0.5, top - 0.5, top, top + 0.5,
                                      top + 7.25, 0.0, 0.5, -0.5, 100.5, 1e300, -1e300};
    for (int trial = 0; trial < 20000; ++trial) {
        std::vector<double> isos;
        const int count = 1 + trial % kMaxIsovalues;
        for (int i = 0; i < count; ++i) {
            const int pick = int(rng() % 4);
            isos.push_back(pick == 0   ? candidates[rng() % candidates.size()]
                           : pick == 1 ? double(byte(rng))
                                       : double(byte(rng)) + (pick == 2 ? 0.5 : 0.125));
        }
        InteriorNode<T> n{};
        for (int c = 0; c < 8; ++c) {
            T a = T(byte(rng)), b = T(byte(rng));
            if (rng() % 5 == 0) a = b;                               // one value
            if (rng() % 7 != 0 && a > b) std::swap(a, b);            // else empty (min > max) now and then
            n.bounds.min[c] = a, n.bounds.max[c] = b;
        }
        const LiveChildren<T> live(isos.data(), count);
        const unsigned mask = live.of(n);
        unsigned expected = 0, held = 0;
        for (int c = 0; c < 8; ++c) {
            expected |= unsigned(n.may_contain_any(c, isos.data(), count)) << c;
            held |= unsigned(LiveChildren<T>::holds(n, mask, c, isos.data(), count)) << c;
        }
        ASSERT_EQ(mask, expected) << "trial " << trial;
        ASSERT_EQ(held, expected) << "trial " << trial;
    }
}

TEST(LiveChildren, U8MatchesThePerChildTest) { expect_same_cull<uint8_t>(11); }
TEST(LiveChildren, I8MatchesThePerChildTest) { expect_same_cull<int8_t>(12); }


/// Wider types: of() culls nothing, so the traversal's predicate (holds) is the per-child test on
/// quantized bounds; a node with only empty children or ranges below the isovalue culls them all.
TEST(LiveChildren, WiderTypesCullThroughThePerChildTest) {
    InteriorNode<int16_t> n{};
    n.bounds.lo = -100, n.bounds.hi = 100;
    for (int c = 0; c < 8; ++c) n.bounds.qmin[c] = uint8_t(10 * c), n.bounds.qmax[c] = uint8_t(10 * c + 40);
    n.bounds.qmin[7] = 200, n.bounds.qmax[7] = 100;   // empty
    for (double iso : {-100.5, -99.5, -60.0, 0.5, 55.5, 100.0, 100.5}) {
        const LiveChildren<int16_t> live(&iso, 1);
        const unsigned mask = live.of(n);
        int held = 0;
        for (int c = 0; c < 8; ++c) {
            EXPECT_EQ(LiveChildren<int16_t>::holds(n, mask, c, &iso, 1), n.may_contain_any(c, &iso, 1)) << iso << " " << c;
            held += LiveChildren<int16_t>::holds(n, mask, c, &iso, 1);
        }
        // Step 200/255: child c spans about [-100 + 7.84 c, -68.6 + 7.84 c] (c < 7), all of
        // them inside [-100, -21.6]: isovalues outside that are culled for every child.
        if (iso == -99.5 || iso == -60.0) EXPECT_GT(held, 0) << iso;
        else EXPECT_EQ(held, 0) << iso;
    }
}

}  // namespace
}  // namespace octiso::test
