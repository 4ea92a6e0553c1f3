// Issue 17, item 6 (light that shows shape), end to end: the light kit is the default colour and
// changes no depth; --shading headlight is the Renderer's own image; --background and --colour
// reach the file; bad shading flags exit 2 and write nothing. (The headlight image is pinned by
// GoldenFrames; the kit's arithmetic against the Renderer by Shading.* in tests/api.)
#include <gtest/gtest.h>

#include <filesystem>

#include "cli/cli_test_util.h"
#include "cli/marschner_render_fixture.h"
#include "octiso/image.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

namespace fs = std::filesystem;

class ShadingCli : public MarschnerRenderCli {
protected:
    ShadingCli() : MarschnerRenderCli("octiso_shading_cli") {}
};

TEST_F(ShadingCli, TheKitIsTheDefaultAndChangesColourNotDepth) {
    const ToolRun kit = render("", "kit"), head = render("--shading headlight", "head"), named = render("--shading kit", "named");
    ASSERT_EQ(kit.status, 0) << kit.err;
    ASSERT_EQ(head.status, 0) << head.err;
    ASSERT_EQ(named.status, 0) << named.err;
    EXPECT_NE(kit.out.find("\"shading\":\"kit\""), std::string::npos);
    EXPECT_NE(head.out.find("\"shading\":\"headlight\""), std::string::npos);
    EXPECT_NE(kit.out.find("\"frame_seconds\""), std::string::npos);
    EXPECT_EQ(image("kit.exr").pixels, image("head.exr").pixels);
    EXPECT_EQ(image("kit.png").pixels, image("named.png").pixels);
    EXPECT_NE(image("kit.png").pixels, image("head.png").pixels);
}

TEST_F(ShadingCli, BackgroundAndColoursReachTheImage) {
    const ToolRun r = render("--shading headlight --background '#ffffff' --colour 1,0,0 --colour '#0000ff'", "c");
    ASSERT_EQ(r.status, 0) << r.err;
    const FloatImage c = image("c.png"), d = image("c.exr");
    int misses = 0, red = 0, blue = 0;
    for (size_t i = 0; i < d.pixels.size(); ++i) {
        const float* p = &c.pixels[3 * i];
        if (!std::isfinite(d.pixels[i])) {
            ++misses;
            EXPECT_EQ(p[0] + p[1] + p[2], 3.0f);
        } else {
            EXPECT_EQ(p[1], 0.0f) << "no green in either colour";
            red += p[0] > 0 && p[2] == 0;
            blue += p[2] > 0 && p[0] == 0;
        }
    }
    EXPECT_GT(misses, 0);
    EXPECT_GT(red, 0);
    EXPECT_GT(blue, 0);
}

TEST_F(ShadingCli, BadShadingFlagsExitTwoAndWriteNothing) {
    ScratchDir out("octiso_shading_bad");
    for (const char* bad : {"--shading phong", "--background 2,0,0", "--background '#12'", "--colour 1,0,0 --colour 0,1,0 --colour 0,0,1",
                                  "--colour blue"}) {
        SCOPED_TRACE(bad);
        const ToolRun r = run_tool("octiso-render", "'" + oct_ + "' --iso 0.3,0.6 --size 16x16 " + bad + " -o '" + out.file("x.png") + "'");
        EXPECT_EQ(r.status, 2);
        EXPECT_EQ(r.err_lines(), 1) << r.err;
        EXPECT_TRUE(out.entries().empty());
    }
}

}  // namespace
}  // namespace octiso::test
