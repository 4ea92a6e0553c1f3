// octiso-info --extract (issue 17, item 3: data back into the ecosystem), end to end: a step
// written as .vti, .nrrd, .nii or .nii.gz comes back through octiso-convert (VTK's readers) with the same type,
// dims, spacing, origin and every voxel byte for byte; .raw is --extract-raw; other extensions,
// --endian with a headed format, and both extract flags at once exit 2 and write nothing.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "cli/cli_test_util.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

namespace fs = std::filesystem;

std::string bytes_of(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class ExtractCli : public ::testing::Test {
protected:
    void SetUp() override {
        for (const char* tool : {"octiso-convert", "octiso-info"})
            if (!fs::exists(std::string(OCTISO_TOOLS_DIR) + "/" + tool)) { OCTISO_SKIP(tool << " not built"); }
        std::vector<int16_t> v(11 * 5 * 3);   // x > 9: VTK reads a shorter first NRRD axis as components
        for (size_t i = 0; i < v.size(); ++i) v[i] = int16_t(int(i * 37 % 101) - 50);
        write_raw(raw_, v);
        ASSERT_EQ(run_tool("octiso-convert", "'" + raw_ + "' --dims 11,5,3 --type i16 --spacing 0.5,1.25,2 --origin -3,4.5,7 -o '" + oct_ + "'").status, 0);
    }
    ScratchDir dir_{"octiso_extract_cli"};
    std::string raw_ = dir_.file("in.raw"), oct_ = dir_.file("in.oct");
};

TEST_F(ExtractCli, VtiAndNrrdComeBackWithTheirPlacementAndEveryVoxel) {
    for (const char* ext : {".vti", ".nrrd", ".nii", ".nii.gz"}) {
        SCOPED_TRACE(ext);
        const std::string out = dir_.file(std::string("x") + ext), back = dir_.file(std::string("back") + ext + ".oct");
        ASSERT_EQ(run_tool("octiso-info", "'" + oct_ + "' --extract '" + out + "'").status, 0);
        const ToolRun c = run_tool("octiso-convert", "'" + out + "' -o '" + back + "' --json");
        ASSERT_EQ(c.status, 0) << c.err;
        EXPECT_NE(c.out.find("\"type\":\"i16\""), std::string::npos) << c.out;
        EXPECT_EQ(json_numbers(c.out, "dims"), (std::vector<double>{11, 5, 3}));
        EXPECT_EQ(json_numbers(c.out, "spacing"), (std::vector<double>{0.5, 1.25, 2}));
        EXPECT_EQ(json_numbers(c.out, "origin"), (std::vector<double>{-3, 4.5, 7}));
        const std::string raw = dir_.file(std::string("back") + ext + ".raw");
        ASSERT_EQ(run_tool("octiso-info", "'" + back + "' --extract-raw '" + raw + "'").status, 0);
        EXPECT_EQ(bytes_of(raw), bytes_of(raw_));
    }
    ASSERT_EQ(run_tool("octiso-info", "'" + oct_ + "' --extract '" + dir_.file("r.raw") + "'").status, 0);
    EXPECT_EQ(bytes_of(dir_.file("r.raw")), bytes_of(raw_));
}

TEST_F(ExtractCli, UnknownFormatsAndContradictionsAreRefused) {
    ScratchDir out("octiso_extract_bad");
    for (const std::string& bad : {"--extract '" + out.file("x.hdr") + "'", "--extract '" + out.file("x.png") + "'",
                                   "--extract '" + out.file("x.nii") + "' --endian big",
                                   "--extract '" + out.file("x.vti") + "' --endian big",
                                   "--extract '" + out.file("x.vti") + "' --extract-raw '" + out.file("y.raw") + "'"}) {
        SCOPED_TRACE(bad);
        const ToolRun r = run_tool("octiso-info", "'" + oct_ + "' " + bad);
        EXPECT_EQ(r.status, 2);
        EXPECT_EQ(r.err_lines(), 1) << r.err;
        EXPECT_TRUE(out.entries().empty());
    }
}

}  // namespace
}  // namespace octiso::test
