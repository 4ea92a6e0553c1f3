// VTK lives in liboctiso_volumes.so, loaded on the first file that needs it (src/io/volume_codec.h):
// no tool loads VTK at start-up, raw and NIfTI inputs (read by octiso itself) convert without the
// module, the VTK formats go through the module the tools find themselves, and a tool that
// cannot load it says so in one line, writes nothing and exits 1 (the installation, not the input).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "cli/cli_test_util.h"

namespace octiso::test {
namespace {

const std::string kTools = OCTISO_TOOLS_DIR;
const std::string kMissing = "OCTISO_VOLUME_MODULE=/nonexistent/liboctiso_volumes.so";

std::string bytes_of(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(VolumeModule, NoToolLoadsVtkAtStartUp) {
    std::vector<std::string> tools;
    for (const char* tool : {"octiso-convert", "octiso-info", "octiso-render", "octiso-view"})
        if (std::filesystem::exists(kTools + "/" + tool)) tools.push_back(kTools + "/" + tool);
    ASSERT_GE(tools.size(), 3u) << "convert, info and render must be built next to the tests";
    for (const std::string& t : tools) {
        const std::string deps = shared_libraries_of(t);
        ASSERT_NE(deps.find("libc.so"), std::string::npos) << "ldd listed nothing for " << t;
        EXPECT_EQ(deps.find("libvtk"), std::string::npos) << t << " depends on VTK:\n" << deps;
    }
    // The module does, and sits where the build-tree tools look for it.
    const std::string deps = shared_libraries_of(kTools + "/liboctiso_volumes.so");
    EXPECT_NE(deps.find("libvtkIOXML"), std::string::npos) << deps;
}

class VolumeModuleCli : public ::testing::Test {
protected:
    void SetUp() override {
        std::vector<uint8_t> v(9 * 7 * 5);
        for (size_t i = 0; i < v.size(); ++i) v[i] = uint8_t(i * 29 % 251);
        write_raw(raw_, v);
    }
    ScratchDir dir_{"octiso_volume_module"};
    std::string raw_ = dir_.file("in.raw");
};

TEST_F(VolumeModuleCli, RawAndNiftiNeedNoModule) {
    const std::string oct = dir_.file("raw.oct");
    const ToolRun r = run_tool("octiso-convert", "'" + raw_ + "' --dims 9,7,5 --type u8 -o '" + oct + "'", kMissing);
    ASSERT_EQ(r.status, 0) << r.err;
    // A NIfTI file written through the module (found), then read without it: octiso's own reader.
    const std::string nii = dir_.file("x.nii.gz"), back = dir_.file("back.oct"), back_raw = dir_.file("back.raw");
    ASSERT_EQ(run_tool("octiso-info", "'" + oct + "' --extract '" + nii + "'").status, 0);
    const ToolRun c = run_tool("octiso-convert", "'" + nii + "' -o '" + back + "'", kMissing);
    ASSERT_EQ(c.status, 0) << c.err;
    ASSERT_EQ(run_tool("octiso-info", "'" + back + "' --extract-raw '" + back_raw + "'", kMissing).status, 0);
    EXPECT_EQ(bytes_of(back_raw), bytes_of(raw_));
}

TEST_F(VolumeModuleCli, VtiGoesThroughTheModuleItFindsItself) {
    const std::string oct = dir_.file("raw.oct"), vti = dir_.file("x.vti"), back = dir_.file("back.oct"),
                      back_raw = dir_.file("back.raw");
    ASSERT_EQ(run_tool("octiso-convert", "'" + raw_ + "' --dims 9,7,5 --type u8 -o '" + oct + "'").status, 0);
    ASSERT_EQ(run_tool("octiso-info", "'" + oct + "' --extract '" + vti + "'").status, 0);
    // The same module named explicitly.
    const ToolRun c = run_tool("octiso-convert", "'" + vti + "' -o '" + back + "'", "OCTISO_VOLUME_MODULE='" + kTools + "/liboctiso_volumes.so'");
    ASSERT_EQ(c.status, 0) << c.err;
    ASSERT_EQ(run_tool("octiso-info", "'" + back + "' --extract-raw '" + back_raw + "'").status, 0);
    EXPECT_EQ(bytes_of(back_raw), bytes_of(raw_));
}

TEST_F(VolumeModuleCli, AMissingModuleIsOneLineExitOneAndNoOutput) {
    const std::string oct = dir_.file("raw.oct"), vti = dir_.file("x.vti");
    ASSERT_EQ(run_tool("octiso-convert", "'" + raw_ + "' --dims 9,7,5 --type u8 -o '" + oct + "'").status, 0);
    ASSERT_EQ(run_tool("octiso-info", "'" + oct + "' --extract '" + vti + "'").status, 0);
    const std::vector<std::string> before{"in.raw", "raw.oct", "x.vti"};
    ASSERT_EQ(dir_.entries(), before);
    for (const std::string& args : {"octiso-convert '" + vti + "' -o '" + dir_.file("back.oct") + "'",
                                    "octiso-info '" + oct + "' --extract '" + dir_.file("y.vti") + "'",
                                    "octiso-info '" + oct + "' --extract '" + dir_.file("y.nii") + "'"}) {
        SCOPED_TRACE(args);
        const size_t space = args.find(' ');
        const ToolRun r = run_tool(args.substr(0, space), args.substr(space + 1), kMissing);
        EXPECT_EQ(r.status, 1) << r.err;
        EXPECT_EQ(r.err_lines(), 1) << r.err;
        EXPECT_NE(r.err.find("volume module liboctiso_volumes.so"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("/nonexistent/liboctiso_volumes.so"), std::string::npos) << r.err;
        EXPECT_EQ(dir_.entries(), before) << "nothing but the inputs may be left";
    }
}

}  // namespace
}  // namespace octiso::test
