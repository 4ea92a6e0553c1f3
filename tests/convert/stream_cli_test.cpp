// octiso-convert --memory (issue 13) from the command line: the suffixes, the one-line exit-2
// refusals (a budget too small for one slab, a bad number, --memory with --in-memory), nothing
// left behind, and the same file with and without the flag.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <vector>

#include "test_util/run_shell.h"
#include "test_util/scratch_dir.h"

namespace octiso::test {
namespace {

const std::string kConvert = std::string(OCTISO_TOOLS_DIR) + "/octiso-convert";

std::string slurp(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

int convert(const std::string& args, std::string* err) {
    return run_shell("'" + kConvert + "' " + args + " 2>&1 >/dev/null", err);
}

TEST(StreamCli, MemoryFlagGivesTheSameFileAndRefusesWithOneLine) {
    ScratchDir dir("stream_cli");
    std::vector<uint8_t> v(70 * 50 * 33);
    for (size_t i = 0; i < v.size(); ++i) v[i] = uint8_t((i % 70) / 9 * 30 + (i / 3500) % 3);
    std::ofstream(dir.file("in.raw"), std::ios::binary).write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size()));
    const std::string in = "'" + dir.file("in.raw") + "' --dims 70,50,33 --type u8 -o ";
    std::string err;
    ASSERT_EQ(convert(in + "'" + dir.file("a.oct") + "'", &err), 0) << err;
    for (const char* m : {"1M", "300K", "2g", "1048576"}) {
        ASSERT_EQ(convert(in + "'" + dir.file("b.oct") + "' --memory " + m, &err), 0) << err;
        EXPECT_NE(err.find("out of core"), std::string::npos) << err;
        EXPECT_TRUE(slurp(dir.file("a.oct")) == slurp(dir.file("b.oct"))) << "--memory " << m;
    }
    for (const char* bad : {"--memory 1K", "--memory 12X", "--memory -5", "--memory 4M --in-memory"}) {
        EXPECT_EQ(convert(in + "'" + dir.file("c.oct") + "' " + bad, &err), 2) << bad << ": " << err;
        EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << bad << ": " << err;
    }
    EXPECT_EQ(dir.entries(), (std::vector<std::string>{"a.oct", "b.oct", "in.raw"}));
}

}  // namespace
}  // namespace octiso::test
