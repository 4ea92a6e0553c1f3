// Extreme data end to end: f32/f64 volumes with values near +-1e30, 1e-30 and the type's limits
// rendered against the dense exact reference; NaN/Inf input refused by octiso-convert (exit 2,
// no output, a message naming the file and the value) or replaced with --nan-as; dimensions whose
// voxel count overflows 32 (and 64) bits refused cleanly by the checked arithmetic; 1xNxM, 2x2x2
// and 1x1x1 volumes through convert, info and render without a crash and without hits where no
// cell exists. CLI parts skip when the tools are not built next to the tests.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "test_util/run_shell.h"
#include "test_util/scratch_dir.h"
#include "octiso/build.h"
#include "octiso/decode.h"
#include "octiso/error.h"
#include "octiso/oct_file.h"
#include "octiso/reader.h"
#include "octiso/render.h"
#include "octree/octree_test_util.h"
#include "reference/reference_render.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

namespace fs = std::filesystem;
const std::string kTools = OCTISO_TOOLS_DIR;

/// A ball-shaped field scale * (offset + 1 - |p - c| / r), so values sit near `scale * offset`
/// with relative variations of order 1/offset (offset 0: values span about [-scale, scale]).
template <typename T> DenseVolume<T> scaled_ball(Dims dims, double scale, double offset) {
    DenseVolume<T> v{dims, std::vector<T>(dims.voxels())};
    const double cx = (dims.x - 1) / 2.0 + 0.3, cy = (dims.y - 1) / 2.0 - 0.2, cz = (dims.z - 1) / 2.0 + 0.1;
    const double r = 0.4 * std::min({dims.x, dims.y, dims.z});
    for (uint32_t z = 0; z < dims.z; ++z)
        for (uint32_t y = 0; y < dims.y; ++y)
            for (uint32_t x = 0; x < dims.x; ++x) {
                const double d = std::sqrt((x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz));
                v.values[x + uint64_t(dims.x) * (y + uint64_t(dims.y) * z)] = T(scale * (offset + 1 - d / r));
            }
    return v;
}

template <typename T> void expect_matches_reference(const DenseVolume<T>& v, double iso, const std::string& what) {
    SCOPED_TRACE(what);
    const auto data = build_octree(v.view(), {});
    const Placement placement;
    RenderOptions options;
    options.isovalues = {iso};
    options.want_colour = false;
    options.want_depth = options.want_normal = true;
    for (const Camera& cam : {frame_data_box(v.dims, placement, 64, 60),
                              Camera{{-20, 30, -25}, {12, 11, 10}, {0, 1, 0}, 30, 49, 49}}) {
        const Frame f = render(data.view(), placement, cam, options);
        for (float d : f.depth) ASSERT_FALSE(std::isnan(d));
        for (float n : f.normal) ASSERT_TRUE(std::isfinite(n));
        const Frame ref = render_reference(v.view(), placement, cam, {iso});
        const ImageError e = compare_frames(f, ref, 1.0);
        EXPECT_EQ(e.mask_mismatch, 0u);
        EXPECT_LE(e.depth_max, 1e-3);
        EXPECT_GT(e.both_hit, 100u);
        EXPECT_LE(e.normal_max_deg, 0.5);
    }
}

std::string g(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

template <typename T> class ExtremeValues : public ::testing::Test {};
using FloatTypes = ::testing::Types<float, double>;
TYPED_TEST_SUITE(ExtremeValues, FloatTypes);

TYPED_TEST(ExtremeValues, HugeTinyAndNegativeScalesRenderLikeTheReference) {
    using T = TypeParam;
    const Dims dims{24, 22, 21};
    for (double scale : {1e30, -1e30, 1e-30, -1e-30}) {
        // values spanning [-|s|, |s|], iso at 0.3 s
        expect_matches_reference(scaled_ball<T>(dims, scale, 0.0), 0.3 * scale, "span, scale " + g(scale));
        // values near s * 1000, relative variations of 1e-3: iso at s * (1000 + 0.5), as T holds it
        const double iso = double(T(scale * 1000.5));
        expect_matches_reference(scaled_ball<T>(dims, scale, 1000.0), iso, "offset, scale " + g(scale));
    }
}

TYPED_TEST(ExtremeValues, ValuesAtTheLimitsOfTheType) {
    using T = TypeParam;
    const double big = double(std::numeric_limits<T>::max()) * 0.75;   // differences overflow T and double
    expect_matches_reference(scaled_ball<T>({20, 20, 20}, big, 0.0), 0.0, "near max");
    const double tiny = double(std::numeric_limits<T>::denorm_min()) * 4096;   // subnormal values
    expect_matches_reference(scaled_ball<T>({20, 20, 20}, tiny, 0.0), 0.0, "subnormal");
}

// ---------------------------------------------------------------------------------------------
/// Exit status of a shell command; its stdout and stderr are captured together in `out`.
int run(const std::string& cmd, std::string* out = nullptr) { return run_shell(cmd + " 2>&1", out); }

struct Dir : ScratchDir {
    Dir() : ScratchDir("octiso_extreme") {}
};

template <typename T> void write_raw(const std::string& path, const std::vector<T>& v) {
    std::ofstream f(path, std::ios::binary);
    f.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(T)));
}

