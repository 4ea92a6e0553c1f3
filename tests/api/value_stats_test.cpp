// value_stats (include/octiso/value_stats.h) against the dense array itself: for all 8 scalar types
// and odd shapes (padding that must not count), the voxel count, min/max, every histogram count
// (through the same bin rule) and every nearest-rank percentile equal what sorting the array gives.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "octiso/any_octree.h"
#include "octiso/error.h"
#include "octiso/value_stats.h"
#include "octree/octree_test_util.h"

namespace octiso::test {
namespace {

template <typename T> void expect_stats_of_array(const DenseVolume<T>& v, int bins, double tolerance = 0) {
    BuildOptions options;
    options.tolerance = tolerance;
    const AnyOctree tree = AnyOctree::build(v.view(), Placement{}, options);
    const ValueStats s = value_stats(tree, bins);

    std::vector<double> sorted;
    for (const T x : v.values)
        if (std::isfinite(double(x))) sorted.push_back(double(x));
    std::sort(sorted.begin(), sorted.end());
    ASSERT_EQ(s.voxels, sorted.size());
    EXPECT_EQ(s.non_finite, v.values.size() - sorted.size());
    ASSERT_FALSE(sorted.empty());
    if (tolerance > 0) {   // a lossy tree: values within the tolerance, counts still exact
        EXPECT_GE(s.range[0], sorted.front() - tolerance);
        EXPECT_LE(s.range[1], sorted.back() + tolerance);
        return;
    }
    EXPECT_EQ(s.range[0], sorted.front());
    EXPECT_EQ(s.range[1], sorted.back());
    ASSERT_EQ(s.counts.size(), size_t(bins));
    std::vector<uint64_t> counts(size_t(bins), 0);
    for (const double x : sorted) ++counts[size_t(s.bin_of(x))];
    EXPECT_EQ(s.counts, counts);
    for (size_t i = 0; i < s.percentiles.size(); ++i) {
        const double want = std::ceil(ValueStats::percentile_levels[i] / 100.0 * double(sorted.size()));
        const size_t rank = std::clamp<size_t>(size_t(want), 1, sorted.size());
        EXPECT_EQ(s.percentiles[i], sorted[rank - 1]) << ValueStats::percentile_levels[i] << "%";
    }
    EXPECT_EQ(s.bin_edge(0), s.range[0]);
    EXPECT_EQ(s.bin_edge(bins), s.range[1]);
}

template <typename T> class ValueStatsTyped : public ::testing::Test {};
TYPED_TEST_SUITE(ValueStatsTyped, AllScalarTypes);

TYPED_TEST(ValueStatsTyped, EqualsTheSortedArrayOnRandomSparseAndBlockyData) {
    using T = TypeParam;
    for (const Pattern p : {Pattern::Random, Pattern::Sparse, Pattern::Blocky}) {
        SCOPED_TRACE(int(p));
        // 13 x 7 x 19: the padded cube is 32^3, so most of it is padding that must not count.
        expect_stats_of_array(make_volume<T>({13, 7, 19}, p, 5), 16);
        expect_stats_of_array(make_volume<T>({33, 2, 5}, p, 6), 7);
    }
}

TEST(ValueStats, ConstantVolumeHasOneValueEverywhere) {
    const auto v = make_volume<uint16_t>({9, 9, 9}, Pattern::Constant, 1);
    const ValueStats s = value_stats(AnyOctree::build(v.view(), Placement{}, {}), 4);
    EXPECT_EQ(s.voxels, 729u);
    EXPECT_EQ(s.range, (std::array<double, 2>{7, 7}));
    for (const double p : s.percentiles) EXPECT_EQ(p, 7);
    EXPECT_EQ(s.counts, (std::vector<uint64_t>{729, 0, 0, 0}));
}

TEST(ValueStats, ExtremeDoublesDoNotOverflowTheBins) {
    auto v = make_volume<double>({6, 5, 4}, Pattern::Random, 4);
    v.values[0] = -1.7e308;
    v.values[1] = 1.7e308;
    v.values[2] = 4.9e-324;   // subnormal neighbours of 0 must still be told apart
    v.values[3] = 9.9e-324;
    expect_stats_of_array(v, 16);
}

TEST(ValueStats, LossyTreeCountsEveryVoxel) {
    expect_stats_of_array(make_volume<float>({17, 11, 9}, Pattern::Blocky, 2), 16, 0.5);
}

TEST(ValueStats, BinCountOutsideOneTo4096IsRefused) {
    const auto v = make_volume<uint8_t>({4, 4, 4}, Pattern::Random, 1);
    const AnyOctree tree = AnyOctree::build(v.view(), Placement{}, {});
    EXPECT_THROW(value_stats(tree, 0), Error);
    EXPECT_THROW(value_stats(tree, 4097), Error);
}

}  // namespace
}  // namespace octiso::test
