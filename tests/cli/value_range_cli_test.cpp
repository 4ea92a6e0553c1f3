// Issue 17, item 1 (value ranges everywhere), end to end through the built tools: octiso-info shows
// the exact min/max, percentiles, histogram, world box and centre; octiso-convert prints the range
// it stored and says when its output outgrew its input; octiso-render refuses an isovalue outside
// the data range (exit 2, one line naming the file and the range, no output); `ratio` is file/raw
// in both tools; a wrong --endian is visible at once in the printed range.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "cli/cli_test_util.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

namespace fs = std::filesystem;

class ValueRangeCli : public ::testing::Test {
protected:
    void SetUp() override {
        for (const char* tool : {"octiso-convert", "octiso-info", "octiso-render"})
            if (!fs::exists(std::string(OCTISO_TOOLS_DIR) + "/" + tool)) { OCTISO_SKIP(tool << " not built"); }
        // 5 x 4 x 3 u16 voxels 10, 11, ..., 69 (x fastest): min 10, max 69, median 39.
        std::vector<uint16_t> v(60);
        for (size_t i = 0; i < v.size(); ++i) v[i] = uint16_t(10 + i);
        write_raw(raw_, v);
        ASSERT_EQ(run_tool("octiso-convert", "'" + raw_ + "' --dims 5,4,3 --type u16 --spacing 0.5,1,2 --origin -1,0,10 -o '" +
                                                 oct_ + "'").status, 0);
    }
    ScratchDir dir_{"octiso_value_range"};
    std::string raw_ = dir_.file("ramp.raw"), oct_ = dir_.file("ramp.oct");
};

TEST_F(ValueRangeCli, InfoReportsExactRangePercentilesHistogramAndWorldBox) {
    const ToolRun r = run_tool("octiso-info", "'" + oct_ + "' --json --bins 6");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(json_numbers(r.out, "value_range"), (std::vector<double>{10, 69}));
    const std::string step0 = r.out.substr(r.out.find("\"per_step\""));
    EXPECT_EQ(json_number(step0, "min"), 10);
    EXPECT_EQ(json_number(step0, "max"), 69);
    EXPECT_EQ(json_number(r.out, "voxels"), 60);
    // Nearest rank over 10..69: p1 -> rank 1, p5 -> 3, p25 -> 15, p50 -> 30, p75 -> 45, p95 -> 57, p99 -> 60.
    EXPECT_EQ(json_number(r.out, "p1"), 10);
    EXPECT_EQ(json_number(r.out, "p5"), 12);
    EXPECT_EQ(json_number(r.out, "p25"), 24);
    EXPECT_EQ(json_number(r.out, "p50"), 39);
    EXPECT_EQ(json_number(r.out, "p75"), 54);
    EXPECT_EQ(json_number(r.out, "p95"), 66);
    EXPECT_EQ(json_number(r.out, "p99"), 69);
    // 6 bins of width 59/6 over [10, 69]: 10 values in each (10..19, 20..29, ... since 59/6 = 9.83).
    EXPECT_EQ(json_numbers(r.out, "counts"), (std::vector<double>{10, 10, 10, 10, 10, 10}));
    const std::vector<double> edges = json_numbers(r.out, "edges");
    ASSERT_EQ(edges.size(), 7u);
    EXPECT_EQ(edges.front(), 10);
    EXPECT_EQ(edges.back(), 69);
    // Voxel positions: x -1 .. -1 + 4 * 0.5, y 0 .. 3, z 10 .. 14.
    const size_t box = r.out.find("\"world_box\"");
    ASSERT_NE(box, std::string::npos);
    EXPECT_EQ(json_numbers(r.out.substr(box), "min"), (std::vector<double>{-1, 0, 10}));
    EXPECT_EQ(json_numbers(r.out.substr(box), "max"), (std::vector<double>{1, 3, 14}));
    EXPECT_EQ(json_numbers(r.out, "centre"), (std::vector<double>{0, 1.5, 12}));
    // ratio is file / raw, as in octiso-convert.
    EXPECT_DOUBLE_EQ(json_number(r.out, "ratio"), json_number(r.out, "file_bytes") / json_number(r.out, "raw_bytes"));

    const ToolRun text = run_tool("octiso-info", "'" + oct_ + "'");
    ASSERT_EQ(text.status, 0);
    EXPECT_NE(text.out.find("data range  10 .. 69"), std::string::npos) << text.out;
    EXPECT_NE(text.out.find("min 10, max 69 over 60 voxels"), std::string::npos) << text.out;
    EXPECT_NE(text.out.find("50%: 39"), std::string::npos) << text.out;
    EXPECT_NE(text.out.find("world box   -1, 0, 10 .. 1, 3, 14"), std::string::npos) << text.out;
    EXPECT_NE(text.out.find("centre      0, 1.5, 12"), std::string::npos) << text.out;
    EXPECT_NE(text.out.find("(file / raw)"), std::string::npos) << text.out;
}

