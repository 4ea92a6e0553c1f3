// LookShader (include/octiso/look.h) on whole frames: with every effect off it is shade_frame bit
// for bit (the two share the hit colour), shadows and AO only take light away and are the same
// on every run and thread count, opaque opacities change nothing and translucent ones let the
// surface behind show; a bad look is refused. The secondary rays themselves are checked against
// the dense reference in tests/render/secondary_test.cpp.
#include <gtest/gtest.h>

#include <cmath>

#include "octiso/any_octree.h"
#include "octiso/error.h"
#include "octiso/loaded_volume.h"
#include "octiso/look.h"
#include "octiso/shading.h"
#include "octiso/synthetic.h"

namespace octiso::test {
namespace {

class LookTest : public ::testing::Test {
protected:
    LookTest() : tree_(AnyOctree::build(synthetic_step("marschner-lobb", {33, 33, 33}, 0, ScalarType::f32), {})) {
        options_.isovalues = {0.3, 0.6};
        options_.want_colour = false, options_.want_depth = options_.want_normal = true;
        camera_ = frame_data_box(tree_.dims(), tree_.placement(), 64, 48);
        aovs_ = tree_.render(camera_, options_);
    }
    Frame shade(const Look& look, ShadingModel model = ShadingModel::kit, LookStats* stats = nullptr, int threads = 0,
                Shading s = {}) {
        RenderOptions o = options_;
        o.threads = threads;
        Frame f = aovs_;
        s.model = model;
        const LookStats st = LookShader(tree_, o, look, model).shade(camera_, s, f);
        if (stats) *stats = st;
        return f;
    }
    Frame plain(ShadingModel model = ShadingModel::kit) {
        Frame f = aovs_;
        Shading s;
        s.model = model;
        shade_frame(tree_, options_.isovalues, camera_, s, f);
        return f;
    }
    AnyOctree tree_;
    RenderOptions options_;
    Camera camera_;
    Frame aovs_;
};

TEST_F(LookTest, EverythingOffIsShadeFrameBitForBit) {
    for (ShadingModel model : {ShadingModel::kit, ShadingModel::headlight}) {
        Look off;
        off.opacity = {1.0, 1.0};   // given, but opaque: no compositing
        EXPECT_FALSE(off.active());
        EXPECT_EQ(shade(off, model).rgb, plain(model).rgb);
    }
}

TEST_F(LookTest, ShadowsAndOcclusionOnlyTakeLightAway) {
    Look look;
    look.shadows = true;
    LookStats stats;
    const Frame lit = plain(), shadowed = shade(look, ShadingModel::kit, &stats);
    int darker = 0;
    for (size_t i = 0; i < lit.rgb.size(); ++i) {
        ASSERT_LE(shadowed.rgb[i], lit.rgb[i]) << "channel " << i;
        darker += shadowed.rgb[i] < lit.rgb[i];
    }
    EXPECT_GT(darker, 100) << "the lobes shadow each other";
    EXPECT_GT(stats.shadow_rays, 300u);
    EXPECT_EQ(stats.ao_rays, 0u);
    EXPECT_EQ(stats.layer_rays, 0u);

    Look ao;
    ao.ao_samples = 8;
    const Frame occluded = shade(ao, ShadingModel::kit, &stats);
    int hits = 0;
    for (size_t i = 0; i < aovs_.depth.size(); ++i) hits += std::isfinite(aovs_.depth[i]);
    EXPECT_EQ(stats.ao_rays, uint64_t(8) * uint64_t(hits));
    darker = 0;
    for (size_t i = 0; i < lit.rgb.size(); ++i) {
        ASSERT_LE(occluded.rgb[i], lit.rgb[i]);
        darker += occluded.rgb[i] < lit.rgb[i];
    }
    EXPECT_GT(darker, 100);
}

TEST_F(LookTest, TheSameImageOnEveryRunAndThreadCount) {
    Look look;
    look.shadows = true;
    look.ao_samples = 5;
    look.opacity = {0.4};
    const Frame a = shade(look, ShadingModel::kit, nullptr, 0), b = shade(look, ShadingModel::kit, nullptr, 1),
                c = shade(look, ShadingModel::kit, nullptr, 2);
    EXPECT_EQ(a.rgb, b.rgb);
    EXPECT_EQ(a.rgb, c.rgb);
    // Shadow rays in packets (the default) or one by one: the same image.
    options_.traversal = Traversal::single;
    EXPECT_EQ(shade(look).rgb, a.rgb);
}

constexpr std::array<float, 3> kAlbedoOfInner{0.3f, 0.6f, 0.9f};

TEST_F(LookTest, TranslucentSurfacesShowWhatLiesBehind) {
    Look look;
    look.opacity = {0.35, 1.0};
    LookStats stats;
    const Frame seen = shade(look, ShadingModel::headlight, &stats), opaque = plain(ShadingModel::headlight);
    int changed = 0;
    for (size_t i = 0; i < seen.rgb.size(); ++i) changed += seen.rgb[i] != opaque.rgb[i];
    EXPECT_GT(changed, 300);
    EXPECT_GT(stats.layer_rays, 300u);
    // Wholly transparent outer surface and a background-coloured world: the inner one alone.
    look.opacity = {0.0, 1.0};
    RenderOptions inner = options_;
    inner.isovalues = {0.6};
    const Frame only_inner_aovs = tree_.render(camera_, inner);
    Frame only_inner = only_inner_aovs;
    Shading s;
    s.model = ShadingModel::headlight;
    s.colours = {kAlbedoOfInner};
    shade_frame(tree_, inner.isovalues, camera_, s, only_inner);
    Shading both;
    both.colours = {std::nullopt, kAlbedoOfInner};
    const Frame transparent = shade(look, ShadingModel::headlight, nullptr, 0, both);
    int worst = 0;
    for (size_t i = 0; i < transparent.rgb.size(); ++i) worst = std::max(worst, std::abs(int(transparent.rgb[i]) - int(only_inner.rgb[i])));
    EXPECT_LE(worst, 1) << "float AOV normals against the traced double ones";
}

TEST_F(LookTest, BadLooksAreRefused) {
    Look look;
    look.opacity = {0.5, 0.5, 0.5};
    EXPECT_THROW(validate_look(look, 2, ShadingModel::kit), Error);
    look.opacity = {1.5};
    EXPECT_THROW(validate_look(look, 2, ShadingModel::kit), Error);
    look = {};
    look.ao_samples = kMaxAoSamples + 1;
    EXPECT_THROW(validate_look(look, 2, ShadingModel::kit), Error);
    look = {};
    look.shadows = true;
    EXPECT_THROW(validate_look(look, 2, ShadingModel::headlight), Error);
    EXPECT_NO_THROW(validate_look(look, 2, ShadingModel::kit));
    look = {};
    look.ao_distance_voxels = 0;
    EXPECT_THROW(validate_look(look, 2, ShadingModel::kit), Error);
}

}  // namespace
}  // namespace octiso::test
