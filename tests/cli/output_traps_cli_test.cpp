// Issue 17, item 3 (no traps), end to end: a %-name without --steps renders every step of a series
// (never a file literally named f_%02d.png); --depth into an 8-bit format is refused; a directory,
// a missing folder or a folder path through a file is refused before any work, naming the user's
// path (never a temporary), by all three tools (a directory as the file: usage, exit 2; a folder
// that cannot take the file: the environment, exit 1, as ConvertCli.UnwritableOutputLeavesNothing
// pins); --threads 0 means all cores.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "cli/cli_test_util.h"
#include "octiso/image.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

namespace fs = std::filesystem;

class OutputTrapsCli : public ::testing::Test {
protected:
    void SetUp() override {
        for (const char* tool : {"octiso-convert", "octiso-info", "octiso-render"})
            if (!fs::exists(std::string(OCTISO_TOOLS_DIR) + "/" + tool)) { OCTISO_SKIP(tool << " not built"); }
        ASSERT_EQ(run_tool("octiso-convert", "--synthetic plume-series:16,3 -o '" + series_ + "'").status, 0);
        ASSERT_EQ(run_tool("octiso-convert", "--synthetic sphere:12 -o '" + single_ + "'").status, 0);
    }
    ScratchDir in_{"octiso_traps_in"};
    std::string series_ = in_.file("series.oct"), single_ = in_.file("sphere.oct");
};

TEST_F(OutputTrapsCli, APercentNameWithoutStepsRendersEveryStep) {
    ScratchDir out("octiso_traps_out");
    const ToolRun r = run_tool("octiso-render", "'" + series_ + "' --iso 60 --size 16x16 -o '" + out.file("f_%02d.png") +
                                                    "' --depth '" + out.file("d_%d.exr") + "'");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(out.entries(), (std::vector<std::string>{"d_0.exr", "d_1.exr", "d_2.exr", "f_00.png", "f_01.png", "f_02.png"}));
    // A one-step file with a pattern gives its one step under the expanded name.
    ScratchDir one("octiso_traps_one");
    ASSERT_EQ(run_tool("octiso-render", "'" + single_ + "' --iso 5 --size 16x16 -o '" + one.file("s_%03d.png") + "'").status, 0);
    EXPECT_EQ(one.entries(), (std::vector<std::string>{"s_000.png"}));
}

TEST_F(OutputTrapsCli, AMultiStepFileWithoutAPatternSaysWhichStepItRendered) {
    ScratchDir out("octiso_traps_out");
    const ToolRun r = run_tool("octiso-render", "'" + series_ + "' --iso 60 --size 16x16 -o '" + out.file("one.png") + "'");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("has 3 steps; rendering step 0"), std::string::npos) << r.err;
    EXPECT_EQ(out.entries(), (std::vector<std::string>{"one.png"}));
}

TEST_F(OutputTrapsCli, DepthIntoAnEightBitFormatIsRefusedAndFloatFormatsKeepDistances) {
    ScratchDir out("octiso_traps_out");
    for (const char* name : {"d.png", "d.jpg"}) {
        const ToolRun r = run_tool("octiso-render", "'" + single_ + "' --iso 5 --size 16x16 --depth '" + out.file(name) + "'");
        EXPECT_EQ(r.status, 2) << name;
        EXPECT_EQ(r.err_lines(), 1) << r.err;
        EXPECT_NE(r.err.find("float format"), std::string::npos) << r.err;
    }
    EXPECT_TRUE(out.entries().empty());
    for (const char* name : {"d.exr", "d.tif"}) {
        ASSERT_EQ(run_tool("octiso-render", "'" + single_ + "' --iso 5 --size 16x16 --depth '" + out.file(name) + "'").status, 0);
        const FloatImage d = read_image(out.file(name));
        float hit_max = 0;
        for (const float t : d.pixels)
            if (std::isfinite(t)) hit_max = std::max(hit_max, t);
        EXPECT_GT(hit_max, 1.0f) << name << ": world distances, not a normalised 8-bit ramp";
    }
}

TEST_F(OutputTrapsCli, UnwritableOutputsAreRefusedBeforeWorkNamingTheUsersPath) {
    ScratchDir out("octiso_traps_out");
    fs::create_directory(out.file("adir"));
    std::ofstream(out.file("afile")) << "x";
    const std::string missing = out.file("no/such/folder/x"), through_file = out.file("afile") + "/x";
    struct Case {
        const char* tool;
        std::string args, named;
        int status = 1;
    };
    const std::vector<Case> cases = {
        {"octiso-render", "'" + single_ + "' --iso 5 -o '" + out.file("adir") + "'", out.file("adir"), 2},
        {"octiso-render", "'" + single_ + "' --iso 5 -o '" + missing + ".png'", missing + ".png"},
        {"octiso-render", "'" + single_ + "' --iso 5 -o '" + through_file + ".png'", through_file + ".png"},
        {"octiso-render", "'" + single_ + "' --iso 5 --depth '" + missing + ".exr'", missing + ".exr"},
        {"octiso-render", "'" + single_ + "' --iso 5 --normal '" + missing + ".exr'", missing + ".exr"},
        {"octiso-render", "'" + series_ + "' --iso 60 -o '" + missing + "_%02d.png'", missing + "_00.png"},
        {"octiso-convert", "--synthetic sphere:8 -o '" + out.file("adir") + "'", out.file("adir"), 2},
        {"octiso-convert", "--synthetic sphere:8 -o '" + missing + ".oct'", missing + ".oct"},
        {"octiso-convert", "--synthetic sphere:8 -o '" + through_file + ".oct'", through_file + ".oct"},
        {"octiso-info", "'" + single_ + "' --extract-raw '" + missing + ".raw'", missing + ".raw"},
        {"octiso-info", "'" + single_ + "' --extract-raw '" + out.file("adir") + "'", out.file("adir"), 2},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(std::string(c.tool) + " " + c.args);
        const ToolRun r = run_tool(c.tool, c.args);
        EXPECT_EQ(r.status, c.status);
        EXPECT_EQ(r.err_lines(), 1) << r.err;
        EXPECT_NE(r.err.find(c.named), std::string::npos) << r.err;
        EXPECT_EQ(r.err.find(".tmp-"), std::string::npos) << "names a temporary: " << r.err;
        EXPECT_EQ(out.entries(), (std::vector<std::string>{"adir", "afile"}));
        EXPECT_TRUE(fs::is_empty(out.file("adir")));
    }
}

TEST_F(OutputTrapsCli, ThreadsZeroMeansAllCores) {
    ScratchDir out("octiso_traps_out");
    const ToolRun r = run_tool("octiso-render", "'" + single_ + "' --iso 5 --size 16x16 --threads 0 --json -o '" + out.file("t.png") + "'");
    ASSERT_EQ(r.status, 0) << r.err;
    const ToolRun d = run_tool("octiso-render", "'" + single_ + "' --iso 5 --size 16x16 --json -o '" + out.file("d.png") + "'");
    ASSERT_EQ(d.status, 0);
    EXPECT_EQ(json_number(r.out, "threads"), json_number(d.out, "threads")) << "the default is all cores";
    EXPECT_EQ(run_tool("octiso-convert", "--synthetic sphere:8 --threads 0 -o '" + out.file("t.oct") + "'").status, 0);
    EXPECT_EQ(run_tool("octiso-render", "'" + single_ + "' --iso 5 --threads -1 -o '" + out.file("u.png") + "'").status, 2);
}

}  // namespace
}  // namespace octiso::test
