// octiso-render end to end (CONVENTIONS 2-3): the image and AOV files it writes, --json as exactly
// one object on stdout, and exit status 2 with no output file left for every bad input or usage.
// Skipped when the tools are not built next to the tests.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "format/oct_test_util.h"
#include "test_util/run_shell.h"
#include "octiso/image.h"
#include "test_util/scratch_dir.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

namespace fs = std::filesystem;
const std::string kTools = OCTISO_TOOLS_DIR;

struct TempDir : ScratchDir {
    TempDir() : ScratchDir("octiso_render_cli") {}
};

int run(const std::string& tool, const std::string& args, std::string* out = nullptr, std::string* err = nullptr) {
    ScratchDir stderr_dir("octiso_render_cli_err");
    const std::string err_file = stderr_dir.file("stderr");
    const int status = run_shell("'" + kTools + "/" + tool + "' " + args + " 2>'" + err_file + "'", out);
    if (err) run_shell("cat '" + err_file + "'", err);
    return status;
}

class RenderCli : public ::testing::Test {
protected:
    void SetUp() override {
        if (!fs::exists(kTools + "/octiso-render") || !fs::exists(kTools + "/octiso-convert")) {
            OCTISO_SKIP("tools not built");
        }
        ASSERT_EQ(run("octiso-convert", "--synthetic sphere:24 -o '" + oct_ + "'"), 0);
        ASSERT_EQ(run("octiso-convert", "--synthetic marschner-lobb:20 --iso-range 0.3,0.7 -o '" + ranged_ + "'"), 0);
    }
    TempDir inputs_;
    std::string oct_ = inputs_.file("sphere.oct"), ranged_ = inputs_.file("ml.oct");
};

TEST_F(RenderCli, WritesColourDepthAndNormalImagesAndOneJsonObject) {
    TempDir out;
    std::string json;
    const std::string args = "'" + oct_ + "' --iso 5 --size 40x30 -o '" + out.file("c.png") + "' --depth '" +
                             out.file("d.exr") + "' --normal '" + out.file("n.exr") + "' --json";
    ASSERT_EQ(run("octiso-render", args, &json), 0);
    // Exactly one JSON object on stdout.
    const size_t first = json.find_first_not_of(" \n"), last = json.find_last_not_of(" \n");
    ASSERT_NE(first, std::string::npos);
    EXPECT_EQ(json[first], '{');
    EXPECT_EQ(json[last], '}');
    EXPECT_NE(json.find("\"seconds\""), std::string::npos);
    EXPECT_NE(json.find("\"mrays_per_second\""), std::string::npos);
    EXPECT_NE(json.find("\"hits\""), std::string::npos);
    // Issue 12: each frame says where its time went, and the phases add up to the frame.
    const nlohmann::json report = nlohmann::json::parse(json);
    const nlohmann::json& frame = report.at("frames").at(0);
    const nlohmann::json& phases = frame.at("phases");
    EXPECT_EQ(phases.at("trace").get<double>(), frame.at("seconds").get<double>());
    for (const char* key : {"trace", "trace_busy", "shade", "other", "write", "step_setup"})
        EXPECT_GE(phases.at(key).get<double>(), 0.0) << key;
    EXPECT_GT(phases.at("trace_busy").get<double>(), 0.0);
    EXPECT_GT(phases.at("write").get<double>(), 0.0) << "three images were written";
    EXPECT_GT(phases.at("step_setup").get<double>(), 0.0) << "the first frame of step 0 made its Renderer";
    EXPECT_GT(phases.at("utilisation").get<double>(), 0.0);
    EXPECT_LE(phases.at("utilisation").get<double>(), 1.0 + 1e-6);
    EXPECT_LE(phases.at("trace").get<double>() + phases.at("shade").get<double>() + phases.at("other").get<double>(),
              frame.at("frame_seconds").get<double>() + 1e-9);

    const FloatImage c = read_image(out.file("c.png"));
    EXPECT_EQ(c.width, 40);
    EXPECT_EQ(c.height, 30);
    EXPECT_EQ(c.channels, 3);
    const FloatImage d = read_image(out.file("d.exr"));
    ASSERT_EQ(d.channels, 1);
    EXPECT_EQ(d.channel_names[0], "Z");
    const FloatImage n = read_image(out.file("n.exr"));
    ASSERT_EQ(n.channels, 3);
    int hits = 0, misses = 0;
    for (int i = 0; i < d.width * d.height; ++i) {
        if (std::isfinite(d.pixels[size_t(i)])) {
            ++hits;
            const float* v = &n.pixels[3 * size_t(i)];
            EXPECT_NEAR(std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]), 1.0, 1e-5) << "hit normals are unit";
        } else {
            ++misses;
            EXPECT_EQ(n.pixels[3 * size_t(i)], 0.0f);
        }
    }
    EXPECT_GT(hits, 0);
    EXPECT_GT(misses, 0);
}

