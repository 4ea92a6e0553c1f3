// Issue 18, class 4: on a full disk every tool fails with one line naming the file (exit 1, an
// "other" failure), publishes nothing, leaves no temporary and keeps an older file under the
// name intact (OIIO's PNG writer did not report ENOSPC, and a truncated PNG was renamed into
// place). Needs a small tmpfs, so root: skipped with a message otherwise, and a failure instead
// of a skip when OCTISO_REQUIRE_ALL=1 (CI).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

#include "hostile/hostile_util.h"

namespace octiso::test {
namespace {

TEST(HostileFullDisk, NoToolPublishesATruncatedFile) {
    ScratchDir dir("octiso_hostile_disk");
    ASSERT_EQ(run_capture("'" + tool("octiso-convert") + "' --synthetic noise:48 -o '" + dir.file("in.oct") + "'",
                          dir.file("err")).exit_status, 0);
    const std::string full = dir.file("full");
    SmallTmpfs fs(full);
    if (!fs.mounted()) {
        OCTISO_SKIP("full-disk test cannot run: " << fs.why());
    }
    // Older files under the names every tool is about to write.
    for (const char* name : {"r.png", "d.exr", "s.oct", "x.raw"}) write_text(full + "/" + name, std::string("old ") + name);
    fs.fill_leaving(8192);

    const std::string err = dir.file("err");
    struct Case {
        std::string command, output;
    };
    const std::string in = "'" + dir.file("in.oct") + "'";
    const std::vector<Case> cases = {
        {"'" + tool("octiso-render") + "' " + in + " --iso 100 --size 512x512 -o '" + full + "/r.png'", full + "/r.png"},
        {"'" + tool("octiso-render") + "' " + in + " --iso 100 --size 512x512 --depth '" + full + "/d.exr'", full + "/d.exr"},
        {"'" + tool("octiso-convert") + "' --synthetic noise:64 -o '" + full + "/s.oct'", full + "/s.oct"},
        {"'" + tool("octiso-info") + "' " + in + " --extract-raw '" + full + "/x.raw'", full + "/x.raw"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.command);
        const RunResult r = run_capture(c.command, err);
        EXPECT_EQ(r.signal, 0);
        EXPECT_EQ(r.exit_status, 1) << r.err;
        EXPECT_NE(r.err.find(c.output), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        const std::string name = std::filesystem::path(c.output).filename().string();
        EXPECT_EQ(read_all(c.output), "old " + name) << "the older file must be left as it was";
        EXPECT_TRUE(temporaries(full).empty());
    }
}

}  // namespace
}  // namespace octiso::test
