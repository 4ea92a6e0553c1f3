// A gtest fixture shared by the CLI tests of octiso-render's look (shading_cli_test, look_cli_test):
// a 25^3 f32 Marschner-Lobb .oct in a scratch folder, and render(flags, name) writing NAME.png and
// NAME.exr (depth) at 40x32 for isovalues 0.3 and 0.6, with --json.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "cli/cli_test_util.h"
#include "octiso/image.h"
#include "test_util/scratch_dir.h"
#include "test_util/skip.h"

namespace octiso::test {

class MarschnerRenderCli : public ::testing::Test {
protected:
    explicit MarschnerRenderCli(const char* scratch) : dir_(scratch) {}
    void SetUp() override {
        for (const char* tool : {"octiso-convert", "octiso-render"})
            if (!std::filesystem::exists(std::string(OCTISO_TOOLS_DIR) + "/" + tool)) { OCTISO_SKIP(tool << " not built"); }
        ASSERT_EQ(run_tool("octiso-convert", "--synthetic marschner-lobb:25 --type f32 -o '" + oct_ + "'").status, 0);
    }
    ToolRun render(const std::string& flags, const std::string& name) {
        return run_tool("octiso-render", "'" + oct_ + "' --iso 0.3,0.6 --size 40x32 " + flags + " -o '" + dir_.file(name) +
                                             ".png' --depth '" + dir_.file(name) + ".exr' --json");
    }
    FloatImage image(const std::string& name) { return read_image(dir_.file(name)); }
    ScratchDir dir_;
    std::string oct_ = dir_.file("ml.oct");
};

}  // namespace octiso::test
