// Issue 11 from the command line: --traversal packets|single and --isa auto|baseline|avx2 draw the
// same bytes (colour and depth) as the defaults, say what ran in --json, and bad values exit 2
// with one line and no output.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "cli/cli_test_util.h"
#include "octiso/image.h"
#include "octiso/render.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

namespace fs = std::filesystem;

std::string bytes_of(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

class TraversalCli : public ::testing::Test {
protected:
    void SetUp() override {
        for (const char* tool : {"octiso-convert", "octiso-render"})
            if (!fs::exists(std::string(OCTISO_TOOLS_DIR) + "/" + tool)) { OCTISO_SKIP(tool << " not built"); }
        ASSERT_EQ(run_tool("octiso-convert", "--synthetic plume:40 -o '" + oct_ + "'").status, 0);
    }
    ToolRun render(const std::string& flags, const std::string& name) {
        return run_tool("octiso-render", "'" + oct_ + "' --iso 40.5 --size 45x37 " + flags + " -o '" + dir_.file(name) +
                                             ".png' --depth '" + dir_.file(name) + ".exr' --json");
    }
    ScratchDir dir_{"octiso_traversal_cli"};
    std::string oct_ = dir_.file("plume.oct");
};

TEST_F(TraversalCli, EveryTraversalAndIsaDrawsTheSameBytes) {
    const ToolRun base = render("", "default");
    ASSERT_EQ(base.status, 0) << base.err;
    EXPECT_NE(base.out.find("\"traversal\":\"packets\""), std::string::npos) << base.out;
    EXPECT_NE(base.out.find("\"embree\":false"), std::string::npos) << base.out;   // the default: direct
    std::vector<std::string> flags{"--traversal single", "--traversal packets", "--isa baseline", "--isa auto",
                                   "--traversal single --isa baseline --no-embree", "--embree",
                                   "--traversal single --embree"};
    if (cpu_has_avx2()) flags.push_back("--isa avx2 --embree");
    int i = 0;
    for (const std::string& f : flags) {
        const std::string name = "v" + std::to_string(i++);
        const ToolRun r = render(f, name);
        ASSERT_EQ(r.status, 0) << f << ": " << r.err;
        EXPECT_EQ(bytes_of(dir_.file(name) + ".png"), bytes_of(dir_.file("default.png"))) << f;
        const FloatImage depth = read_image(dir_.file(name) + ".exr"), base_depth = read_image(dir_.file("default.exr"));
        ASSERT_EQ(depth.pixels.size(), base_depth.pixels.size()) << f;
        EXPECT_EQ(0, std::memcmp(depth.pixels.data(), base_depth.pixels.data(), depth.pixels.size() * sizeof(float))) << f;
    }
    const ToolRun both = render("--embree --no-embree", "both");
    EXPECT_EQ(both.status, 2) << both.err;
    EXPECT_NE(both.err.find("--embree"), std::string::npos) << both.err;
    const ToolRun single = render("--traversal single --isa baseline", "named");
    EXPECT_NE(single.out.find("\"traversal\":\"single\""), std::string::npos) << single.out;
    EXPECT_NE(single.out.find("\"isa\":\"baseline\""), std::string::npos) << single.out;
}

TEST_F(TraversalCli, BadValuesAreRefusedWithOneLine) {
    for (const std::string f : {"--traversal simd", "--isa sse4", "--isa"}) {
        const ToolRun r = render(f, "bad");
        EXPECT_EQ(r.status, 2) << f;
        EXPECT_EQ(r.err_lines(), 1) << f << ": " << r.err;
        EXPECT_FALSE(fs::exists(dir_.file("bad.png"))) << f;
    }
}

}  // namespace
}  // namespace octiso::test