std::string convert() { return kTools + "/octiso-convert "; }
std::string info() { return kTools + "/octiso-info "; }
std::string render_tool() { return kTools + "/octiso-render "; }

class ExtremeCli : public ::testing::Test {
protected:
    void SetUp() override {
        for (const char* tool : {"octiso-convert", "octiso-info", "octiso-render"})
            if (!fs::exists(kTools + "/" + tool)) {
                OCTISO_SKIP(tool << " not built");
            }
    }
};

template <typename T> void check_non_finite_refused_and_replaced(const std::string& type) {
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    for (double bad : {nan, inf, -inf}) {
        Dir dir;
        std::vector<T> v(5 * 4 * 3);
        for (size_t i = 0; i < v.size(); ++i) v[i] = T(double(i) * 0.5);
        v[2 + 5 * (3 + 4 * 1)] = T(bad);   // voxel (2,3,1)
        const std::string raw = dir.file("bad.raw"), out = dir.file("out.oct");
        write_raw(raw, v);
        std::string text;
        EXPECT_EQ(run(convert() + raw + " --dims 5,4,3 --type " + type + " -o " + out, &text), 2) << text;
        EXPECT_FALSE(fs::exists(out));
        EXPECT_EQ(dir.entries().size(), 1u) << "no output and no temporary left behind";
        EXPECT_NE(text.find(raw), std::string::npos) << "the message names the file: " << text;
        EXPECT_NE(text.find(std::isnan(bad) ? "NaN" : "infinite"), std::string::npos) << text;
        EXPECT_NE(text.find("--nan-as"), std::string::npos) << "the message names the way out: " << text;
        EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << "one line: " << text;

        ASSERT_EQ(run(convert() + raw + " --dims 5,4,3 --type " + type + " --nan-as -7.25 -o " + out, &text), 0)
            << text;
        const OctFile f = OctFile::open(out);
        std::vector<T> back(v.size());
        decode_to_dense(f.step<T>(0), back.data());
        for (size_t i = 0; i < v.size(); ++i) EXPECT_EQ(back[i], std::isfinite(double(v[i])) ? v[i] : T(-7.25)) << i;
    }
}

TEST_F(ExtremeCli, NonFiniteInputIsRefusedUnlessReplaced) {
    check_non_finite_refused_and_replaced<float>("f32");
    check_non_finite_refused_and_replaced<double>("f64");
}

TEST_F(ExtremeCli, VoxelCountsBeyond32BitsAreRefusedCleanly) {
    Dir dir;
    const std::string tiny = dir.file("tiny.raw"), out = dir.file("out.oct");
    write_raw(tiny, std::vector<uint8_t>(64, 1));
    const struct { const char* dims; const char* type; const char* expect; } cases[] = {
        {"70000,70000,1", "u8", "4900000000"},              // 4.9e9 voxels: > 2^32, the size is named
        {"70000,70000,70000", "f64", "2744000000000000"},   // 3.4e14 voxels: fits 64 bits, still wrong size
        {"1073741824,1073741824,1073741824", "f64", "overflow"},
        {"1073741824,1073741824,16", "u8", "overflow"},      // exactly 2^64 bytes
        {"1073741825,1,1", "u8", "1073741824"},              // beyond the largest extent
    };
    for (const auto& c : cases) {
        std::string text;
        EXPECT_EQ(run(convert() + tiny + " --dims " + c.dims + " --type " + c.type + " -o " + out, &text), 2)
            << c.dims << ": " << text;
        EXPECT_NE(text.find(c.expect), std::string::npos) << c.dims << ": " << text;
        EXPECT_FALSE(fs::exists(out));
        EXPECT_EQ(dir.entries().size(), 1u);
    }
}

TEST(ExtremeDims, CheckedArithmeticPaths) {
    EXPECT_EQ(checked_volume_bytes({70000, 70000, 1}, ScalarType::u8, "x"), 4900000000ull);
    EXPECT_EQ(checked_volume_bytes({70000, 70000, 1}, ScalarType::f64, "x"), 39200000000ull);
    const uint32_t m = Dims::kMaxExtent;
    EXPECT_EQ(checked_volume_bytes({m, m, 15}, ScalarType::u8, "x"), 15ull << 60);
    EXPECT_THROW(checked_volume_bytes({m, m, 16}, ScalarType::u8, "x"), Error);   // 2^64
    EXPECT_THROW(checked_volume_bytes({m, m, 8}, ScalarType::u16, "x"), Error);   // 2^64 bytes via the type
    EXPECT_THROW(checked_volume_bytes({m, m, m}, ScalarType::f64, "x"), Error);
    EXPECT_THROW(parse_dims("1073741825,1,1", "--dims"), Error);
    EXPECT_THROW(parse_dims("70000,70000,0", "--dims"), Error);
    EXPECT_THROW(parse_dims("70000,-1,2", "--dims"), Error);
    EXPECT_THROW(parse_dims("18446744073709551617,1,1", "--dims"), Error);
    const Dims ok = parse_dims("70000,70000,1", "--dims");
    EXPECT_EQ(ok.voxels(), 4900000000ull);
    EXPECT_EQ(dmax_for(ok), 17);
    EXPECT_EQ(dmax_for({m, 1, 1}), 30);
    // A raw file that claims 70000x70000x1 but holds 64 bytes: a clean Error, no mapping past its end.
    const fs::path p = fs::temp_directory_path() / ("octiso_tiny_" + std::to_string(::getpid()) + ".raw");
    write_raw(p.string(), std::vector<uint8_t>(64, 1));
    EXPECT_THROW(read_raw(p.string(), {70000, 70000, 1}, ScalarType::u8), Error);
    EXPECT_THROW(read_raw(p.string(), {m, m, m}, ScalarType::f64), Error);
    fs::remove(p);
}

