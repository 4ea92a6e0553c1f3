// Secondary rays (src/render/secondary.h) against the dense exact reference: shadow and AO rays
// from the hits of a frame hit or miss where the reference says and at its t; a convex surface
// casts no shadow on its lit side (the start offset clears the root finder's error); the AO
// sequence is reproducible and cosine-weighted. Compositing is tests/render/composite_test.cpp.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "render/look_test_util.h"
#include "render/render_test_util.h"
#include "render/secondary.h"

namespace octiso::test {
namespace {

Vec3 unit(Vec3 d) { return vec_normalized(d); }

TEST(ShadowRays, HitAndMissWhereTheReferenceSays) {
    const auto v = make_field<uint8_t>(Field::Torus, {41, 37, 17});
    Placement placement;
    placement.spacing = {1.0, 1.0, 1.5};
    const auto data = build_octree(v.view(), {});
    RenderOptions options;
    options.isovalues = {47.0, 90.0};
    options.root_finder = RootFinder::exact;
    const KernelTracer octree(data.view(), placement, options);
    const ReferenceTracer<uint8_t> ref{v.view(), placement, options.isovalues};
    const Camera cam = look_at({70, -40, 60}, {20, 18, 12}, {0, 0, 1}, 40, 48);
    const PinholeCamera pinhole(cam);
    const double offset = kSecondaryOffsetVoxels * 1.0;
    int shadowed = 0, lit = 0;
    for (const Vec3& light : {unit({-0.3, 0.8, 0.4}), unit({0.9, 0.1, 0.2}), unit({0.0, -0.0, 1.0})}) {
        for (int py = 0; py < cam.height; ++py)
            for (int px = 0; px < cam.width; ++px) {
                const Ray primary = pinhole.ray(px, py);
                const TraceHit h = octree(primary, true);
                if (!h.is_hit()) continue;
                const Ray s = shadow_ray(point_at(primary, h.t), light, offset, {});
                const TraceHit a = octree(s, false), b = ref(s, false);
                ASSERT_EQ(a.is_hit(), b.is_hit()) << "pixel " << px << "," << py;
                if (a.is_hit()) {
                    EXPECT_NEAR(a.t, b.t, 1e-3) << "pixel " << px << "," << py;
                    EXPECT_EQ(a.iso_index, b.iso_index);
                }
                (a.is_hit() ? shadowed : lit)++;
            }
    }
    EXPECT_GT(shadowed, 200) << "the torus shadows itself";
    EXPECT_GT(lit, 200);
}

TEST(AoRays, HitAndMissWhereTheReferenceSays) {
    const auto v = make_field<int16_t>(Field::Sierpinski, {27, 27, 27});
    Placement placement;
    placement.spacing = {0.5, 0.5, 0.7};
    const auto data = build_octree(v.view(), {});
    RenderOptions options;
    options.isovalues = {60.0};
    options.root_finder = RootFinder::exact;
    const KernelTracer octree(data.view(), placement, options);
    const ReferenceTracer<int16_t> ref{v.view(), placement, options.isovalues};
    const Camera cam = look_at({30, -20, 25}, {6.5, 6.5, 9}, {0, 0, 1}, 40, 32);
    const PinholeCamera pinhole(cam);
    const double voxel = 0.5, reach = kDefaultAoDistanceVoxels * voxel;
    const ClipPlane cut[] = {{{0, 0, 1}, 15}};
    int occluded = 0, open = 0;
    for (int py = 0; py < cam.height; ++py)
        for (int px = 0; px < cam.width; ++px) {
            const Ray primary = pinhole.ray(px, py);
            const TraceHit h = octree(primary, true);
            if (!h.is_hit()) continue;
            const uint32_t seed = pixel_seed(px, py, {0, 0});
            for (int s = 0; s < 8; ++s) {
                const Ray r = ao_ray(point_at(primary, h.t), h.normal, ao_sample(s, 8, seed), kSecondaryOffsetVoxels * voxel, reach, cut);
                const TraceHit a = octree(r, false), b = ref(r, false);
                ASSERT_EQ(a.is_hit(), b.is_hit()) << "pixel " << px << "," << py << " sample " << s;
                if (a.is_hit()) {
                    EXPECT_NEAR(a.t, b.t, 1e-3 * voxel);
                    EXPECT_LE(a.t, reach);
                }
                (a.is_hit() ? occluded : open)++;
            }
        }
    EXPECT_GT(occluded, 300) << "the sponge's holes occlude";
    EXPECT_GT(open, 300);
}

TEST(ShadowRays, AConvexSurfaceCastsNoShadowOnItsLitSide) {
    const auto v = nested_spheres();
    const auto data = build_octree(v.view(), {});
    for (RootFinder finder : {RootFinder::neubauer, RootFinder::exact}) {
        RenderOptions options;
        options.isovalues = {30.0};
        options.root_finder = finder;
        const KernelTracer octree(data.view(), Placement{}, options);
        const Camera cam = look_at({45, -35, 40}, {15, 15, 15}, {0, 0, 1}, 30, 64);
        const PinholeCamera pinhole(cam);
        const Vec3 light = unit({0.2, -0.9, 0.5});
        int tested = 0;
        for (int py = 0; py < cam.height; ++py)
            for (int px = 0; px < cam.width; ++px) {
                const Ray primary = pinhole.ray(px, py);
                const TraceHit h = octree(primary, true);
                // Well away from the terminator (n . l > 0.05): the trilinear sphere is convex at that scale.
                if (!h.is_hit() || vec_dot(h.normal, light) < 0.05) continue;
                ++tested;
                const TraceHit s = octree(shadow_ray(point_at(primary, h.t), light, kSecondaryOffsetVoxels, {}), false);
                EXPECT_FALSE(s.is_hit()) << "acne at pixel " << px << "," << py << " (t " << s.t << ")";
            }
        EXPECT_GT(tested, 500);
    }
}

TEST(AoSamples, ReproducibleStratifiedAndCosineWeighted) {
    EXPECT_EQ(pixel_seed(3, 4, {0, 0}), pixel_seed(3, 4, {0, 0}));
    EXPECT_NE(pixel_seed(3, 4, {0, 0}), pixel_seed(4, 3, {0, 0}));
    EXPECT_NE(pixel_seed(3, 4, {0, 0}), pixel_seed(3, 4, {0.25, -0.1}));
    EXPECT_EQ(reverse_bits(1u), 0x80000000u);
    EXPECT_EQ(reverse_bits(6u), 0x60000000u);
    const Vec3 n = unit({0.3, -0.5, 0.8});
    double mean_cos = 0;
    int count = 0;
    for (int px = 0; px < 64; ++px) {
        const uint32_t seed = pixel_seed(px, 7, {0, 0});
        for (int s = 0; s < 16; ++s) {
            const auto u = ao_sample(s, 16, seed);
            ASSERT_GE(u[0], 0.0);
            ASSERT_LT(u[0], 1.0);
            ASSERT_GE(u[1], 0.0);
            ASSERT_LT(u[1], 1.0);
            const Ray r = ao_ray({1, 2, 3}, n, u, 0.5, 4.0, {});
            EXPECT_NEAR(vec_dot(r.dir, r.dir), 1.0, 1e-12);
            const double c = vec_dot(r.dir, n);
            EXPECT_GE(c, 0.0) << "inside the hemisphere of the normal";
            mean_cos += c, ++count;
            EXPECT_EQ(r.t_min, 0.5);
            EXPECT_EQ(r.t_max, 4.0);
        }
    }
    // Cosine-weighted: E[cos] = 2/3 (uniform would give 1/2).
    EXPECT_NEAR(mean_cos / count, 2.0 / 3.0, 0.01);
    // The basis is orthonormal, also at the poles.
    for (const Vec3& m : {Vec3{0, 0, 1}, Vec3{0, 0, -1}, unit({1, 2, -3})}) {
        Vec3 t, b;
        orthonormal_basis(m, t, b);
        EXPECT_NEAR(vec_dot(t, b), 0, 1e-12);
        EXPECT_NEAR(vec_dot(t, m), 0, 1e-12);
        EXPECT_NEAR(vec_dot(b, m), 0, 1e-12);
        EXPECT_NEAR(vec_dot(t, t), 1, 1e-12);
    }
}

}  // namespace
}  // namespace octiso::test
