// Float images written with OpenEXR directly (src/io/exr_writer.h): what OpenImageIO reads back
// are the same floats bit for bit (infinities of missed pixels included) under the same channel
// names, for one and three channels at any size; the same image gives the same bytes (no time
// stamp); the depth and normal writers take every spelling of ".exr"; sizes outside an image are
// refused in one message and leave nothing behind.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "io/exr_writer.h"
#include "octiso/error.h"
#include "octiso/image.h"
#include "test_util/scratch_dir.h"

namespace octiso::test {
namespace {

std::vector<float> random_floats(size_t n, uint32_t seed, bool with_infinities) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1000.0f, 1000.0f);
    std::vector<float> v(n);
    for (size_t i = 0; i < n; ++i)
        v[i] = with_infinities && rng() % 5 == 0 ? std::numeric_limits<float>::infinity() : u(rng);
    return v;
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

void write_bytes(const std::string& path, const std::vector<unsigned char>& bytes) {
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

TEST(ExrWriter, FloatsReadBackBitForBitUnderTheirNames) {
    ScratchDir dir{"octiso_exr_writer"};
    const std::pair<int, int> sizes[] = {{1, 1}, {7, 3}, {3, 7}, {257, 129}};
    const std::vector<std::vector<std::string>> channel_sets = {{"Z"}, {"R", "G", "B"}};
    uint32_t seed = 1;
    for (const auto& [w, h] : sizes) {
        for (const auto& names : channel_sets) {
            const std::vector<float> pixels = random_floats(size_t(w) * size_t(h) * names.size(), seed++, names.size() == 1);
            const std::string path = dir.file("f.exr");
            write_bytes(path, io::encode_float_exr(w, h, pixels.data(), names, "test"));
            const FloatImage back = read_image(path);
            ASSERT_EQ(back.width, w);
            ASSERT_EQ(back.height, h);
            EXPECT_EQ(back.channel_names, names);
            EXPECT_TRUE(same_bits(back.pixels, pixels)) << w << "x" << h << ", " << names.size() << " channels";
        }
    }
}

TEST(ExrWriter, TheSameImageGivesTheSameBytes) {
    const std::vector<float> pixels = random_floats(64 * 48, 9, true);
    EXPECT_EQ(io::encode_float_exr(64, 48, pixels.data(), {"Z"}, "a"), io::encode_float_exr(64, 48, pixels.data(), {"Z"}, "b"));
}

TEST(ExrWriter, WorkerThreadsGiveTheSameBytesAndEveryLevelReadsBack) {
    ScratchDir dir{"octiso_exr_writer"};
    // 203 rows: 13 ZIP blocks of 16 rows, the last one short, so several workers share the file.
    const int w = 71, h = 203;
    const std::vector<float> normal = random_floats(size_t(w) * h * 3, 11, false);
    const std::vector<std::string> names{"R", "G", "B"};
    const std::vector<unsigned char> alone = io::encode_float_exr(w, h, normal.data(), names, "n", 1);
    for (int threads : {0, 2, 3, 64}) EXPECT_EQ(io::encode_float_exr(w, h, normal.data(), names, "n", threads), alone) << threads;
    for (int level : {1, 4, 9}) {
        const std::vector<unsigned char> bytes = io::encode_float_exr(w, h, normal.data(), names, "n", 2, level);
        const std::string path = dir.file("level.exr");
        std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
        const FloatImage back = read_image(path);
        EXPECT_TRUE(same_bits(back.pixels, normal)) << "zip level " << level;
    }
}

TEST(ExrWriter, DepthAndNormalWritersTakeEverySpellingOfExr) {
    ScratchDir dir{"octiso_exr_writer"};
    Frame f;
    f.width = 9, f.height = 5;
    f.depth = random_floats(45, 3, true);
    f.normal = random_floats(135, 4, false);
    for (const char* name : {"a.exr", "b.EXR", "c.Exr"}) {
        const std::string depth = dir.file(std::string("d_") + name), normal = dir.file(std::string("n_") + name);
        write_depth_image(depth, f);
        write_normal_image(normal, f);
        const FloatImage d = read_image(depth), n = read_image(normal);
        EXPECT_EQ(d.channel_names, std::vector<std::string>{"Z"}) << name;
        EXPECT_TRUE(same_bits(d.pixels, f.depth)) << name;
        EXPECT_EQ(n.channel_names, (std::vector<std::string>{"R", "G", "B"})) << name;
        EXPECT_TRUE(same_bits(n.pixels, f.normal)) << name;
    }
    // Buffers of another size than the frame's are refused, not read past their end.
    Frame short_depth = f;
    short_depth.depth.pop_back();
    EXPECT_THROW(write_depth_image(dir.file("short.exr"), short_depth), Error);
    Frame short_normal = f;
    short_normal.normal.pop_back();
    EXPECT_THROW(write_normal_image(dir.file("short_n.exr"), short_normal), Error);
    EXPECT_FALSE(std::filesystem::exists(dir.file("short.exr")) || std::filesystem::exists(dir.file("short_n.exr")));
    EXPECT_TRUE(io::is_exr_path("x.exr") && io::is_exr_path("/a/b.ExR"));
    EXPECT_FALSE(io::is_exr_path("exr") || io::is_exr_path("x.exr.png") || io::is_exr_path("x.ex"));
}

TEST(ExrWriter, SizesOutsideAnImageAreRefusedInOneMessage) {
    const float pixel[3] = {1, 2, 3};
    struct Case {
        int w, h;
        std::vector<std::string> names;
    };
    const Case cases[] = {{0, 1, {"Z"}}, {1, 0, {"Z"}}, {-2, 3, {"Z"}}, {1, 1, {}}, {1, 1, {"A", "B", "C", "D", "E"}},
                          {1 << 29, 1, {"R", "G", "B"}}};
    for (const Case& c : cases) {
        try {
            (void)io::encode_float_exr(c.w, c.h, pixel, c.names, "out.exr");
            ADD_FAILURE() << c.w << "x" << c.h << " of " << c.names.size() << " channels was encoded";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("out.exr"), std::string::npos) << e.what();
            EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
        }
    }
}

}  // namespace
}  // namespace octiso::test
