// Issue 17, item 7 (what a ray tracer gives for free), end to end: --shadows, --ao N, --opacity
// and --clip reach the image and report their secondary rays in --json and the text report;
// shadows, AO and opacity change colour, never the depth AOV; --clip cuts the depth AOV exactly
// at the plane; without the flags the image is the one of before (GoldenFrames pins that too);
// bad values exit 2 with one line and write nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "cli/cli_test_util.h"
#include "cli/marschner_render_fixture.h"
#include "octiso/image.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

namespace fs = std::filesystem;

class LookCli : public MarschnerRenderCli {
protected:
    LookCli() : MarschnerRenderCli("octiso_look_cli") {}
};

TEST_F(LookCli, EachEffectChangesColourNotDepthAndReportsItsRays) {
    const ToolRun plain = render("", "plain");
    ASSERT_EQ(plain.status, 0) << plain.err;
    EXPECT_EQ(plain.out.find("\"secondary\""), std::string::npos) << "no look, no report of one";
    EXPECT_EQ(plain.err.find("look:"), std::string::npos);
    const double hits = json_number(plain.out, "hits");
    ASSERT_GT(hits, 100);
    const struct { const char* flags; const char* name; const char* counter; } cases[] = {
        {"--shadows", "shadows", "shadow_rays"}, {"--ao 4 --ao-distance 6", "ao", "ao_rays"}, {"--opacity 0.4", "opacity", "layer_rays"}};
    for (const auto& c : cases) {
        SCOPED_TRACE(c.flags);
        const ToolRun r = render(c.flags, c.name);
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_NE(r.out.find("\"secondary\""), std::string::npos) << r.out;
        EXPECT_GT(json_number(r.out, c.counter), 0);
        EXPECT_GE(json_number(r.out, "seconds"), 0);
        EXPECT_NE(r.err.find("look:"), std::string::npos) << r.err;
        EXPECT_NE(r.out.find("\"look\""), std::string::npos);
        EXPECT_EQ(image(std::string(c.name) + ".exr").pixels, image("plain.exr").pixels);
        EXPECT_NE(image(std::string(c.name) + ".png").pixels, image("plain.png").pixels);
    }
    EXPECT_EQ(json_number(render("--ao 4", "ao4").out, "ao_rays"), 4 * hits);
}

TEST_F(LookCli, AnImageIsTheSameOnEveryRunAndThreadCount) {
    const std::string flags = "--shadows --ao 6 --opacity 0.5 --spp 2 ";
    const ToolRun a = render(flags, "a"), b = render(flags + "--threads 1", "b");
    ASSERT_EQ(a.status, 0) << a.err;
    ASSERT_EQ(b.status, 0) << b.err;
    EXPECT_EQ(image("a.png").pixels, image("b.png").pixels);
}

TEST_F(LookCli, ClipCutsTheDepthAtThePlane) {
    // The data box is [0, 24]^3; keep z <= 12 with an eye above the data: every hit lies at or below z = 12.
    const std::string cam = "--eye 12,12,60 --look 12,12,0 --up 0,1,0 --fov 30 ";
    const ToolRun whole = render(cam, "whole"), cut = render(cam + "--clip 0,0,1,12", "cut");
    ASSERT_EQ(whole.status, 0) << whole.err;
    ASSERT_EQ(cut.status, 0) << cut.err;
    const FloatImage a = image("whole.exr"), b = image("cut.exr");
    int deeper = 0, hits = 0;
    for (size_t i = 0; i < b.pixels.size(); ++i) {
        if (!std::isfinite(b.pixels[i])) continue;
        ++hits;
        // Along the ray from z = 60 the plane z = 12 lies at t >= 48 (exactly 48 on the axis).
        EXPECT_GE(b.pixels[i], 48.0f * 0.9999f) << "pixel " << i;
        deeper += std::isfinite(a.pixels[i]) && b.pixels[i] > a.pixels[i];
    }
    EXPECT_GT(hits, 50);
    EXPECT_GT(deeper, 50) << "the cut exposes surfaces behind the removed ones";
    EXPECT_NE(cut.out.find("\"clip\":[[0,0,1,12]]"), std::string::npos) << cut.out;
    // A plane that keeps everything changes nothing, bit for bit.
    const ToolRun all = render(cam + "--clip 0,0,1,1000", "all");
    ASSERT_EQ(all.status, 0) << all.err;
    EXPECT_EQ(image("all.exr").pixels, a.pixels);
    EXPECT_EQ(image("all.png").pixels, image("whole.png").pixels);
}

