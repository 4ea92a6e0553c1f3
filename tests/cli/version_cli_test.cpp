// --version in every tool (cli::run_main): "TOOL VERSION" and a newline on stdout, exit 0, before
// and instead of anything else on the command line. octiso-bench is checked where it is built
// (OCTISO_BENCH_BUILT, from CMake; the sanitizer build leaves it out).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "octiso/version.h"
#include "test_util/run_shell.h"

namespace octiso::test {
namespace {

const std::string kTools = OCTISO_TOOLS_DIR;

#if OCTISO_BENCH_BUILT
const std::vector<const char*> kBuiltTools{"octiso-convert", "octiso-render", "octiso-info", "octiso-bench"};
#else
const std::vector<const char*> kBuiltTools{"octiso-convert", "octiso-render", "octiso-info"};
#endif

class VersionCli : public ::testing::TestWithParam<const char*> {};

TEST_P(VersionCli, PrintsToolAndVersionAndExitsZero) {
    const std::string tool = GetParam();
    ASSERT_TRUE(std::filesystem::exists(kTools + "/" + tool)) << tool << " is not built next to the tests";
    const std::string expected = tool + " " + OCTISO_VERSION_STRING + "\n";
    std::string out;
    EXPECT_EQ(run_shell("'" + kTools + "/" + tool + "' --version 2>/dev/null", &out), 0);
    EXPECT_EQ(out, expected);
    // Other arguments, even bad ones, do not matter once --version is there.
    EXPECT_EQ(run_shell("'" + kTools + "/" + tool + "' --no-such-flag --version 2>/dev/null", &out), 0);
    EXPECT_EQ(out, expected);
}

INSTANTIATE_TEST_SUITE_P(AllTools, VersionCli,
                         ::testing::ValuesIn(kBuiltTools),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                             std::string name = info.param;
                             name.erase(0, std::string("octiso-").size());
                             return name;
                         });

}  // namespace
}  // namespace octiso::test
