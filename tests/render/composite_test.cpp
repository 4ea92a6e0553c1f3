// Front-to-back compositing (src/render/composite.h) against the dense exact reference: the layers
// along a composited ray are the reference's hits along the same ray, in order, clip included;
// nested spheres give their four crossings and the transmittance is the product of the crossed
// opacities; an opaque surface ends the list; the over operator on exact cases.
#include <cmath>

#include <gtest/gtest.h>

#include "render/composite.h"
#include "render/look_test_util.h"
#include "render/render_test_util.h"

namespace octiso::test {
namespace {

Vec3 unit(Vec3 d) { return vec_normalized(d); }

TEST(Layers, AreTheReferenceHitsAlongTheRayInOrder) {
    const auto v = make_field<float>(Field::MarschnerLobb, {27, 27, 27});
    const auto data = build_octree(v.view(), {});
    RenderOptions options;
    options.isovalues = {35.0, 70.0};
    options.root_finder = RootFinder::exact;
    const KernelTracer octree(data.view(), Placement{}, options);
    const ReferenceTracer<float> ref{v.view(), Placement{}, options.isovalues};
    const double alpha[] = {0.3, 0.6};
    const Opacities opacity{alpha};
    const Camera cam = look_at({50, -30, 45}, {13, 13, 13}, {0, 0, 1}, 40, 40);
    const PinholeCamera pinhole(cam);
    int multi = 0;
    for (int py = 0; py < cam.height; ++py)
        for (int px = 0; px < cam.width; ++px) {
            Ray ray = pinhole.ray(px, py);
            const ClipPlane cut[] = {{{0, 0, 1}, 20}};   // compositing honours the clip too
            clip_ray(cut, ray);
            Layers a, b;
            SecondaryCounters ca, cb;
            collect_layers(octree, ray, opacity, kSecondaryOffsetVoxels, a, ca);
            collect_layers(ref, ray, opacity, kSecondaryOffsetVoxels, b, cb);
            ASSERT_EQ(a.count, b.count) << "pixel " << px << "," << py;
            for (int k = 0; k < a.count; ++k) {
                EXPECT_NEAR(a.hit[k].t, b.hit[k].t, 1e-3) << "pixel " << px << "," << py << " layer " << k;
                EXPECT_EQ(a.hit[k].iso_index, b.hit[k].iso_index);
                if (k > 0) { EXPECT_GT(a.hit[k].t, a.hit[k - 1].t + kSecondaryOffsetVoxels * 0.999); }
                EXPECT_LE(a.hit[k].t, ray.t_max);
            }
            EXPECT_EQ(ca.layer_rays, cb.layer_rays);
            multi += a.count > 2;
        }
    EXPECT_GT(multi, 100) << "the view must see nested surfaces";
}

TEST(Layers, NestedSpheresComposeFrontToBack) {
    const auto v = nested_spheres();
    const auto data = build_octree(v.view(), {});
    RenderOptions options;
    options.isovalues = {30.0, 60.0};
    options.root_finder = RootFinder::exact;
    const KernelTracer octree(data.view(), Placement{}, options);
    // Straight through the centre: outer in, inner in, inner out, outer out.
    const Ray ray{{15.3, 15.2, -10}, unit({0.001, 0.0, 1.0})};
    const double alpha[] = {0.5, 0.25};
    Layers layers;
    SecondaryCounters counters;
    collect_layers(octree, ray, Opacities{alpha}, kSecondaryOffsetVoxels, layers, counters);
    ASSERT_EQ(layers.count, 4);
    const int order[] = {0, 1, 1, 0};
    for (int k = 0; k < 4; ++k) EXPECT_EQ(layers.hit[k].iso_index, order[k]) << "layer " << k;
    EXPECT_EQ(counters.layer_rays, 4u) << "three continuations and the one that found nothing more";
    const double pass = transmittance(octree, ray, Opacities{alpha}, kSecondaryOffsetVoxels, counters);
    EXPECT_DOUBLE_EQ(pass, 0.5 * 0.75 * 0.75 * 0.5);
    const double opaque[] = {1.0, 1.0};
    EXPECT_EQ(transmittance(octree, ray, Opacities{opaque}, kSecondaryOffsetVoxels, counters), 0.0);
    collect_layers(octree, ray, Opacities{opaque}, kSecondaryOffsetVoxels, layers, counters);
    EXPECT_EQ(layers.count, 1) << "an opaque surface ends the list";
    // The over operator: opaque layers give the first colour bit for bit.
    const std::array<double, 3> colour[] = {{0.2, 0.4, 0.6}, {1, 1, 1}};
    const double a1[] = {1.0, 1.0}, a2[] = {0.5, 1.0};
    EXPECT_EQ(composite_over(colour, a1, 2, {0, 0, 0}), colour[0]);
    const auto half = composite_over(colour, a2, 2, {0, 0, 0});
    EXPECT_DOUBLE_EQ(half[0], 0.5 * 0.2 + 0.5 * 1.0);
    const auto none = composite_over(colour, a2, 0, {0.1, 0.2, 0.3});
    EXPECT_DOUBLE_EQ(none[2], 0.3);
}

}  // namespace
}  // namespace octiso::test
