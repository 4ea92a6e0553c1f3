// Octree construction and hashing against the dense array it came from: point location of every
// voxel, neighbour finding of every forward neighbour, exact min/max, tolerance, iso-range.
#include <cmath>
#include <cstring>
#include <limits>

#include "octiso/build.h"
#include "octiso/error.h"
#include "octree/octree_test_util.h"
#include "octree/prepare.h"

namespace octiso::test {
namespace {

template <typename T> class OctreeBuild : public ::testing::Test {};
TYPED_TEST_SUITE(OctreeBuild, AllScalarTypes);

const Dims kShapes[] = {{1, 1, 1}, {2, 2, 2}, {1000, 1, 1}, {3, 5, 7}, {65, 33, 17}, {1, 9, 30}, {16, 16, 16}};
const Pattern kPatterns[] = {Pattern::Random, Pattern::Constant, Pattern::Sparse, Pattern::Blocky};

template <typename T> void expect_every_voxel_located(const DenseVolume<T>& v, const Octree<T>& tree) {
    for (uint32_t z = 0; z < v.dims.z; ++z)
        for (uint32_t y = 0; y < v.dims.y; ++y)
            for (uint32_t x = 0; x < v.dims.x; ++x)
                ASSERT_EQ(tree.point_locate({x, y, z}), v.at(x, y, z)) << "voxel " << x << "," << y << "," << z;
}

TYPED_TEST(OctreeBuild, EveryVoxelThroughPointLocationEqualsInput) {
    using T = TypeParam;
    uint32_t seed = 1;
    for (const Dims& dims : kShapes)
        for (Pattern p : kPatterns) {
            const auto v = make_volume<T>(dims, p, seed++);
            const auto data = build_octree(v.view(), {});
            SCOPED_TRACE(::testing::Message() << dims.x << "x" << dims.y << "x" << dims.z << " pattern " << int(p));
            expect_every_voxel_located(v, data.view());
        }
}

TYPED_TEST(OctreeBuild, ConstantVolumeIsOneRootOfScalarLeaves) {
    using T = TypeParam;
    const auto v = make_volume<T>({64, 64, 64}, Pattern::Constant, 0);
    const auto data = build_octree(v.view(), {});
    EXPECT_EQ(data.view().node_count(0), 1u);
    EXPECT_EQ(data.view().node(0, 0).child_mask, 0);
    EXPECT_EQ(data.view().cap_count(), 0u);
}

TYPED_TEST(OctreeBuild, NeighbourFindingEqualsDirectLookup) {
    using T = TypeParam;
    for (const Dims& dims : {Dims{9, 7, 6}, Dims{17, 4, 11}, Dims{8, 8, 8}})
        for (Pattern p : {Pattern::Random, Pattern::Blocky, Pattern::Sparse}) {
            const auto v = make_volume<T>(dims, p, 42);
            const auto data = build_octree(v.view(), {});
            const Octree<T> tree = data.view();
            uint32_t trace[kMaxDepth];
            for (uint32_t z = 0; z < dims.z; ++z)
                for (uint32_t y = 0; y < dims.y; ++y)
                    for (uint32_t x = 0; x < dims.x; ++x) {
                        // Build the parent trace of (x,y,z) by descending from the root.
                        const Coord start{x, y, z};
                        int d = 0;
                        uint32_t index = 0;
                        for (;;) {   // down to the holding leaf's node, or a cap's parent (octree.h)
                            trace[d] = index;
                            const auto& n = tree.node(d, index);
                            const int c = octant_of(start, tree.child_bit(d));
                            if (n.is_scalar_leaf(c) || d + 1 == tree.cap_depth()) break;
                            index = tree.child_index(d, index, n, c);
                            ++d;
                        }
                        for (int dir = 1; dir < 8; ++dir) {
                            const Coord dest{x + ((dir & 1) ? 1u : 0u), y + ((dir & 2) ? 1u : 0u), z + ((dir & 4) ? 1u : 0u)};
                            if (dest.x >= dims.x || dest.y >= dims.y || dest.z >= dims.z) continue;
                            ASSERT_EQ(tree.neighbour_find(start, dest, d, trace), v.at(dest.x, dest.y, dest.z))
                                << "from " << x << "," << y << "," << z << " dir " << dir;
                        }
                    }
        }
}

TYPED_TEST(OctreeBuild, MinMaxEqualsExactCellRangeOfEveryChild) {
    using T = TypeParam;
    for (const Dims& dims : {Dims{13, 9, 21}, Dims{2, 2, 2}, Dims{33, 2, 5}, Dims{16, 16, 16}})
        for (Pattern p : kPatterns) {
            const auto v = make_volume<T>(dims, p, 7);
            const auto data = build_octree(v.view(), {});
            const Octree<T> tree = data.view();
            int checked = 0;
            for_each_node<T>(tree, [&](int d, uint32_t i, Coord o) {
                const auto& n = tree.node(d, i);
                const uint32_t half = tree.child_bit(d);
                for (int c = 0; c < 8; ++c) {
                    const Coord co{o.x + ((c & 4) ? half : 0), o.y + ((c & 2) ? half : 0), o.z + ((c & 1) ? half : 0)};
                    double lo, hi;
                    const bool has_cells = exact_cell_range<T>(dims, co, half, [&](uint32_t x, uint32_t y, uint32_t z) { return v.at(x, y, z); }, lo, hi);
                    if (!has_cells) {
                        EXPECT_TRUE(n.bounds.empty(c)) << "child without data cells must have an empty range";
                    } else if constexpr (sizeof(T) == 1) {   // exact bounds (octree.h)
                        EXPECT_EQ(n.bounds.lower(c), lo) << "depth " << d << " child " << c;
                        EXPECT_EQ(n.bounds.upper(c), hi) << "depth " << d << " child " << c;
                    } else {
                        // 8-bit codes in the node's exact range: they contain the cell range and
                        // are the tightest codes that do (within one code step of it).
                        ASSERT_FALSE(n.bounds.empty(c));
                        const double step = (double(n.bounds.hi) - double(n.bounds.lo)) / 255;
                        EXPECT_LE(n.bounds.lower(c), lo) << "depth " << d << " child " << c;
                        EXPECT_GE(n.bounds.upper(c), hi) << "depth " << d << " child " << c;
                        EXPECT_LE(lo - n.bounds.lower(c), step * 1.001) << "depth " << d << " child " << c;
                        EXPECT_LE(n.bounds.upper(c) - hi, step * 1.001) << "depth " << d << " child " << c;
                        EXPECT_LE(double(n.bounds.lo), lo);
                        EXPECT_GE(double(n.bounds.hi), hi);
                    }
                    ++checked;
                }
            });
            EXPECT_GT(checked, 0);
        }
}

TYPED_TEST(OctreeBuild, ToleranceNeverExceedsEpsAndRangesStillBoundStoredCells) {
    using T = TypeParam;
    const Dims dims{37, 20, 26};
    DenseVolume<T> v{dims, std::vector<T>(dims.voxels())};
    for (uint64_t i = 0; i < v.values.size(); ++i) {  // smooth ramp with small wiggles: merges happen
        const uint32_t x = uint32_t(i % dims.x), y = uint32_t(i / dims.x % dims.y), z = uint32_t(i / (uint64_t(dims.x) * dims.y));
        v.values[i] = T(10 + (x / 3) + ((x * 7 + y * 3 + z) % 4));
    }
    for (double eps : {1.0, 2.0, 3.5}) {
        BuildOptions options;
        options.tolerance = eps;
        const auto lossy = build_octree(v.view(), options);
        const auto exact = build_octree(v.view(), {});
        const Octree<T> tree = lossy.view();
        double max_err = 0;
        for (uint32_t z = 0; z < dims.z; ++z)
            for (uint32_t y = 0; y < dims.y; ++y)
                for (uint32_t x = 0; x < dims.x; ++x)
                    max_err = std::max(max_err, std::abs(double(tree.point_locate({x, y, z})) - double(v.at(x, y, z))));
        EXPECT_LE(max_err, eps);
        EXPECT_LT(lossy.stats.cap_bytes + lossy.stats.interior_bytes, exact.stats.cap_bytes + exact.stats.interior_bytes)
            << "a tolerance of " << eps << " should compress this ramp";
        // Every child range must contain the cells of the values actually stored.
        for_each_node<T>(tree, [&](int d, uint32_t i, Coord o) {
            const auto& n = tree.node(d, i);
            const uint32_t half = tree.child_bit(d);
            for (int c = 0; c < 8; ++c) {
                const Coord co{o.x + ((c & 4) ? half : 0), o.y + ((c & 2) ? half : 0), o.z + ((c & 1) ? half : 0)};
                double lo, hi;
                if (exact_cell_range<T>(dims, co, half, [&](uint32_t x, uint32_t y, uint32_t z) { return tree.point_locate({x, y, z}); }, lo, hi)) {
                    EXPECT_LE(n.bounds.lower(c), lo);
                    EXPECT_GE(n.bounds.upper(c), hi);
                }
            }
        });
    }
}

/// Format 6 (CapAnchor, octree.h): a 1-byte cap takes its base from its child's lower or upper
/// bound, per parent the narrower. Dark data with a little noise takes the lower, bright data
/// the upper, and every voxel comes back, odd extents (border caps whose last layer no cell
/// starts at, whose bounds the packer widens or chooses) included.
template <typename T> void expect_both_anchors_exact() {
    const Dims dims{37, 21, 19};
    DenseVolume<T> v{dims, std::vector<T>(dims.voxels())};
    uint32_t state = 12345;
    const auto noise = [&] { return (state = state * 1664525u + 1013904223u) >> 29; };   // 0 .. 7
    for (uint32_t z = 0; z < dims.z; ++z)
        for (uint32_t y = 0; y < dims.y; ++y)
            for (uint32_t x = 0; x < dims.x; ++x) {
                const int lowest = int(std::numeric_limits<T>::lowest()), highest = int(std::numeric_limits<T>::max());
                // x < 18: near the lowest value; above: near the highest; one bright line in the dark.
                const int value = x < 18 && y != 7 ? lowest + int(noise()) + (x % 3) : highest - int(noise()) - (z % 3);
                v.values[uint64_t(z) * dims.y * dims.x + uint64_t(y) * dims.x + x] = T(value);
            }
    const auto built = build_octree(v.view(), {});
    const Octree<T> tree = built.view();
    expect_every_voxel_located(v, tree);
    uint64_t anchors[2] = {};
    const int d = tree.dmax() - 2;
    for (uint64_t i = 0; i < tree.node_count(d); ++i) {
        const InteriorNode<T>& n = tree.node(d, i);
        if (n.child_mask == 0) continue;
        const bool upper = n.cap_anchor() == CapAnchor::upper;
        ++anchors[upper];
        EXPECT_GE(n.cap_width(), 1u);
        EXPECT_LE(n.cap_width(), 8u);
        // A cap child with cells keeps its anchor's bound on the far side of every voxel.
        for (int c = 0; c < 8; ++c) {
            if (n.is_scalar_leaf(c) || n.bounds.empty(c)) continue;
            T voxel[8];
            tree.cap(i, n, c).decode(voxel);
            for (T x : voxel) {
                if (upper) EXPECT_LE(x, n.bounds.max[c]);
                else EXPECT_GE(x, n.bounds.min[c]);
            }
        }
    }
    EXPECT_GT(anchors[0], 0u) << "no parent took the lower bound";
    EXPECT_GT(anchors[1], 0u) << "no parent took the upper bound";
}

TEST(OctreeBuildOneByte, CapsTakeEitherBoundAndComeBackExactly) {
    expect_both_anchors_exact<uint8_t>();
    expect_both_anchors_exact<int8_t>();
}

TYPED_TEST(OctreeBuild, IsoRangeKeepsEveryCellThatReachesIntoTheRange) {
    using T = TypeParam;
    const Dims dims{30, 17, 23};
    DenseVolume<T> v{dims, std::vector<T>(dims.voxels())};
    for (uint64_t i = 0; i < v.values.size(); ++i) {
        const uint32_t x = uint32_t(i % dims.x), y = uint32_t(i / dims.x % dims.y), z = uint32_t(i / (uint64_t(dims.x) * dims.y));
        v.values[i] = T((x * 5 + y * 3 + z * 7 + (x * y) % 11) % 100);
    }
    const double lo = 30.5, hi = 60.5;
    BuildOptions options;
    options.iso_range = {{lo, hi}};
    const auto data = build_octree(v.view(), options);
    const Octree<T> tree = data.view();
    int clamped = 0;
    for (uint32_t z = 0; z + 1 < dims.z; ++z)
        for (uint32_t y = 0; y + 1 < dims.y; ++y)
            for (uint32_t x = 0; x + 1 < dims.x; ++x) {
                // A cell either keeps all 8 corners, or lies wholly at/below LO (or at/above HI)
                // both before and after: then no iso in (LO, HI) can cross it either way.
                bool same = true, below_before = true, below_after = true, above_before = true, above_after = true;
                for (int k = 0; k < 8; ++k) {
                    const Coord p{x + (k & 1), y + ((k >> 1) & 1), z + ((k >> 2) & 1)};
                    const double a = double(v.at(p.x, p.y, p.z)), b = double(tree.point_locate(p));
                    same &= a == b;
                    below_before &= a <= lo, below_after &= b <= lo;
                    above_before &= a >= hi, above_after &= b >= hi;
                }
                EXPECT_TRUE(same || (below_before && below_after) || (above_before && above_after))
                    << "cell " << x << "," << y << "," << z;
                clamped += !same;
            }
    EXPECT_GT(clamped, 0) << "the test field must exercise clamping";
    for (uint32_t z = 0; z < dims.z; ++z)
        for (uint32_t y = 0; y < dims.y; ++y)
            for (uint32_t x = 0; x < dims.x; ++x) {
                const T s = tree.point_locate({x, y, z}), a = v.at(x, y, z);
                EXPECT_TRUE(s == a || s == detail::clamp_target_low<T>(lo) || s == detail::clamp_target_high<T>(hi));
            }
}

TEST(OctreeBuildNonFinite, RefusedByDefaultAndReplacedWithNanAs) {
    DenseVolume<float> v = make_volume<float>({6, 5, 4}, Pattern::Sparse, 3);
    v.values[17] = std::numeric_limits<float>::quiet_NaN();
    v.values[40] = std::numeric_limits<float>::infinity();
    BuildOptions options;
    options.source_name = "field.raw";
    EXPECT_THROW(build_octree(v.view(), options), Error);
    try {
        build_octree(v.view(), options);
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("field.raw"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("NaN"), std::string::npos);
    }
    options.nan_as = -1.0;
    const auto data = build_octree(v.view(), options);
    EXPECT_EQ(data.view().point_locate({17 % 6, 17 / 6 % 5, 0}), -1.0f);
    EXPECT_EQ(data.view().point_locate({40 % 6, 40 / 6 % 5, 40 / 30}), -1.0f);
}

TEST(OctreeBuildLarge, ParallelPiecesMatchInputOnAnOddShape) {
    // Big enough that the split depth is 3 (512 pieces), odd so pieces are partly padding.
    const auto v = make_volume<uint16_t>({133, 71, 90}, Pattern::Blocky, 5);
    const auto data = build_octree(v.view(), {});
    expect_every_voxel_located(v, data.view());
    uint64_t total = 0;
    for (uint64_t n : data.stats.nodes_per_depth) total += n;
    EXPECT_GT(total, 1u);
}

TEST(OctreeBuildLarge, SameBytesOnAnyThreadCountWithEveryPhaseTimed) {
    // Issue 12: the pieces are concatenated in parallel batches; the result must not depend on
    // how many threads copied them, and the phases the converter reports must add up.
    const auto v = make_volume<uint8_t>({133, 71, 90}, Pattern::Blocky, 9);
    BuildOptions one;
    one.threads = 1;
    const auto reference = build_octree(v.view(), one);
    for (int threads : {2, 3, 5}) {
        BuildOptions options;
        options.threads = threads;
        const auto data = build_octree(v.view(), options);
        ASSERT_EQ(data.nodes.size(), reference.nodes.size());
        for (size_t d = 0; d < data.nodes.size(); ++d) {
            ASSERT_EQ(data.nodes[d].size, reference.nodes[d].size) << "depth " << d;
            EXPECT_EQ(std::memcmp(data.nodes[d].data.get(), reference.nodes[d].data.get(),
                                  data.nodes[d].size * sizeof(InteriorNode<uint8_t>)), 0)
                << "depth " << d << " on " << threads << " threads";
        }
        ASSERT_EQ(data.cap_bytes, reference.cap_bytes);
        EXPECT_EQ(std::memcmp(data.caps.data.get(), reference.caps.data.get(), data.cap_bytes + kCapReadSlack), 0)
            << threads << " threads";
        EXPECT_EQ(data.stats.nodes_per_depth, reference.stats.nodes_per_depth);
        EXPECT_EQ(data.stats.scalar_leaves_per_depth, reference.stats.scalar_leaves_per_depth);
        const BuildPhases& p = data.stats.phases;
        for (double phase : {p.prepare, p.pieces, p.top, p.concatenate, p.release}) EXPECT_GE(phase, 0.0);
        EXPECT_GT(p.pieces, 0.0);
        EXPECT_LE(p.prepare + p.pieces + p.top + p.concatenate + p.release, data.stats.seconds);
    }
}

}  // namespace
}  // namespace octiso::test
