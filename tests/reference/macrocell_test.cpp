// The macrocell grid (src/reference/macrocell.h) against independent references: its ranges
// against a brute-force min/max over each macrocell's cells, its images against the dense exact
// tracer (trace_reference), its octree corner source against direct array reads, and the octree
// tracer reading array corners against the octree tracer reading its own.
#include <cmath>
#include <random>

#include "octiso/build.h"
#include "octree/octree_test_util.h"
#include "reference/brute_force.h"
#include "reference/macrocell.h"
#include "reference/trace_frame.h"
#include "render/pinhole_camera.h"
#include "render/render_test_util.h"

namespace octiso::test {
namespace {

template <typename T>
ImageError against_reference(const Frame& frame, const DenseVolume<T>& v, const Placement& placement, const Camera& camera,
                             double iso) {
    return error_against_reference(frame, v.view(), placement, camera, iso);
}

template <typename T>
Frame grid_frame(const MacrocellGrid<T>& grid, const VolumeView<T>& volume, const Placement& placement, const Camera& cam,
                 double iso) {
    const MacrocellTracer<T, Neubauer, ArrayCorners<T>> tracer(grid, ArrayCorners<T>{volume}, placement, &iso, 1, Neubauer{});
    return trace_frame(tracer, cam, false);
}

const MacrocellOptions kConfigs[] = {{4, 3}, {8, 1}, {2, 5}, {3, 2}, {4, 0}};

template <typename T> class MacrocellGridTest : public ::testing::Test {};
TYPED_TEST_SUITE(MacrocellGridTest, AllScalarTypes);

TYPED_TEST(MacrocellGridTest, RangesAreTheExactMinMaxOfTheCoveredCells) {
    using T = TypeParam;
    for (const Pattern pattern : {Pattern::Random, Pattern::Blocky}) {
        const auto v = make_volume<T>({19, 11, 14}, pattern, 5);
        for (const MacrocellOptions& o : {MacrocellOptions{4, 2}, MacrocellOptions{3, 3}, MacrocellOptions{2, 1}}) {
            const MacrocellGrid<T> grid(v.view(), o);
            int64_t u = 1;
            for (int l = 1; l <= o.levels; ++l) {
                u *= o.branching;
                const auto& c = grid.count(l);
                ASSERT_EQ(c[0], (18 + u - 1) / u);
                for (int64_t k = 0; k < c[2]; ++k)
                    for (int64_t j = 0; j < c[1]; ++j)
                        for (int64_t i = 0; i < c[0]; ++i) {
                            // Cells [m u, min((m+1) u, n-1)) have voxels up to min((m+1) u, n-1).
                            T lo = std::numeric_limits<T>::max(), hi = std::numeric_limits<T>::lowest();
                            for (int64_t z = k * u; z <= std::min((k + 1) * u, int64_t(13)); ++z)
                                for (int64_t y = j * u; y <= std::min((j + 1) * u, int64_t(10)); ++y)
                                    for (int64_t x = i * u; x <= std::min((i + 1) * u, int64_t(18)); ++x)
                                        lo = std::min(lo, v.at(x, y, z)), hi = std::max(hi, v.at(x, y, z));
                            ASSERT_EQ(grid.min_at(l, i, j, k), lo) << "level " << l;
                            ASSERT_EQ(grid.max_at(l, i, j, k), hi) << "level " << l;
                        }
            }
        }
    }
}

TYPED_TEST(MacrocellGridTest, OctreeCornersEqualArrayCornersOnEveryCell) {
    using T = TypeParam;
    for (const Pattern pattern : {Pattern::Random, Pattern::Sparse, Pattern::Blocky, Pattern::Constant}) {
        const auto v = make_volume<T>({21, 17, 9}, pattern, 11);
        const auto data = build_octree(v.view(), {});
        const OctreeCorners<T> from_tree{data.view()};
        const ArrayCorners<T> from_array{v.view()};
        for (uint32_t z = 0; z + 1 < 9; ++z)
            for (uint32_t y = 0; y + 1 < 17; ++y)
                for (uint32_t x = 0; x + 1 < 21; ++x) {
                    double a[8], b[8];
                    from_tree.gather({x, y, z}, a);
                    from_array.gather({x, y, z}, b);
                    for (int k = 0; k < 8; ++k) ASSERT_EQ(a[k], b[k]) << x << "," << y << "," << z << " corner " << k;
                }
    }
}

TYPED_TEST(MacrocellGridTest, SphereFromAllEightOctantsAgreesWithReference) {
    using T = TypeParam;
    const Dims dims{23, 19, 26};
    const auto v = make_field<T>(Field::Sphere, dims);
    Placement placement;
    const MacrocellGrid<T> grid(v.view(), {4, 2});
    const std::array<double, 3> centre{11, 9, 12.5};
    for (int o = 0; o < 8; ++o) {
        const std::array<double, 3> eye{centre[0] + ((o & 1) ? 40 : -40), centre[1] + ((o & 2) ? 35 : -35),
                                        centre[2] + ((o & 4) ? 45 : -45)};
        const Camera cam = look_at(eye, centre, {0, 0, 1}, 35, 40);
        expect_agreement(against_reference(grid_frame(grid, v.view(), placement, cam, 60.0), v, placement, cam, 60.0),
                         "octant " + std::to_string(o));
    }
}

TEST(MacrocellGridImages, EveryConfigurationFieldAndCameraAgreesWithReference) {
    struct Case { Field field; Dims dims; double iso; std::array<double, 3> spacing; };
    const Case cases[] = {{Field::MarschnerLobb, {33, 33, 33}, 60.0, {1.0, 0.7, 1.6}},
                          {Field::Noise, {17, 21, 13}, 56.0, {1, 1, 1}},
                          {Field::Sphere, {65, 33, 17}, 70.0, {1, 1, 1}}};
    for (const Case& c : cases) {
        const auto v = make_field<float>(c.field, c.dims);
        Placement placement;
        placement.spacing = c.spacing;
        placement.origin = {-3, 2, 5};
        std::array<double, 3> centre;
        const uint32_t n[3] = {c.dims.x, c.dims.y, c.dims.z};
        double r = 0;
        for (int a = 0; a < 3; ++a) {
            centre[a] = placement.origin[a] + 0.5 * (n[a] - 1) * c.spacing[a];
            r = std::max(r, 1.6 * n[a] * c.spacing[a]);
        }
        const Camera cams[] = {
            look_at({centre[0] + r, centre[1] - 0.7 * r, centre[2] + 0.5 * r}, centre, {0, 0, 1}, 40, 40),
            look_at({centre[0] - 0.3 * r, centre[1] + r, centre[2] - 0.8 * r}, centre, {0, 0, 1}, 40, 40),
            // exactly axis-aligned (odd size: the middle ray has +-0 components) and an eye inside
            look_at({centre[0], centre[1], centre[2] + r}, centre, {0, 1, 0}, 35, 41),
            look_at(centre, {centre[0] + 5, centre[1] + 1, centre[2] - 2}, {0, 0, 1}, 80, 40)};
        for (const MacrocellOptions& o : kConfigs) {
            const MacrocellGrid<float> grid(v.view(), o);
            int i = 0;
            for (const Camera& cam : cams)
                expect_agreement(against_reference(grid_frame(grid, v.view(), placement, cam, c.iso), v, placement, cam, c.iso),
                                 "field " + std::to_string(int(c.field)) + " B=" + std::to_string(o.branching) +
                                     " levels=" + std::to_string(o.levels) + " camera " + std::to_string(i++));
        }
    }
}

TEST(MacrocellGridImages, NonFiniteCellsAreSkippedLikeTheReference) {
    auto v = make_field<float>(Field::Sphere, {24, 24, 24});
    std::mt19937 rng(3);
    for (int i = 0; i < 300; ++i) v.values[rng() % v.values.size()] = (i % 2) ? NAN : INFINITY;
    Placement placement;
    const MacrocellGrid<float> grid(v.view(), {4, 2});
    const Camera cam = look_at({60, -45, 50}, {11.5, 11.5, 11.5}, {0, 0, 1}, 35, 48);
    expect_agreement(against_reference(grid_frame(grid, v.view(), placement, cam, 70.0), v, placement, cam, 70.0), "nan/inf");
}

TEST(MacrocellGridImages, GridOnOctreeDataEqualsGridOnArrayData) {
    const auto v = make_field<uint16_t>(Field::MarschnerLobb, {40, 37, 29});
    const auto data = build_octree(v.view(), {});
    Placement placement;
    const MacrocellGrid<uint16_t> grid(v.view(), {4, 2});
    const Camera cam = look_at({80, -60, 70}, {20, 18, 14}, {0, 0, 1}, 35, 48);
    const double iso = 60.0;
    const MacrocellTracer<uint16_t, Neubauer, OctreeCorners<uint16_t>> on_tree(grid, OctreeCorners<uint16_t>{data.view()},
                                                                             placement, &iso, 1, Neubauer{});
    const Frame a = trace_frame(on_tree, cam, true);
    const Frame b = grid_frame(grid, v.view(), placement, cam, iso);
    ASSERT_EQ(a.depth.size(), b.depth.size());
    for (size_t i = 0; i < a.depth.size(); ++i)
        ASSERT_TRUE(a.depth[i] == b.depth[i] || (std::isinf(a.depth[i]) && std::isinf(b.depth[i]))) << "pixel " << i;
    expect_agreement(against_reference(a, v, placement, cam, iso), "grid over octree data");
}

TEST(OctreeOverArrayData, EqualsTheOctreeReadingItsOwnCorners) {
    for (const Field field : {Field::MarschnerLobb, Field::Noise}) {
        const auto v = make_field<uint8_t>(field, {37, 30, 33});
        const auto data = build_octree(v.view(), {});
        Placement placement;
        placement.spacing = {1.0, 1.2, 0.8};
        const double iso = 58.0;
        const Camera cam = look_at({90, -50, 60}, {18, 18, 13}, {0, 0, 1}, 35, 48);
        const OctreeTracer<uint8_t, Neubauer> own(data.view(), placement, &iso, 1, Neubauer{});
        const OctreeTracer<uint8_t, Neubauer, ArrayCorners<uint8_t>> array(data.view(), placement, &iso, 1, Neubauer{},
                                                                          ArrayCorners<uint8_t>{v.view()});
        const Frame a = trace_frame(own, cam, true), b = trace_frame(array, cam, true);
        for (size_t i = 0; i < a.depth.size(); ++i)
            ASSERT_TRUE(a.depth[i] == b.depth[i] || (std::isinf(a.depth[i]) && std::isinf(b.depth[i]))) << "pixel " << i;
        expect_agreement(against_reference(b, v, placement, cam, iso), "octree over array data");
    }
}

TEST(OctreeOverArrayData, PatternsWithLeavesAndCapsFromManyCamerasMatchBitwise) {
    // Sparse and blocky volumes mix caps and scalar leaves of every size, so the octree's own
    // corner reads (in-cap, neighbour blocks, leaf shells) are all exercised against the array.
    const struct { Pattern pattern; double iso; } cases[] = {{Pattern::Random, 127.5}, {Pattern::Sparse, 100.5},
                                                             {Pattern::Blocky, 2.5}, {Pattern::Blocky, 1.0}};
    for (const auto& c : cases) {
        const auto v = make_volume<uint8_t>({29, 35, 22}, c.pattern, 17);
        const auto data = build_octree(v.view(), {});
        Placement placement;
        const std::array<double, 3> centre{14, 17, 10.5};
        for (int o = 0; o < 8; ++o) {
            const std::array<double, 3> eye{centre[0] + ((o & 1) ? 50 : -45), centre[1] + ((o & 2) ? 40 : -55),
                                            centre[2] + ((o & 4) ? 35 : -40)};
            const Camera cam = look_at(eye, centre, {0, 0, 1}, 40, 32);
            const OctreeTracer<uint8_t, Neubauer> own(data.view(), placement, &c.iso, 1, Neubauer{});
            const OctreeTracer<uint8_t, Neubauer, ArrayCorners<uint8_t>> array(data.view(), placement, &c.iso, 1, Neubauer{},
                                                                              ArrayCorners<uint8_t>{v.view()});
            const Frame a = trace_frame(own, cam, true), b = trace_frame(array, cam, true);
            for (size_t i = 0; i < a.depth.size(); ++i) {
                ASSERT_TRUE(a.depth[i] == b.depth[i] || (std::isinf(a.depth[i]) && std::isinf(b.depth[i])))
                    << "pattern " << int(c.pattern) << " octant " << o << " pixel " << i;
                for (int k = 0; k < 3; ++k) ASSERT_EQ(a.normal[3 * i + k], b.normal[3 * i + k]);
            }
        }
    }
}

}  // namespace
}  // namespace octiso::test
