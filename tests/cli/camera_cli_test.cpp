// Issue 17, item 8 (cameras a user can drive), end to end: the camera octiso-render prints (text
// and --json) reproduces the image when pasted back as flags; --view iso is the default image;
// --view NAME looks along the data's axis; --azimuth/--elevation/--zoom orbit the data centre;
// --orbit N writes N frames, frame k the image of --azimuth start + 360 k / N; --spp 1 is the
// plain image and --spp N is deterministic; combinations without one meaning exit 2 and write nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "cli/cli_test_util.h"
#include "octiso/image.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

namespace fs = std::filesystem;

bool same_pixels(const std::string& a, const std::string& b) {
    const FloatImage x = read_image(a), y = read_image(b);
    return x.width == y.width && x.height == y.height && x.pixels == y.pixels;
}

/// The flags after "camera: " on stderr (up to the end of that line or a " (").
std::string printed_camera(const std::string& err) {
    const size_t at = err.find("camera: ");
    if (at == std::string::npos) return "";
    const size_t end = std::min(err.find('\n', at), err.find(" (", at));
    return err.substr(at + 8, end - at - 8);
}

class CameraCli : public ::testing::Test {
protected:
    void SetUp() override {
        for (const char* tool : {"octiso-convert", "octiso-render"})
            if (!fs::exists(std::string(OCTISO_TOOLS_DIR) + "/" + tool)) { OCTISO_SKIP(tool << " not built"); }
        // Anisotropic and off-origin, so that a camera ignoring the placement would show.
        ASSERT_EQ(run_tool("octiso-convert", "--synthetic plume:24 --spacing 1,1.5,0.75 --origin -5,3,8 -o '" + oct_ + "'").status, 0);
    }
    std::string render(const std::string& flags, const std::string& png, ToolRun* run = nullptr) {
        const ToolRun r = run_tool("octiso-render", "'" + oct_ + "' --iso 60 --size 40x30 " + flags + " -o '" + png + "' --json");
        EXPECT_EQ(r.status, 0) << flags << ": " << r.err;
        if (run) *run = r;
        return png;
    }
    ScratchDir dir_{"octiso_camera_cli"};
    std::string oct_ = dir_.file("plume.oct");
};

TEST_F(CameraCli, ThePrintedCameraReproducesTheImage) {
    for (const char* flags : {"", "--view left", "--azimuth 33 --elevation -20 --zoom 1.7", "--view top --zoom 2"}) {
        SCOPED_TRACE(flags);
        ToolRun r;
        const std::string a = render(flags, dir_.file("a.png"), &r);
        const std::string text = printed_camera(r.err);
        ASSERT_NE(text.find("--eye "), std::string::npos) << r.err;
        EXPECT_NE(text.find("--size 40x30"), std::string::npos) << text;
        const std::string b = dir_.file("b.png");   // the printed flags alone, --size included
        ASSERT_EQ(run_tool("octiso-render", "'" + oct_ + "' --iso 60 " + text + " -o '" + b + "'").status, 0);
        EXPECT_TRUE(same_pixels(a, b));
        // The JSON holds the same camera, to the last bit.
        const size_t at = text.find("--eye ") + 6;
        const std::string eye_text = text.substr(at, text.find(' ', at) - at);
        EXPECT_EQ(json_numbers("{\"eye\":[" + eye_text + "]}", "eye"), json_numbers(r.out, "eye"));
    }
}

TEST_F(CameraCli, ViewIsoIsTheDefaultAndNamedViewsLookAlongTheDataAxes) {
    EXPECT_TRUE(same_pixels(render("", dir_.file("d.png")), render("--view iso", dir_.file("i.png"))));
    // Centre of the voxel positions: x -5 .. 18, y 3 .. 37.5, z 8 .. 25.25.
    const std::vector<double> centre{6.5, 20.25, 16.625};
    struct Want {
        const char* view;
        int axis;
        double sign;
    };
    for (const Want w : {Want{"front", 1, -1}, {"back", 1, 1}, {"left", 0, -1}, {"right", 0, 1}, {"top", 2, 1}, {"bottom", 2, -1}}) {
        SCOPED_TRACE(w.view);
        ToolRun r;
        render(std::string("--view ") + w.view, dir_.file("v.png"), &r);
        EXPECT_EQ(json_numbers(r.out, "look"), centre);
        const std::vector<double> eye = json_numbers(r.out, "eye");
        ASSERT_EQ(eye.size(), 3u);
        for (int a = 0; a < 3; ++a) {
            if (a == w.axis) EXPECT_GT((eye[a] - centre[a]) * w.sign, 10.0);
            else EXPECT_EQ(eye[a], centre[a]);
        }
    }
}

