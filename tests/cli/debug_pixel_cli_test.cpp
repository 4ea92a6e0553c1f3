// octiso-render --debug-pixel X,Y: prints the path of that pixel's ray to stdout and exits 0
// without writing an image; a pixel outside the image, or not X,Y, exits 2 with one stderr line.
// Skipped when the tools are not built next to the tests.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "test_util/run_shell.h"
#include "test_util/skip.h"
#include "test_util/scratch_dir.h"

namespace octiso::test {
namespace {

namespace fs = std::filesystem;
const std::string kTools = OCTISO_TOOLS_DIR;

class DebugPixelCli : public ::testing::Test {
protected:
    void SetUp() override {
        if (!fs::exists(kTools + "/octiso-render") || !fs::exists(kTools + "/octiso-convert")) {
            OCTISO_SKIP("tools not built");
        }
        ASSERT_EQ(run("'" + kTools + "/octiso-convert' --synthetic sphere:24 -o '" + oct_ + "'"), 0);
    }
    int run(const std::string& command, std::string* out = nullptr, std::string* err = nullptr) {
        const std::string err_file = dir_.file("stderr");
        const int status = run_shell(command + " 2>'" + err_file + "'", out);
        if (err) run_shell("cat '" + err_file + "'", err);
        return status;
    }
    int render(const std::string& args, std::string* out, std::string* err = nullptr) {
        return run("'" + kTools + "/octiso-render' '" + oct_ + "' " + args, out, err);
    }
    ScratchDir dir_{"octiso_debug_pixel_cli"};
    std::string oct_ = dir_.file("sphere.oct");
};

TEST_F(DebugPixelCli, PrintsThePathOfOnePixelAndWritesNoImage) {
    std::string out;
    ASSERT_EQ(render("--iso 5 --size 40x30 --debug-pixel 20,15", &out), 0);
    EXPECT_EQ(out.rfind("pixel (20,15) of 40x30", 0), 0u) << out;
    EXPECT_NE(out.find("data box: t ["), std::string::npos) << out;
    EXPECT_NE(out.find("node depth 0 #0"), std::string::npos) << out;
    EXPECT_NE(out.find("\nhit t "), std::string::npos) << "the centre pixel sees the sphere:\n" << out;
    for (const auto& entry : fs::directory_iterator(dir_.path()))
        EXPECT_NE(entry.path().extension(), ".png") << "no image without -o";
}

TEST_F(DebugPixelCli, PixelOutsideTheImageOrMalformedExitsTwoWithOneLine) {
    for (const std::string pixel : {"40,0", "0,30", "-1,2", "7", "a,b"}) {
        std::string out, err;
        EXPECT_EQ(render("--iso 5 --size 40x30 --debug-pixel " + pixel, &out, &err), 2) << pixel;
        EXPECT_TRUE(out.empty()) << pixel << ": " << out;
        EXPECT_NE(err.find("--debug-pixel"), std::string::npos) << pixel << ": " << err;
        EXPECT_EQ(err.find('\n'), err.size() - 1) << "one line: " << err;
    }
}

}  // namespace
}  // namespace octiso::test
