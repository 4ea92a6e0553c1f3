// OpenImageIO lives in liboctiso_images.so, loaded on the first image (src/io/image_codec.h):
// nothing octiso builds may depend on it at start-up, the tools still write images through it, and
// a tool that cannot load it says so in one line, writes nothing and exits 1 (not bad input). The
// 8-bit colour PNG is written by libpng and float OpenEXR by OpenEXR without the module
// (src/io/png_writer.h, exr_writer.h): a render that writes only those never loads it.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "cli/cli_test_util.h"
#include "octiso/image.h"

namespace octiso::test {
namespace {

const std::string kTools = OCTISO_TOOLS_DIR;

/// Every executable octiso builds beside the tests, and this test binary.
std::vector<std::string> built_programs() {
    std::vector<std::string> out{"/proc/self/exe"};
    for (const char* tool : {"octiso-convert", "octiso-info", "octiso-render", "octiso-view", "octiso-bench", "octiso-probe"})
        if (std::filesystem::exists(kTools + "/" + tool)) out.push_back(kTools + "/" + tool);
    return out;
}

TEST(ImageModule, NoProgramLoadsOpenImageIOAtStartUp) {
    const std::vector<std::string> programs = built_programs();
    ASSERT_GE(programs.size(), 4u) << "convert, info and render must be built next to the tests";
    for (const std::string& p : programs) {
        const std::string deps = shared_libraries_of(p == "/proc/self/exe" ? std::filesystem::read_symlink(p).string() : p);
        ASSERT_NE(deps.find("libc.so"), std::string::npos) << "ldd listed nothing for " << p;
        EXPECT_EQ(deps.find("libOpenImageIO"), std::string::npos) << p << " depends on OpenImageIO:\n" << deps;
    }
    // The module does, and sits where the build-tree tools look for it.
    const std::string deps = shared_libraries_of(kTools + "/liboctiso_images.so");
    EXPECT_NE(deps.find("libOpenImageIO"), std::string::npos) << deps;
}

class ImageModuleCli : public ::testing::Test {
protected:
    void SetUp() override {
        oct_ = dir_.file("plume.oct");
        ASSERT_EQ(run_tool("octiso-convert", "--synthetic plume:24 -o '" + oct_ + "' >/dev/null").status, 0);
    }
    ScratchDir dir_{"octiso_image_module"};
    std::string oct_;
};

TEST_F(ImageModuleCli, RenderWritesImagesThroughTheModuleItFindsItself) {
    const std::string png = dir_.file("frame.png"), exr = dir_.file("depth.exr");
    const ToolRun r = run_tool("octiso-render", "'" + oct_ + "' --iso 40.5 --size 40x30 -o '" + png + "' --depth '" + exr + "'");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(std::filesystem::exists(png));
    EXPECT_TRUE(std::filesystem::exists(exr));
    // The same module named explicitly.
    const ToolRun forced = run_tool("octiso-render", "'" + oct_ + "' --iso 40.5 --size 40x30 -o '" + png + "'",
                                    "OCTISO_IMAGE_MODULE='" + kTools + "/liboctiso_images.so'");
    EXPECT_EQ(forced.status, 0) << forced.err;
}

TEST_F(ImageModuleCli, AColourPngAndExrAovsNeedNoModule) {
    const std::string png = dir_.file("frame.png"), depth = dir_.file("depth.exr"), normal = dir_.file("normal.exr");
    const ToolRun r = run_tool("octiso-render", "'" + oct_ + "' --iso 40.5 --size 40x30 -o '" + png + "' --depth '" + depth +
                                                    "' --normal '" + normal + "'",
                               "OCTISO_IMAGE_MODULE=/nonexistent/liboctiso_images.so");
    ASSERT_EQ(r.status, 0) << r.err;
    // The same pixels as OpenImageIO's own writers give the same frame (TIFF: 8-bit colour, float AOVs).
    const std::string tif = dir_.file("frame.tif"), depth_tif = dir_.file("depth.tif"), normal_tif = dir_.file("normal.tif");
    ASSERT_EQ(run_tool("octiso-render", "'" + oct_ + "' --iso 40.5 --size 40x30 -o '" + tif + "' --depth '" + depth_tif +
                                            "' --normal '" + normal_tif + "'")
                  .status,
              0);
    const FloatImage a = read_image(png), b = read_image(tif);
    EXPECT_EQ(a.width, 40);
    EXPECT_EQ(a.channels, 3);
    EXPECT_EQ(a.pixels, b.pixels);
    EXPECT_EQ(read_image(depth).pixels, read_image(depth_tif).pixels);
    EXPECT_EQ(read_image(normal).pixels, read_image(normal_tif).pixels);
}

TEST_F(ImageModuleCli, AMissingModuleIsOneLineExitOneAndNoOutput) {
    // A PNG colour image with a TIFF depth image beside it: the TIFF needs the module.
    const std::string png = dir_.file("frame.png"), exr = dir_.file("depth.tif");
    const ToolRun r = run_tool("octiso-render", "'" + oct_ + "' --iso 40.5 --size 40x30 -o '" + png + "' --depth '" + exr + "'",
                               "OCTISO_IMAGE_MODULE=/nonexistent/liboctiso_images.so");
    EXPECT_EQ(r.status, 1) << r.err;   // the installation, not the input (ErrorKind::Other)
    EXPECT_EQ(r.err_lines(), 1) << r.err;
    EXPECT_NE(r.err.find("image module liboctiso_images.so"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("/nonexistent/liboctiso_images.so"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(png));
    EXPECT_FALSE(std::filesystem::exists(exr));
    EXPECT_EQ(dir_.entries(), std::vector<std::string>{"plume.oct"}) << "nothing but the input may be left";
    // An 8-bit normal image in PNG goes through the module too (OpenImageIO maps the floats), so
    // it is refused before the colour PNG, which would not need it, is written.
    const std::string normal = dir_.file("normal.png");
    const ToolRun n = run_tool("octiso-render", "'" + oct_ + "' --iso 40.5 --size 40x30 -o '" + png + "' --normal '" + normal + "'",
                               "OCTISO_IMAGE_MODULE=/nonexistent/liboctiso_images.so");
    EXPECT_EQ(n.status, 1) << n.err;
    EXPECT_EQ(n.err_lines(), 1) << n.err;
    EXPECT_EQ(dir_.entries(), std::vector<std::string>{"plume.oct"}) << "nothing but the input may be left";
}

}  // namespace
}  // namespace octiso::test