TEST_F(RenderCli, BadInputsExitTwoAndLeaveNoOutput) {
    TempDir out;
    const std::string png = "-o '" + out.file("x.png") + "'";
    const std::vector<std::string> bad = {
        "'" + oct_ + "' " + png,                                                    // no --iso
        "'" + oct_ + "' --iso 5",                                                   // no output at all
        "'" + oct_ + "' --iso abc " + png,                                          // not a number
        "'" + out.file("missing.oct") + "' --iso 5 " + png,                         // no such file
        "'" + oct_ + "' --iso 5 -o '" + out.file("x.unknownext") + "'",             // no image format
        "'" + oct_ + "' --iso 5 --size 0x10 " + png,                                // bad size
        "'" + oct_ + "' --iso 5 --eye 1,2,3 --look 1,2,3 " + png,                   // eye == look
        "'" + oct_ + "' --iso 5 --up 0,0,0 " + png,                                 // zero up
        "'" + oct_ + "' --iso 5 --root-finder newton " + png,                       // unknown finder
        "'" + oct_ + "' --iso 5 --frobnicate " + png,                               // unknown flag
        "'" + oct_ + "' --iso 5 --steps 0:3 -o '" + out.file("f_%03d.png") + "'",   // steps out of range
        "'" + ranged_ + "' --iso 0.9 " + png,                                       // outside the iso-range
        "'" + ranged_ + "' --iso 0.3 " + png,                                       // the range's own end
    };
    for (const std::string& args : bad) {
        std::string err;
        EXPECT_EQ(run("octiso-render", args, nullptr, &err), 2) << args;
        EXPECT_EQ(out.entries().size(), 0u) << "no output, no temporary left: " << args;
        EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << "one line on stderr: " << err;
    }
}

TEST_F(RenderCli, IsovalueInsideTheIsoRangeRenders) {
    TempDir out;
    EXPECT_EQ(run("octiso-render", "'" + ranged_ + "' --iso 0.5 --size 16x16 -o '" + out.file("ok.png") + "'"), 0);
    EXPECT_TRUE(fs::exists(out.file("ok.png")));
}

TEST_F(RenderCli, CorruptFileIsRejectedCleanly) {
    TempDir out;
    const std::string bad = out.file("bad.oct");
    fs::copy_file(oct_, bad);
    fs::resize_file(bad, fs::file_size(bad) / 2);
    std::string err;
    EXPECT_EQ(run("octiso-render", "'" + bad + "' --iso 5 -o '" + out.file("x.png") + "'", nullptr, &err), 2);
    EXPECT_NE(err.find("bad.oct"), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(out.file("x.png")));
}

// Issue 13: --verify touched checks nodes as rays reach them (format/touch_validation.h). The
// image is the full check's byte for byte, with threads faulting on blocks together; a bad node
// a frame reads ends the run with the full check's message and no output.
TEST_F(RenderCli, VerifyTouchedGivesTheSameImageAndRefusesABadNode) {
    TempDir out;
    const std::string big = out.file("plume.oct");
    ASSERT_EQ(run("octiso-convert", "--synthetic plume:256 -o '" + big + "'"), 0);
    ASSERT_GT(fs::file_size(big), uint64_t(4) << 20) << "the file must span several blocks";
    std::string json;
    const std::string common = " --iso 40.5 --size 96x96 --threads 2 --json ";
    ASSERT_EQ(run("octiso-render", "'" + big + "'" + common + "--verify full -o '" + out.file("full.png") + "'"), 0);
    ASSERT_EQ(run("octiso-render", "'" + big + "'" + common + "--verify touched -o '" + out.file("touched.png") + "'", &json), 0);
    EXPECT_EQ(read_bytes(out.file("full.png")), read_bytes(out.file("touched.png")));
    EXPECT_NE(json.find("\"verify\":\"touched\""), std::string::npos) << json;
    EXPECT_NE(json.find("\"touched_blocks\""), std::string::npos) << json;
    EXPECT_NE(json.find("\"open_to_first_frame_seconds\""), std::string::npos) << json;

    OctBytes b(big);
    b.set_group_base(0, 0, 0, 0xffffffffu);   // the root's children far past depth 1
    b.rechecksum();
    const std::string bad = out.file("bad.oct");
    b.save(bad);
    for (const char* mode : {"full", "touched"}) {
        SCOPED_TRACE(mode);
        std::string err;
        EXPECT_EQ(run("octiso-render", "'" + bad + "'" + common + "--verify " + mode + " -o '" + out.file("x.png") + "'", nullptr, &err), 2);
        EXPECT_NE(err.find("bad.oct: step 0, depth 0 (interior nodes), node 0: group base + child_offset + popcount(child_mask) runs past"),
                  std::string::npos) << err;
        EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
        EXPECT_FALSE(fs::exists(out.file("x.png")));
    }
    std::string err;
    EXPECT_EQ(run("octiso-render", "'" + big + "' --iso 40.5 --verify some -o '" + out.file("x.png") + "'", nullptr, &err), 2);
    EXPECT_NE(err.find("--verify: expected auto, full or touched"), std::string::npos) << err;
}

}  // namespace
}  // namespace octiso::test