// ---------------------------------------------------------------------------------------------
TEST(TinyVolumes, NoCellsNoHitsAndOneCellLikeTheReference) {
    const Placement placement;
    RenderOptions options;
    options.isovalues = {0.5};
    options.want_depth = options.want_normal = true;
    for (const Dims dims : {Dims{1, 1, 1}, Dims{1, 7, 5}, Dims{6, 1, 4}, Dims{3, 5, 1}, Dims{1, 1, 9}}) {
        DenseVolume<float> v{dims, std::vector<float>(dims.voxels())};
        for (size_t i = 0; i < v.values.size(); ++i) v.values[i] = float(i % 2);   // iso 0.5 everywhere between
        const auto data = build_octree(v.view(), {});
        for (bool embree : {true, false}) {
            options.use_embree = embree;
            for (const Camera& cam : {frame_data_box(dims, placement, 24, 20),
                                      Camera{{0.2, 0.3, 0.1}, {5, 5, 5}, {0, 0, 1}, 120, 17, 17}}) {
                const Frame f = render(data.view(), placement, cam, options);
                EXPECT_EQ(f.stats.hits, 0u) << dims.x << "x" << dims.y << "x" << dims.z;
                for (float d : f.depth) EXPECT_TRUE(std::isinf(d));
            }
        }
    }
    // 2x2x2: exactly one cell.
    DenseVolume<double> v{{2, 2, 2}, {0, 1, 0, 1, 1, 1, 0, 0}};
    const auto data = build_octree(v.view(), {});
    for (const Camera& cam : {frame_data_box(v.dims, placement, 40, 40), Camera{{0.5, 0.5, 0.5}, {1, 1, 0}, {0, 0, 1}, 100, 21, 21}}) {
        const Frame f = render(data.view(), placement, cam, options);
        const Frame ref = render_reference(v.view(), placement, cam, {0.5});
        const ImageError e = compare_frames(f, ref, 1.0);
        EXPECT_EQ(e.mask_mismatch, 0u);
        EXPECT_LE(e.depth_max, 1e-3);
        EXPECT_GT(e.both_hit, 20u);
    }
}

TEST_F(ExtremeCli, TinyVolumesThroughConvertInfoAndRender) {
    for (const char* dims : {"1,1,1", "1,9,6", "7,1,3", "2,2,2"}) {
        Dir dir;
        Dims d = parse_dims(dims, "--dims");
        std::vector<float> v(d.voxels());
        for (size_t i = 0; i < v.size(); ++i) v[i] = float((i * 37) % 5);
        const std::string raw = dir.file("in.raw"), oct = dir.file("in.oct");
        write_raw(raw, v);
        std::string text;
        ASSERT_EQ(run(convert() + raw + " --dims " + dims + " --type f32 -o " + oct, &text), 0) << dims << text;
        ASSERT_EQ(run(info() + oct + " --json 2>/dev/null", &text), 0) << dims << text;
        EXPECT_NE(text.find("\"dims\":[" + std::string(dims) + "]"), std::string::npos) << text;
        ASSERT_EQ(run(info() + oct + " --extract-raw " + dir.file("back.raw"), &text), 0) << text;
        EXPECT_EQ(fs::file_size(dir.file("back.raw")), v.size() * sizeof(float));
        ASSERT_EQ(run(render_tool() + oct + " --iso 1.5 --size 16x12 -o " + dir.file("img.png") + " --depth " +
                          dir.file("depth.exr") + " --json 2>/dev/null",
                      &text),
                  0)
            << dims << text;
        EXPECT_TRUE(fs::exists(dir.file("img.png")));
        EXPECT_TRUE(fs::exists(dir.file("depth.exr")));
        const bool has_cells = d.x >= 2 && d.y >= 2 && d.z >= 2;
        if (!has_cells) {
            EXPECT_NE(text.find("\"hits\":0"), std::string::npos) << dims << ": " << text;
        }
    }
}

}  // namespace
}  // namespace octiso::test