TEST_F(LookCli, ClipCapDrawsTheCutFaceAtThePlane) {
    // As above, seen from above, cut at z <= 16 (at z = 12 the Marschner-Lobb field is 0.4 or more
    // everywhere, at 16 it spans 0.2 .. 0.4): with --clip-cap the cut face is drawn where the field
    // there is inside an isovalue (value >= 0.3), nearer than what the open cut shows, never above the plane.
    const std::string cam = "--eye 12,12,60 --look 12,12,0 --up 0,1,0 --fov 30 --clip 0,0,1,16 ";
    const ToolRun cut = render(cam, "open"), capped = render(cam + "--clip-cap", "capped");
    ASSERT_EQ(cut.status, 0) << cut.err;
    ASSERT_EQ(capped.status, 0) << capped.err;
    EXPECT_NE(capped.out.find("\"clip_cap\":true"), std::string::npos) << capped.out;
    const FloatImage a = image("open.exr"), b = image("capped.exr");
    int nearer = 0, same = 0;
    for (size_t i = 0; i < b.pixels.size(); ++i) {
        if (!std::isfinite(b.pixels[i])) {
            EXPECT_FALSE(std::isfinite(a.pixels[i])) << "a cap never removes a hit: pixel " << i;
            continue;
        }
        EXPECT_GE(b.pixels[i], 44.0f * 0.9999f) << "pixel " << i;   // the plane lies at t >= 44
        if (b.pixels[i] == a.pixels[i]) ++same;
        else {
            EXPECT_TRUE(!std::isfinite(a.pixels[i]) || b.pixels[i] < a.pixels[i]) << "pixel " << i;
            ++nearer;
        }
    }
    EXPECT_GT(nearer, 50) << "the cap covers the inside of the cut";
    EXPECT_GT(same, 50) << "outside the surfaces the cut stays open";
    EXPECT_NE(image("capped.png").pixels, image("open.png").pixels);
    // Refused: a cap without a plane, and with translucent layers.
    for (const char* bad : {"--clip-cap", "--clip 0,0,1,12 --clip-cap --opacity 0.5"}) {
        SCOPED_TRACE(bad);
        const ToolRun r = run_tool("octiso-render", "'" + oct_ + "' --iso 0.3,0.6 --size 16x16 " + std::string(bad) + " -o '" +
                                                        dir_.file("bad.png") + "'");
        EXPECT_EQ(r.status, 2) << r.err;
        EXPECT_EQ(r.err_lines(), 1) << r.err;
        EXPECT_NE(r.err.find("--clip-cap"), std::string::npos) << r.err;
        EXPECT_FALSE(std::filesystem::exists(dir_.file("bad.png")));
    }
}

TEST_F(LookCli, BadLookFlagsExitTwoAndWriteNothing) {
    ScratchDir out("octiso_look_bad");
    for (const char* bad : {"--opacity 1.5", "--opacity x", "--opacity 0.5 --opacity 0.5 --opacity 0.5", "--ao -1", "--ao 257",
                            "--ao-distance 0", "--clip 0,0,0,1", "--clip 1,2,3", "--clip 1,0,0,nan", "--shadows --shading headlight",
                            "--ao 2 --shading headlight"}) {
        SCOPED_TRACE(bad);
        const ToolRun r = run_tool("octiso-render", "'" + oct_ + "' --iso 0.3,0.6 --size 16x16 " + std::string(bad) + " -o '" + out.file("x.png") + "'");
        EXPECT_EQ(r.status, 2) << r.err;
        EXPECT_EQ(r.err_lines(), 1) << r.err;
        EXPECT_TRUE(out.entries().empty());
    }
}

}  // namespace
}  // namespace octiso::test
