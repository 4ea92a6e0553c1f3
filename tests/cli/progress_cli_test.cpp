// Issue 17 item 5 inside one frame, end to end: octiso-render --progress draws its line on stderr
// even when stderr is not a terminal (here a file), and the frame it writes is the frame without
// the line bit for bit (colour, depth, normal; the same rays and hits), whatever the samples and
// the look; without --progress and without a terminal nothing of the line is written.
#include <gtest/gtest.h>

#include <algorithm>

#include "cli/cli_test_util.h"
#include "cli/marschner_render_fixture.h"
#include "octiso/image.h"

namespace octiso::test {
namespace {

class ProgressCli : public MarschnerRenderCli {
protected:
    ProgressCli() : MarschnerRenderCli("octiso_progress_cli") {}
    ToolRun render_big(const std::string& flags, const std::string& name) {
        return run_tool("octiso-render", "'" + oct_ + "' --iso 0.3,0.6 --size 203x157 --spp 2 --shadows --json " + flags + " -o '" +
                                             dir_.file(name) + ".png' --depth '" + dir_.file(name) + ".exr' --normal '" +
                                             dir_.file(name) + "_n.exr'");
    }
};

TEST_F(ProgressCli, FramesAreBitIdenticalWithTheLineOnAndOff) {
    const ToolRun off = render_big("", "off"), on = render_big("--progress", "on");
    ASSERT_EQ(off.status, 0) << off.err;
    ASSERT_EQ(on.status, 0) << on.err;
    EXPECT_EQ(off.err.find('\r'), std::string::npos) << "no terminal, no --progress: no line";
    EXPECT_NE(on.err.find('\r'), std::string::npos) << on.err;
    EXPECT_NE(on.err.find("tiles "), std::string::npos) << "progress inside the frame: " << on.err;
    EXPECT_NE(on.err.find("100%"), std::string::npos) << on.err;
    // The report after the line starts on a line of its own.
    EXPECT_NE(on.err.find("\ncamera: "), std::string::npos) << on.err;
    for (const char* suffix : {".png", ".exr", "_n.exr"}) {
        SCOPED_TRACE(suffix);
        EXPECT_EQ(image(std::string("on") + suffix).pixels, image(std::string("off") + suffix).pixels);
    }
    EXPECT_EQ(json_number(on.out, "hits"), json_number(off.out, "hits"));
    EXPECT_EQ(json_number(on.out, "rays"), json_number(off.out, "rays"));
}

}  // namespace
}  // namespace octiso::test