TEST_F(CameraCli, AzimuthElevationAndZoomOrbitTheCentre) {
    ToolRun near, far;
    render("--azimuth 90 --elevation 0 --zoom 2", dir_.file("n.png"), &near);
    render("--azimuth 90 --elevation 0", dir_.file("f.png"), &far);
    const std::vector<double> e2 = json_numbers(near.out, "eye"), e1 = json_numbers(far.out, "eye");
    ASSERT_EQ(e1.size(), 3u);
    ASSERT_EQ(e2.size(), 3u);
    EXPECT_NEAR(e1[0], 6.5, 1e-12);   // azimuth 90: on the +y side of the centre
    EXPECT_NEAR(e1[2], 16.625, 1e-12);
    EXPECT_GT(e1[1], 20.25);
    EXPECT_NEAR(e2[1] - 20.25, (e1[1] - 20.25) / 2, 1e-9);
}

TEST_F(CameraCli, OrbitWritesNFramesEachTheImageOfItsAzimuth) {
    const ToolRun orbit = run_tool("octiso-render", "'" + oct_ + "' --iso 60 --size 40x30 --orbit 4 --azimuth 10 --elevation 30 -o '" +
                                                        dir_.file("o_%02d.png") + "' --json");
    ASSERT_EQ(orbit.status, 0) << orbit.err;
    for (int k = 0; k < 4; ++k) {
        SCOPED_TRACE(k);
        const std::string frame = dir_.file("o_0" + std::to_string(k) + ".png");
        ASSERT_TRUE(fs::exists(frame));
        EXPECT_TRUE(same_pixels(frame, render("--azimuth " + std::to_string(10 + 90 * k) + " --elevation 30", dir_.file("s.png"))));
    }
    EXPECT_FALSE(fs::exists(dir_.file("o_04.png")));
}

TEST_F(CameraCli, SppOneIsThePlainImageAndMoreSamplesAreDeterministic) {
    EXPECT_TRUE(same_pixels(render("", dir_.file("p.png")), render("--spp 1", dir_.file("s1.png"))));
    const std::string a = render("--spp 6", dir_.file("a.png")), b = render("--spp 6", dir_.file("b.png"));
    EXPECT_TRUE(same_pixels(a, b));
    EXPECT_FALSE(same_pixels(a, dir_.file("p.png"))) << "edges are averaged";
}

TEST_F(CameraCli, CombinationsWithoutOneMeaningAreRefused) {
    ScratchDir out("octiso_camera_bad");
    const std::string png = " -o '" + out.file("x.png") + "'", series = " -o '" + out.file("x_%d.png") + "'";
    for (const std::string& bad : {"--view sideways" + png, "--view front --azimuth 10" + png, "--view top --elevation 10" + png,
                                  "--orbit 3 --eye 1,2,3" + series, "--orbit 3 --view left" + series, "--orbit 3" + png,
                                  "--orbit 0" + series, "--elevation 90" + png, "--zoom 0" + png, "--zoom -2" + png, "--spp 0" + png,
                                  "--spp 257" + png, "--azimuth nan" + png, "--lod -1" + png, "--lod nan" + png,
                                  "--lod 2 --distribute data" + png}) {
        SCOPED_TRACE(bad);
        const ToolRun r = run_tool("octiso-render", "'" + oct_ + "' --iso 60 --size 16x16 " + bad);
        EXPECT_EQ(r.status, 2);
        EXPECT_EQ(r.err_lines(), 1) << r.err;
        EXPECT_TRUE(out.entries().empty());
    }
}

}  // namespace
}  // namespace octiso::test
