// The colour PNG written with libpng directly (src/io/png_writer.h): the pixels OpenImageIO reads
// back are the frame's bytes exactly (8-bit RGB), at any size, zlib level and filtering; sizes a
// PNG cannot take are refused in one message; and write_colour_image goes this way for every
// spelling of ".png".
#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "io/png_writer.h"
#include "octiso/error.h"
#include "octiso/image.h"
#include "test_util/scratch_dir.h"

namespace octiso::test {
namespace {

Frame random_frame(int width, int height, uint32_t seed) {
    Frame f;
    f.width = width, f.height = height;
    f.rgb.resize(size_t(width) * size_t(height) * 3);
    std::mt19937 rng(seed);
    for (auto& b : f.rgb) b = uint8_t(rng());
    return f;
}

/// What OpenImageIO reads back, as bytes (its float of an 8-bit channel is v / 255 exactly).
std::vector<uint8_t> read_back_bytes(const std::string& path, int& width, int& height, int& channels) {
    const FloatImage img = read_image(path);
    width = img.width, height = img.height, channels = img.channels;
    std::vector<uint8_t> out(img.pixels.size());
    for (size_t i = 0; i < out.size(); ++i) out[i] = uint8_t(img.pixels[i] * 255.0f + 0.5f);
    return out;
}

TEST(PngWriter, PixelsReadBackExactlyAtEverySizeAndLevel) {
    ScratchDir dir{"octiso_png_writer"};
    const std::pair<int, int> sizes[] = {{1, 1}, {7, 3}, {3, 7}, {257, 129}, {512, 512}};
    uint32_t seed = 1;
    for (const auto& [w, h] : sizes) {
        for (io::PngEffort effort :
             {io::kPngFile, io::kPngStream, io::PngEffort{0, io::PngRowFilter::adaptive}, io::PngEffort{9, io::PngRowFilter::none},
              io::PngEffort{6, io::PngRowFilter::up, io::PngDeflate::run_length}, io::PngEffort{6, io::PngRowFilter::adaptive},
              io::PngEffort{9, io::PngRowFilter::paeth}}) {
            const Frame f = random_frame(w, h, seed++);
            const std::vector<unsigned char> bytes = io::encode_rgb8_png(w, h, f.rgb.data(), effort, "test");
            const std::string path = dir.file("f.png");
            std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
            int rw = 0, rh = 0, rc = 0;
            const std::vector<uint8_t> back = read_back_bytes(path, rw, rh, rc);
            ASSERT_EQ(rw, w);
            ASSERT_EQ(rh, h);
            ASSERT_EQ(rc, 3);
            EXPECT_EQ(back, f.rgb) << w << "x" << h << " at level " << effort.zlib_level << ", filter " << int(effort.filter)
                                << ", deflate " << int(effort.deflate);
        }
    }
}

TEST(PngWriter, StripsGiveTheSameBytesOnAnyThreadCount) {
    // 64-row strips: 1, 2 and 4 of them, the last one short; every single-filter setting.
    for (const auto& [w, h] : {std::pair<int, int>{5, 64}, {33, 65}, {130, 200}}) {
        const Frame f = random_frame(w, h, uint32_t(w * h));
        for (io::PngEffort effort : {io::kPngFile, io::kPngStream, io::PngEffort{3, io::PngRowFilter::up}}) {
            const std::vector<unsigned char> alone = io::encode_rgb8_png(w, h, f.rgb.data(), effort, "test", 1);
            for (int threads : {0, 2, 3}) EXPECT_EQ(io::encode_rgb8_png(w, h, f.rgb.data(), effort, "test", threads), alone) << w << "x" << h;
        }
    }
}

TEST(PngWriter, WriteColourImageTakesEverySpellingOfPng) {
    ScratchDir dir{"octiso_png_writer"};
    const Frame f = random_frame(33, 17, 7);
    for (const char* name : {"a.png", "b.PNG", "c.Png"}) {
        const std::string path = dir.file(name);
        write_colour_image(path, f);
        int w = 0, h = 0, c = 0;
        EXPECT_EQ(read_back_bytes(path, w, h, c), f.rgb) << name;
        std::ifstream in(path, std::ios::binary);
        char magic[8] = {};
        in.read(magic, 8);
        EXPECT_EQ(std::string(magic, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << name;
    }
    EXPECT_TRUE(io::is_png_path("x.png") && io::is_png_path("/a/b.PnG") && io::is_png_path(".png"));
    EXPECT_FALSE(io::is_png_path("png") || io::is_png_path("x.png.exr") || io::is_png_path("x.pn") || io::is_png_path("x.apng"));
}

TEST(PngWriter, SizesOutsidePngAreRefusedInOneMessage) {
    const uint8_t pixel[3] = {1, 2, 3};
    for (const auto& [w, h] : std::vector<std::pair<int, int>>{{0, 1}, {1, 0}, {-3, 4}, {1 << 30, 1}}) {
        try {
            (void)io::encode_rgb8_png(w, h, pixel, io::kPngFile, "out.png");
            ADD_FAILURE() << w << "x" << h << " was encoded";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("out.png"), std::string::npos) << e.what();
            EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
        }
    }
    Frame short_rgb = random_frame(4, 4, 3);
    short_rgb.rgb.pop_back();
    ScratchDir dir{"octiso_png_writer"};
    EXPECT_THROW(write_colour_image(dir.file("s.png"), short_rgb), Error);
    EXPECT_TRUE(dir.entries().empty()) << "nothing may be left after a refused write";
}

}  // namespace
}  // namespace octiso::test
