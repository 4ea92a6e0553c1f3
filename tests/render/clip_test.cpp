// Clip planes (src/render/clip.h) and the ray interval [t_min, t_max] they rest on (math/ray.h):
// the interval arithmetic on exact cases (+-0 directions, a point on the plane, parallel rays),
// the octree tracer against the dense exact reference on rays with arbitrary intervals, and
// clipped frames against the reference with the same clip; no plane is no change.
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "octiso/error.h"
#include "octiso/render.h"
#include "render/look_test_util.h"
#include "render/render_test_util.h"

namespace octiso::test {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(ClipRay, HalfSpacesNarrowTheInterval) {
    Ray r{{0, 0, 0}, {1, 0, 0}};
    const ClipPlane keep_below_5[] = {{{1, 0, 0}, 5}};
    clip_ray(keep_below_5, r);
    EXPECT_EQ(r.t_min, 0.0);
    EXPECT_EQ(r.t_max, 5.0);
    const ClipPlane keep_above_2[] = {{{-1, 0, 0}, -2}};   // -x <= -2: x >= 2
    clip_ray(keep_above_2, r);
    EXPECT_EQ(r.t_min, 2.0);
    EXPECT_EQ(r.t_max, 5.0);
    const ClipPlane scaled[] = {{{2, 0, 0}, 6}};            // 2x <= 6: the same as x <= 3
    clip_ray(scaled, r);
    EXPECT_EQ(r.t_max, 3.0);
}

TEST(ClipRay, ParallelRaysKeepAllOrNothingAndNegativeZeroIsParallel) {
    for (double zero : {0.0, -0.0}) {
        Ray inside{{0, 0, 1}, {1, zero, 0}};
        const ClipPlane y_le_0[] = {{{0, 1, 0}, 0}};   // the origin lies on the plane: kept (closed)
        clip_ray(y_le_0, inside);
        EXPECT_EQ(inside.t_min, 0.0);
        EXPECT_EQ(inside.t_max, kInf);
        Ray outside{{0, 1, 1}, {1, zero, 0}};
        clip_ray(y_le_0, outside);
        EXPECT_FALSE(outside.t_min <= outside.t_max) << "a ray wholly on the cut side is empty";
    }
}

TEST(ClipRay, BadPlanesAreRefused) {
    RenderOptions o;
    o.isovalues = {1};
    for (const ClipPlane& bad : {ClipPlane{{0, 0, 0}, 1}, ClipPlane{{NAN, 0, 1}, 1}, ClipPlane{{0, 0, 1}, kInf}}) {
        o.clip_planes = {bad};
        EXPECT_THROW(validate_options(o), Error);
    }
    o.clip_planes = {{{0, 0, -3}, 1}};
    EXPECT_NO_THROW(validate_options(o));
}

// Rays with a random interval [t_min, t_max] (starting inside cells, ending inside cells, empty):
// the octree kernel and the exact reference agree on hit or miss and on t.
TEST(RayInterval, TracerAgreesWithTheReferenceOnEveryInterval) {
    const auto v = make_field<float>(Field::MarschnerLobb, {25, 22, 27});
    Placement placement;
    placement.spacing = {1.0, 1.3, 0.8};
    const auto data = build_octree(v.view(), {});
    RenderOptions options;
    options.isovalues = {40.0, 75.0};
    options.root_finder = RootFinder::exact;
    const KernelTracer octree(data.view(), placement, options);
    const ReferenceTracer<float> ref{v.view(), placement, options.isovalues};
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(0, 1);
    int hits = 0, misses = 0;
    for (int i = 0; i < 3000; ++i) {
        Ray r;
        for (int a = 0; a < 3; ++a) r.origin[a] = -5 + 40 * u(rng), r.dir[a] = u(rng) - 0.5;
        if (i % 7 == 0) r.dir[i % 3] = (i % 2) ? 0.0 : -0.0;
        const double len = std::sqrt(r.dir[0] * r.dir[0] + r.dir[1] * r.dir[1] + r.dir[2] * r.dir[2]);
        for (double& d : r.dir) d /= len;
        r.t_min = 30 * u(rng);
        r.t_max = i % 5 == 0 ? kInf : r.t_min + 30 * u(rng) - 3;   // some empty
        const TraceHit a = octree(r, false), b = ref(r, false);
        ASSERT_EQ(a.is_hit(), b.is_hit()) << "ray " << i;
        if (!a.is_hit()) { ++misses; continue; }
        ++hits;
        EXPECT_GE(a.t, r.t_min);
        EXPECT_LE(a.t, r.t_max);
        EXPECT_NEAR(a.t, b.t, 1e-3) << "ray " << i;
        EXPECT_EQ(a.iso_index, b.iso_index) << "ray " << i;
    }
    EXPECT_GT(hits, 150);
    EXPECT_GT(misses, 300);
}

template <typename T> class ClippedFrames : public ::testing::Test {};
using ClipTypes = ::testing::Types<uint8_t, int16_t, float, double>;
TYPED_TEST_SUITE(ClippedFrames, ClipTypes);

// A sphere cut open by two planes: the octree frame through the Renderer (Embree and direct)
// against the reference with the same clip, and the cut actually changes the image.
TYPED_TEST(ClippedFrames, MatchTheReferenceWithTheSameClip) {
    using T = TypeParam;
    const auto v = make_field<T>(Field::Torus, {33, 29, 21});
    Placement placement;
    placement.origin = {-4, 3, 1};
    const auto data = build_octree(v.view(), {});
    RenderOptions options;
    options.isovalues = {47.0};
    options.root_finder = RootFinder::exact;
    options.want_colour = false;
    options.want_depth = true;
    const Camera cam = look_at({50, -30, 45}, {12, 17, 11}, {0, 0, 1}, 40, 56);
    const Frame plain = render(data.view(), placement, cam, options);
    options.clip_planes = {{{1, 1, 0}, 27}, {{0, 0, -1}, -6}};   // keep x + y <= 27 and z >= 6
    const ReferenceTracer<T> ref{v.view(), placement, options.isovalues};
    const Frame expected = reference_frame_clipped(ref, cam, options.clip_planes);
    for (bool embree : {true, false}) {
        options.use_embree = embree;
        const Frame clipped = render(data.view(), placement, cam, options);
        expect_agreement(compare_frames(clipped, expected, 1.0), embree ? "embree" : "direct", kExactFinderBar);
        int changed = 0;
        for (size_t i = 0; i < plain.depth.size(); ++i) changed += !(plain.depth[i] == clipped.depth[i]);
        EXPECT_GT(changed, 100) << "the planes must cut the visible surface";
    }
}

}  // namespace
}  // namespace octiso::test
