// Frames that must not change by accident: colour, depth and normal images of three synthetic
// volumes (f32, u8, i16) under five cameras and both root-finder families, rendered through the
// tools by the commit before the Renderer refactor (0102e1b) and kept in tests/data/golden/.
// The current tools must reproduce every pixel exactly. A deliberate change of the images (new
// shading, say) regenerates them with the commands in kCases and says so in its commit.
// Issue 17 made the light kit the default colour; the kept colour images are the Renderer's own
// headlight, which `--shading headlight` still gives bit for bit, so the colour is compared under
// that flag. Depth and normals do not depend on the shading: they are compared under both.
#include <gtest/gtest.h>

#include <string>

#include "octiso/image.h"
#include "test_util/run_shell.h"
#include "test_util/scratch_dir.h"

namespace octiso::test {
namespace {

const std::string kTools = OCTISO_TOOLS_DIR;
const std::string kGolden = OCTISO_TEST_DATA_DIR "/golden";

struct GoldenCase {
    const char* volume;   ///< octiso-convert arguments (without -o)
    const char* render;   ///< octiso-render arguments (without the file and outputs)
    const char* name;     ///< golden files NAME.png, NAME.exr (depth), NAME_n.exr (normal) if `normal`
    bool normal;
};

constexpr GoldenCase kCases[] = {
    {"--synthetic marschner-lobb:41 --type f32", "--iso 0.5 --size 80x64", "ml_a", true},
    {"--synthetic marschner-lobb:41 --type f32",
     "--iso 0.3,0.7 --size 72x72 --eye 20,20,60 --look 20,20,0 --up 0,1,0 --fov 50 --root-finder exact", "ml_b", false},
    {"--synthetic plume:48", "--iso 60,140 --size 80x64", "plume_a", true},
    {"--synthetic plume:48", "--iso 100 --size 64x80 --eye 24,24,24 --look 40,10,30 --up 0,0,1 --fov 70", "plume_b", false},
    {"--synthetic sponge:27 --type i16", "--iso 50 --size 80x64", "sponge_a", false},
};

void expect_same_image(const std::string& produced, const std::string& golden) {
    SCOPED_TRACE(golden);
    const FloatImage a = read_image(produced), b = read_image(golden);
    ASSERT_EQ(a.width, b.width);
    ASSERT_EQ(a.height, b.height);
    ASSERT_EQ(a.channels, b.channels);
    ASSERT_EQ(a.pixels.size(), b.pixels.size());
    size_t differ = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i) differ += !(a.pixels[i] == b.pixels[i] || (a.pixels[i] != a.pixels[i] && b.pixels[i] != b.pixels[i]));
    EXPECT_EQ(differ, 0u) << differ << " of " << a.pixels.size() << " channel values differ";
}

TEST(GoldenFrames, CurrentToolsReproduceTheKeptImagesExactly) {
    ScratchDir dir("octiso_golden");
    for (const GoldenCase& c : kCases) {
        SCOPED_TRACE(c.name);
        const std::string oct = dir.file(std::string(c.name) + ".oct");
        ASSERT_EQ(run_shell("'" + kTools + "/octiso-convert' " + c.volume + " -o '" + oct + "' 2>/dev/null"), 0);
        const std::string base = dir.file(c.name);
        std::string outputs = " -o '" + base + ".png' --depth '" + base + ".exr'";
        if (c.normal) outputs += " --normal '" + base + "_n.exr'";
        for (const char* shading : {" --shading headlight", ""}) {
            SCOPED_TRACE(shading);
            ASSERT_EQ(run_shell("'" + kTools + "/octiso-render' '" + oct + "' " + c.render + shading + outputs + " 2>/dev/null"), 0);
            if (*shading) expect_same_image(base + ".png", kGolden + "/" + c.name + ".png");
            expect_same_image(base + ".exr", kGolden + "/" + c.name + ".exr");
            if (c.normal) expect_same_image(base + "_n.exr", kGolden + "/" + c.name + "_n.exr");
        }
    }
}

}  // namespace
}  // namespace octiso::test
