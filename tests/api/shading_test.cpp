// Deferred shading (include/octiso/shading.h) against the Renderer's own colour: the headlight
// model from the AOVs gives the Renderer's image within one 8-bit level (the AOVs hold the normal
// as float, the Renderer shades with the double), for one isovalue and for three, which also
// checks that the isovalue read back from the field at each hit is the one the tracer hit;
// misses take the background exactly; a --colour replaces the albedo; the light kit spreads the
// foreground's luminance wider than the headlight; parse_colour reads both spellings.
#include <gtest/gtest.h>

#include <cmath>

#include "octiso/any_octree.h"
#include "octiso/error.h"
#include "octiso/loaded_volume.h"
#include "octiso/shading.h"
#include "octiso/synthetic.h"

namespace octiso::test {
namespace {

struct Rendered {
    Frame own, aovs;
    Camera camera;
};

Rendered render_both(const AnyOctree& tree, const std::vector<double>& isos) {
    RenderOptions o;
    o.isovalues = isos;
    Rendered r;
    r.camera = frame_data_box(tree.dims(), tree.placement(), 64, 48);
    r.own = tree.render(r.camera, o);
    o.want_colour = false, o.want_depth = o.want_normal = true;
    r.aovs = tree.render(r.camera, o);
    return r;
}

double luminance_spread(const Frame& f) {
    double sum = 0, sum2 = 0;
    int n = 0;
    for (size_t i = 0; i < f.depth.size(); ++i)
        if (std::isfinite(f.depth[i])) {
            const double y = 0.2126 * f.rgb[3 * i] + 0.7152 * f.rgb[3 * i + 1] + 0.0722 * f.rgb[3 * i + 2];
            sum += y, sum2 += y * y, ++n;
        }
    return std::sqrt(std::max(0.0, sum2 / n - (sum / n) * (sum / n)));
}

TEST(Shading, HeadlightFromTheAovsIsTheRenderersImageWithinOneLevel) {
    const AnyOctree tree = AnyOctree::build(synthetic_step("marschner-lobb", {33, 33, 33}, 0, ScalarType::f32), {});
    for (const std::vector<double>& isos : {std::vector<double>{0.5}, std::vector<double>{0.2, 0.5, 0.8}}) {
        SCOPED_TRACE(isos.size());
        Rendered r = render_both(tree, isos);
        Shading s;
        s.model = ShadingModel::headlight;
        shade_frame(tree, isos, r.camera, s, r.aovs);
        ASSERT_EQ(r.aovs.rgb.size(), r.own.rgb.size());
        int worst = 0;
        for (size_t i = 0; i < r.own.rgb.size(); ++i) worst = std::max(worst, std::abs(int(r.aovs.rgb[i]) - int(r.own.rgb[i])));
        EXPECT_LE(worst, 1);
    }
}

TEST(Shading, MissesTakeTheBackgroundAndAColourReplacesTheAlbedo) {
    const AnyOctree tree = AnyOctree::build(synthetic_step("sphere", {24, 24, 24}, 0), {});
    Rendered r = render_both(tree, {6.5});
    Shading s;
    s.model = ShadingModel::headlight;
    s.background = parse_colour("#ffffff", "--background");
    s.colours = {parse_colour("1,0,0", "--colour")};
    shade_frame(tree, {6.5}, r.camera, s, r.aovs);
    int hits = 0, misses = 0;
    for (size_t i = 0; i < r.aovs.depth.size(); ++i) {
        const uint8_t* c = &r.aovs.rgb[3 * i];
        if (std::isfinite(r.aovs.depth[i])) {
            ++hits;
            EXPECT_GT(c[0], 0);
            EXPECT_EQ(c[1], 0);
            EXPECT_EQ(c[2], 0);
        } else {
            ++misses;
            EXPECT_EQ(c[0], 255);
            EXPECT_EQ(c[1], 255);
            EXPECT_EQ(c[2], 255);
        }
    }
    EXPECT_GT(hits, 0);
    EXPECT_GT(misses, 0);
}

TEST(Shading, TheLightKitSpreadsTheForegroundWiderThanTheHeadlight) {
    const AnyOctree tree = AnyOctree::build(synthetic_step("marschner-lobb", {41, 41, 41}, 0, ScalarType::f32), {});
    Rendered r = render_both(tree, {0.5});
    Shading kit;
    shade_frame(tree, {0.5}, r.camera, kit, r.aovs);
    EXPECT_GT(luminance_spread(r.aovs), 1.2 * luminance_spread(r.own));
}

TEST(Shading, RowsInParallelGiveTheSameFrameOnAnyThreadCount) {
    // Issue 12: the pass runs rows in parallel; each pixel reads only its own AOVs.
    const AnyOctree tree = AnyOctree::build(synthetic_step("marschner-lobb", {33, 33, 33}, 0, ScalarType::f32), {});
    const std::vector<double> isos{0.2, 0.5, 0.8};
    Rendered r = render_both(tree, isos);
    Frame serial = r.aovs;
    Shading s;
    s.threads = 1;
    shade_frame(tree, isos, r.camera, s, serial);
    for (int threads : {0, 2, 3}) {
        Frame f = r.aovs;
        s.threads = threads;
        shade_frame(tree, isos, r.camera, s, f);
        EXPECT_EQ(f.rgb, serial.rgb) << threads << " threads";
    }
}

TEST(Shading, MissingAovsAreAnError) {
    const AnyOctree tree = AnyOctree::build(synthetic_step("sphere", {8, 8, 8}, 0), {});
    Rendered r = render_both(tree, {3});
    EXPECT_THROW(shade_frame(tree, {3}, r.camera, {}, r.own), Error);
}

TEST(ParseColour, HexAndDecimalSrgbBecomeLinear) {
    EXPECT_EQ(parse_colour("#ff0000", "--colour"), (std::array<float, 3>{1, 0, 0}));
    EXPECT_EQ(parse_colour("1,0,1", "--colour"), (std::array<float, 3>{1, 0, 1}));
    const auto grey = parse_colour("0.5,0.5,0.5", "--colour");
    EXPECT_NEAR(grey[0], 0.21404114, 1e-6);   // the sRGB curve at 0.5
    for (const char* bad : {"", "1,2", "1,0,0,0", "#12345", "#12345g", "1.5,0,0", "-0.1,0,0", "a,b,c", "1,,0", "red"})
        EXPECT_THROW(parse_colour(bad, "--colour"), Error) << bad;
}

}  // namespace
}  // namespace octiso::test
