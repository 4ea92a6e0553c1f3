// Issue 17, item 2 (help that documents), end to end: every tool prints its help on stdout for
// --help and -h (exit 0, nothing on stderr), the same help on stderr for no arguments (exit 2, a
// usage error), and the help names every flag the tool accepts.
#include <gtest/gtest.h>

#include <filesystem>

#include "cli/cli_test_util.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

struct ToolFlags {
    const char* tool;
    std::vector<std::string> flags;
};

const ToolFlags kTools[] = {
    {"octiso-render",
     {"-o, --output", "--depth", "--normal", "--json", "--steps", "--view", "--azimuth", "--elevation", "--zoom", "--orbit", "--eye",
      "--look", "--up", "--fov", "--size", "--spp", "--lod", "--shading", "--background", "--colour", "--root-finder", "--iterations",
      "--embree", "--no-embree", "--threads", "--debug-pixel", "--version", "--help", "--iso", "--traversal", "--isa", "--distribute", "--shadows",
      "--ao", "--ao-distance", "--opacity", "--clip", "--clip-cap", "--progress"}},
    {"octiso-info", {"--json", "--bins", "--verify", "--extract-raw", "--step", "--endian", "--version", "--help"}},
    {"octiso-convert",
     {"-o, --output", "--dims", "--type", "--endian", "--offset", "--spacing", "--origin", "--iso-range", "--tolerance", "--nan-as",
      "--steps", "--synthetic", "--threads", "--json", "--version", "--help"}},
};

TEST(HelpCli, HelpOnStdoutNoArgumentsOnStderrAndEveryFlagNamed) {
    for (const ToolFlags& t : kTools) {
        SCOPED_TRACE(t.tool);
        if (!std::filesystem::exists(std::string(OCTISO_TOOLS_DIR) + "/" + t.tool)) { OCTISO_SKIP(t.tool << " not built"); }
        const ToolRun help = run_tool(t.tool, "--help"), h = run_tool(t.tool, "-h"), none = run_tool(t.tool, "");
        EXPECT_EQ(help.status, 0);
        EXPECT_EQ(help.err, "");
        EXPECT_EQ(help.out.rfind("usage: ", 0), 0u) << help.out;
        EXPECT_EQ(h.status, 0);
        EXPECT_EQ(h.out, help.out);
        EXPECT_EQ(none.status, 2);
        EXPECT_EQ(none.out, "");
        EXPECT_EQ(none.err, help.out);
        for (const std::string& flag : t.flags) EXPECT_NE(help.out.find(flag), std::string::npos) << flag;
    }
}

}  // namespace
}  // namespace octiso::test
