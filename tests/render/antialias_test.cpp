// Supersampling (include/octiso/antialias.h) and the pixel offset under it: an offset of (0, 0)
// leaves every ray of CONVENTIONS 2 bit for bit; pixel px shifted by +0.5 traces exactly the ray
// of pixel px+1 shifted by -0.5; render_antialiased's colour is the linear-light mean of the
// frames rendered at subpixel_offset(0 .. spp-1), its depth and normals those of the centre
// sample; spp 1 is a plain render; the pattern is fixed (same frame twice).
#include <cmath>

#include <gtest/gtest.h>

#include "octiso/antialias.h"
#include "octiso/any_octree.h"
#include "octiso/error.h"
#include "octiso/loaded_volume.h"
#include "octiso/synthetic.h"
#include "render/pinhole_camera.h"
#include "render/shade.h"

namespace octiso::test {
namespace {

AnyOctree sphere() { return AnyOctree::build(synthetic_step("sphere", {20, 20, 20}, 0), {}); }

RenderOptions all_outputs() {
    RenderOptions o;
    o.isovalues = {6.5};
    o.want_depth = o.want_normal = true;
    return o;
}

TEST(PixelOffset, ZeroIsTheConventionsRayAndHalfAPixelReachesTheNeighbour) {
    Camera c = frame_data_box({20, 20, 20}, {}, 17, 11);
    const PinholeCamera plain(c);
    c.pixel_offset = {0.0, 0.0};
    const PinholeCamera zero(c);
    c.pixel_offset = {0.5, 0.5};
    const PinholeCamera right(c);
    c.pixel_offset = {-0.5, -0.5};
    const PinholeCamera left(c);
    for (int py = 0; py + 1 < 11; ++py)
        for (int px = 0; px + 1 < 17; ++px) {
            EXPECT_EQ(plain.ray(px, py).dir, zero.ray(px, py).dir);
            EXPECT_EQ(right.ray(px, py).dir, left.ray(px + 1, py + 1).dir);
        }
}

TEST(SubpixelOffset, CentreFirstThenHaltonInsideThePixel) {
    EXPECT_EQ(subpixel_offset(0), (std::array<double, 2>{0, 0}));
    EXPECT_EQ(subpixel_offset(1), (std::array<double, 2>{0.0, 1.0 / 3.0 - 0.5}));
    EXPECT_EQ(subpixel_offset(2), (std::array<double, 2>{-0.25, 2.0 / 3.0 - 0.5}));
    for (int i = 0; i < kMaxSamplesPerPixel; ++i)
        for (const double d : subpixel_offset(i)) {
            EXPECT_GE(d, -0.5);
            EXPECT_LT(d, 0.5);
        }
}

TEST(Antialias, ColourIsTheLinearMeanOfTheShiftedFramesAndAovsStayTheCentres) {
    const AnyOctree tree = sphere();
    const Renderer renderer = tree.make_renderer(all_outputs());
    const Camera camera = frame_data_box(tree.dims(), tree.placement(), 33, 25);
    const int spp = 5;
    Frame aa;
    render_antialiased(renderer, camera, spp, aa);

    const Frame centre = renderer.render(camera);
    EXPECT_EQ(aa.depth, centre.depth);
    EXPECT_EQ(aa.normal, centre.normal);
    std::vector<float> sum(centre.rgb.size(), 0.0f);
    for (int s = 0; s < spp; ++s) {
        Camera shifted = camera;
        shifted.pixel_offset = subpixel_offset(s);
        const Frame f = renderer.render(shifted);
        for (size_t i = 0; i < sum.size(); ++i) {
            const double v = f.rgb[i] / 255.0;   // sRGB decoded by the formula, independently of the table
            sum[i] += float(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
        }
    }
    size_t differ = 0, smoothed = 0;
    for (size_t i = 0; i < sum.size(); ++i) {
        differ += aa.rgb[i] != SrgbTable::instance()(sum[i] * (1.0f / float(spp)));
        smoothed += aa.rgb[i] != centre.rgb[i];
    }
    EXPECT_EQ(differ, 0u);
    EXPECT_GT(smoothed, 0u) << "the silhouette must change";

    Frame again;
    render_antialiased(renderer, camera, spp, again);
    EXPECT_EQ(again.rgb, aa.rgb);
    Frame one;
    render_antialiased(renderer, camera, 1, one);
    EXPECT_EQ(one.rgb, centre.rgb);
    EXPECT_THROW(render_antialiased(renderer, camera, 0, one), Error);
    EXPECT_THROW(render_antialiased(renderer, camera, kMaxSamplesPerPixel + 1, one), Error);
}

}  // namespace
}  // namespace octiso::test