TEST_F(ValueRangeCli, ConvertPrintsTheStoredRangeAndAWrongEndianShowsAtOnce) {
    const std::string big = dir_.file("big.oct");
    const ToolRun r = run_tool("octiso-convert", "'" + raw_ + "' --dims 5,4,3 --type u16 --endian big -o '" + big + "' --json");
    ASSERT_EQ(r.status, 0) << r.err;
    // 10 = 0x000a read big-endian is 0x0a00 = 2560; 69 = 0x0045 -> 0x4500 = 17664.
    EXPECT_EQ(json_numbers(r.out, "value_range"), (std::vector<double>{2560, 17664}));
    EXPECT_NE(r.err.find("values 2560 .. 17664"), std::string::npos) << r.err;
    EXPECT_DOUBLE_EQ(json_number(r.out, "ratio"), json_number(r.out, "file_bytes") / json_number(r.out, "input_bytes"));
}

TEST_F(ValueRangeCli, ConvertSaysWhenTheOctreeOutgrewItsInput) {
    const ToolRun noise = run_tool("octiso-convert", "--synthetic noise:16 -o '" + dir_.file("noise.oct") + "' --json");
    ASSERT_EQ(noise.status, 0) << noise.err;
    ASSERT_GT(json_number(noise.out, "file_bytes"), json_number(noise.out, "input_bytes"));
    EXPECT_NE(noise.out.find("\"larger_than_input\":true"), std::string::npos);
    EXPECT_NE(noise.err.find("larger than its input"), std::string::npos) << noise.err;
    EXPECT_NE(noise.err.find("--iso-range"), std::string::npos) << noise.err;
    EXPECT_NE(noise.err.find("--tolerance"), std::string::npos) << noise.err;

    const ToolRun sphere = run_tool("octiso-convert", "--synthetic plume:32 -o '" + dir_.file("plume.oct") + "' --json");
    ASSERT_EQ(sphere.status, 0);
    ASSERT_LT(json_number(sphere.out, "file_bytes"), json_number(sphere.out, "input_bytes"));
    EXPECT_NE(sphere.out.find("\"larger_than_input\":false"), std::string::npos);
    EXPECT_EQ(sphere.err.find("larger than its input"), std::string::npos) << sphere.err;
}

TEST_F(ValueRangeCli, RenderRefusesAnIsovalueOutsideTheDataRangeNamingIt) {
    for (const char* iso : {"9.5", "69.5", "-1e9", "40,70"}) {
        SCOPED_TRACE(iso);
        const std::string png = dir_.file("out.png");
        const ToolRun r = run_tool("octiso-render", "'" + oct_ + "' --iso " + iso + " --size 8x8 -o '" + png + "'");
        EXPECT_EQ(r.status, 2);
        EXPECT_EQ(r.err_lines(), 1) << r.err;
        EXPECT_NE(r.err.find(oct_), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("10 .. 69"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(png));
    }
    // The ends of the range are data values and are accepted.
    for (const char* iso : {"10", "69", "39.5"}) {
        SCOPED_TRACE(iso);
        EXPECT_EQ(run_tool("octiso-render", "'" + oct_ + "' --iso " + iso + " --size 8x8 -o '" + dir_.file("ok.png") + "'").status, 0);
    }
}

}  // namespace
}  // namespace octiso::test
