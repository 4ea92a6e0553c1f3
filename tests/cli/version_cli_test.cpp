// --version in every tool (cli::run_main): "TOOL VERSION" and a newline on stdout, exit 0, before
// and instead of anything else on the command line. Tools not built next to the tests are skipped.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "octiso/version.h"
#include "test_util/run_shell.h"

namespace octiso::test {
namespace {

const std::string kTools = OCTISO_TOOLS_DIR;

class VersionCli : public ::testing::TestWithParam<const char*> {};

TEST_P(VersionCli, PrintsToolAndVersionAndExitsZero) {
    const std::string tool = GetParam();
    if (!std::filesystem::exists(kTools + "/" + tool)) GTEST_SKIP() << tool << " not built";
    const std::string expected = tool + " " + OCTISO_VERSION_STRING + "\n";
    std::string out;
    EXPECT_EQ(run_shell("'" + kTools + "/" + tool + "' --version 2>/dev/null", &out), 0);
    EXPECT_EQ(out, expected);
    // Other arguments, even bad ones, do not matter once --version is there.
    EXPECT_EQ(run_shell("'" + kTools + "/" + tool + "' --no-such-flag --version 2>/dev/null", &out), 0);
    EXPECT_EQ(out, expected);
}

INSTANTIATE_TEST_SUITE_P(AllTools, VersionCli,
                         ::testing::Values("octiso-convert", "octiso-render", "octiso-info", "octiso-bench"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                             std::string name = info.param;
                             name.erase(0, std::string("octiso-").size());
                             return name;
                         });

}  // namespace
}  // namespace octiso::test
