// octiso-view's command line (CONVENTIONS 3): --help, and one stderr line with exit status 2 for
// a bad file or bad flags, before anything is served. Serving itself is server_test.cpp and the
// end-to-end browser test (e2e_view.py).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "test_util/run_shell.h"
#include "test_util/scratch_dir.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

const std::string kTools = OCTISO_TOOLS_DIR;

class ViewCli : public ::testing::Test {
protected:
    void SetUp() override {
        if (!std::filesystem::exists(kTools + "/octiso-view")) {
            OCTISO_SKIP("octiso-view not built");
        }
    }
    int view(const std::string& args, std::string* out, std::string* err) {
        const std::string err_file = dir_.file("stderr");
        const int status = run_shell("'" + kTools + "/octiso-view' " + args + " 2>'" + err_file + "'", out);
        run_shell("cat '" + err_file + "'", err);
        return status;
    }
    ScratchDir dir_{"octiso_view_cli"};
};

TEST_F(ViewCli, HelpPrintsUsage) {
    std::string out, err;
    EXPECT_EQ(view("--help", &out, &err), 0);
    EXPECT_EQ(out.rfind("usage: octiso-view FILE.oct", 0), 0u) << out;
}

TEST_F(ViewCli, BadFileOrFlagsExitTwoWithOneLine) {
    const std::string junk = dir_.file("junk.oct");
    std::ofstream(junk) << "not an octree";
    const std::pair<std::string, std::string> cases[] = {
        {"'" + dir_.file("missing.oct") + "'", "missing.oct"},
        {"'" + junk + "'", "junk.oct"},
        {"", "expected exactly one FILE.oct"},
        {"'" + junk + "' --port 70000", "--port"},
        {"'" + junk + "' --threads 0", "--threads"},
        {"'" + junk + "' --bogus", "--bogus"},
        {"'" + junk + "' --iso abc", "--iso"},
        {"'" + junk + "' --lod -1", "--lod"},
        {"'" + junk + "' --lod abc", "--lod"},
    };
    for (const auto& [args, needle] : cases) {
        std::string out, err;
        EXPECT_EQ(view(args, &out, &err), 2) << args;
        EXPECT_TRUE(out.empty()) << args << ": " << out;
        EXPECT_NE(err.find(needle), std::string::npos) << args << ": " << err;
        if (needle != "expected exactly one FILE.oct") {
            EXPECT_EQ(err.find('\n'), err.size() - 1) << "one line: " << err;
        }
    }
}

}  // namespace
}  // namespace octiso::test
