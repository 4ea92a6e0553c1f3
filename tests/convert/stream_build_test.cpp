// The out-of-core converter (src/convert/stream_build.cpp, issue 13) against the in-memory one:
// the same input converted both ways must give the same .oct file, byte for byte, for all 8
// scalar types, odd and power-of-two grids, forced small pieces (so that every seam between
// pieces and slabs is crossed), --iso-range, --tolerance, --nan-as, big-endian input with an
// offset, series, and node arrays spilled to disk. A budget too small for one slab is refused
// before anything is written; temporaries never outlive the conversion.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <random>

#include "convert/stream_build.h"
#include "octiso/convert.h"
#include "octiso/error.h"
#include "test_util/scratch_dir.h"

namespace octiso::test {
namespace {

std::string slurp(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

void write_bytes(const std::string& path, const void* data, size_t n) {
    std::ofstream(path, std::ios::binary).write(static_cast<const char*>(data), std::streamsize(n));
}

/// Values from a small palette (so that siblings merge into scalar leaves and iso-range clamps)
/// with runs of constant blocks and some noise; seeded.
template <typename T> std::vector<T> field(Dims d, uint32_t seed) {
    std::mt19937 rng(seed);
    const double palette[] = {0, 3, 7, 10, 40, 90, 100, 120};
    std::vector<T> v(d.voxels());
    for (uint64_t i = 0; i < v.size(); ++i) {
        const uint64_t x = i % d.x, y = i / d.x % d.y, z = i / (uint64_t(d.x) * d.y);
        const bool block = ((x / 4 + y / 3 + z / 5) % 3) == 0;
        const double p = palette[block ? (x / 4 + z) % 2 : rng() % 8];
        const double noise = std::is_floating_point_v<T> && rng() % 4 == 0 ? double(rng() % 1000) / 997.0 : 0.0;
        v[i] = T(p + noise);
    }
    return v;
}

RawOptions raw_of(Dims d, ScalarType t) {
    RawOptions raw;
    raw.dims = d;
    raw.type = t;
    return raw;
}

MemoryOptions streamed(uint32_t piece_side, uint64_t budget = uint64_t(1) << 30) {
    MemoryOptions m;
    m.budget = budget;
    m.piece_side = piece_side;
    return m;
}

/// Converts `source` in memory and out of core with `memory`; the two files must be identical.
void expect_identical(ScratchDir& dir, const ConvertSource& source, const BuildOptions& options, const MemoryOptions& memory,
                      const std::string& what) {
    const std::string a = dir.file("in_memory.oct"), b = dir.file("streamed.oct");
    const ConvertReport ra = convert(source, a, options);
    const ConvertReport rb = convert(source, b, options, memory);
    ASSERT_FALSE(ra.streamed) << what;
    ASSERT_TRUE(rb.streamed) << what;
    const std::string fa = slurp(a), fb = slurp(b);
    ASSERT_FALSE(fa.empty()) << what;
    ASSERT_EQ(fa.size(), fb.size()) << what;
    EXPECT_TRUE(fa == fb) << what << ": the streamed file differs from the in-memory one";
    EXPECT_EQ(ra.total.nodes_per_depth, rb.total.nodes_per_depth) << what;
    EXPECT_EQ(ra.total.scalar_leaves_per_depth, rb.total.scalar_leaves_per_depth) << what;
    EXPECT_EQ(rb.bytes_read, rb.input_bytes) << what << ": every input byte read exactly once";
    // Nothing but the two outputs (and the inputs) is left: no spill file, no temporary.
    for (const std::string& e : dir.entries()) EXPECT_EQ(e.find(".tmp-"), std::string::npos) << what << ": left " << e;
}

template <typename T> class StreamBuildTyped : public ::testing::Test {};
using AllTypes = ::testing::Types<uint8_t, int8_t, uint16_t, int16_t, uint32_t, int32_t, float, double>;
TYPED_TEST_SUITE(StreamBuildTyped, AllTypes);

TYPED_TEST(StreamBuildTyped, SameBytesAsInMemoryOverGridsPiecesAndOptions) {
    using T = TypeParam;
    const ScalarType type = scalar_type_of<T>();
    const Dims grids[] = {{1, 1, 1}, {2, 3, 5}, {65, 33, 17}, {4, 4, 4}, {16, 16, 16}, {9, 20, 70}, {33, 2, 40}};
    uint32_t seed = 1;
    for (const Dims d : grids) {
        ScratchDir dir("stream_build");
        const std::vector<T> v = field<T>(d, seed++);
        const std::string in = dir.file("in.raw");
        write_bytes(in, v.data(), v.size() * sizeof(T));
        const ConvertSource source = ConvertSource::file(in, raw_of(d, type));
        BuildOptions plain, iso, tol, both;
        iso.iso_range = std::array<double, 2>{5, 95};
        tol.tolerance = 3.5;
        both.iso_range = std::array<double, 2>{8, 60};
        both.tolerance = 2;
        const std::pair<const char*, BuildOptions*> option_sets[] = {{"plain", &plain}, {"iso", &iso}, {"tol", &tol}, {"both", &both}};
        for (const uint32_t side : {4u, 8u, 0u})
            for (const auto& [name, opt] : option_sets) {
                const std::string what = std::string(scalar_type_name(type)) + " " + std::to_string(d.x) + "x" +
                                         std::to_string(d.y) + "x" + std::to_string(d.z) + " side " + std::to_string(side) +
                                         " " + name;
                expect_identical(dir, source, *opt, streamed(side), what);
            }
    }
}

TYPED_TEST(StreamBuildTyped, BigEndianWithOffsetReadInSlabs) {
    using T = TypeParam;
    const Dims d{19, 7, 23};
    ScratchDir dir("stream_endian");
    std::vector<T> v = field<T>(d, 77);
    std::vector<std::byte> bytes(13 + v.size() * sizeof(T), std::byte{0x5a});
    for (uint64_t i = 0; i < v.size(); ++i) {
        std::byte e[sizeof(T)];
        std::memcpy(e, &v[i], sizeof(T));
        for (size_t k = 0; k < sizeof(T); ++k) bytes[13 + i * sizeof(T) + k] = e[sizeof(T) - 1 - k];
    }
    const std::string in = dir.file("big.raw");
    write_bytes(in, bytes.data(), bytes.size());
    RawOptions raw = raw_of(d, scalar_type_of<T>());
    raw.endian = Endian::big;
    raw.offset = 13;
    expect_identical(dir, ConvertSource::file(in, raw), BuildOptions{}, streamed(4), "big endian, offset 13");
}

TEST(StreamBuild, NanAsAndNonFiniteRefusalMatchTheInMemoryBuild) {
    const Dims d{10, 9, 30};
    ScratchDir dir("stream_nan");
    std::vector<float> v = field<float>(d, 5);
    v[d.voxels() - 40] = std::numeric_limits<float>::quiet_NaN();   // in the last slab
    v[d.voxels() - 3] = std::numeric_limits<float>::infinity();
    const std::string in = dir.file("nan.raw");
    write_bytes(in, v.data(), v.size() * sizeof(float));
    const ConvertSource source = ConvertSource::file(in, raw_of(d, ScalarType::f32));
    BuildOptions replace;
    replace.nan_as = 50;
    replace.iso_range = std::array<double, 2>{5, 95};
    expect_identical(dir, source, replace, streamed(4), "--nan-as with --iso-range");

    std::string in_memory, out_of_core;
    try {
        convert(source, dir.file("a.oct"), BuildOptions{});
    } catch (const Error& e) {
        in_memory = e.what();
        EXPECT_EQ(e.exit_status(), 2);
    }
    try {
        convert(source, dir.file("b.oct"), BuildOptions{}, streamed(4));
    } catch (const Error& e) {
        out_of_core = e.what();
        EXPECT_EQ(e.exit_status(), 2);
    }
    EXPECT_FALSE(in_memory.empty());
    EXPECT_EQ(in_memory, out_of_core);
    for (const std::string& e : dir.entries()) EXPECT_TRUE(e == "nan.raw" || e == "in_memory.oct" || e == "streamed.oct") << e;
}

TEST(StreamBuild, SeriesStepByStep) {
    const Dims d{21, 12, 18};
    ScratchDir dir("stream_series");
    for (int s = 0; s < 3; ++s) {
        const std::vector<int16_t> v = field<int16_t>(d, 100 + uint32_t(s));
        char name[32];
        std::snprintf(name, sizeof name, "t_%02d.raw", s);
        write_bytes(dir.file(name), v.data(), v.size() * sizeof(int16_t));
    }
    BuildOptions iso;
    iso.iso_range = std::array<double, 2>{5, 95};
    expect_identical(dir, ConvertSource::pattern(dir.file("t_%02d.raw"), 0, 2, raw_of(d, ScalarType::i16)), iso,
                     streamed(8), "series of 3");
}

TEST(StreamBuild, SpillsToDiskUnderATightBudgetAndCleansUp) {
    const Dims d{40, 36, 64};
    ScratchDir dir("stream_spill");
    const std::vector<uint16_t> v = field<uint16_t>(d, 9);
    const std::string in = dir.file("in.raw");
    write_bytes(in, v.data(), v.size() * sizeof(uint16_t));
    const convert_detail::StreamPlan p = convert_detail::plan_stream(d, ScalarType::u16, BuildOptions{}, uint64_t(1) << 30, 4, "in.raw");
    const uint64_t tight = p.slab_bytes + p.fixed_bytes + 1024;   // almost nothing left for spilled arrays
    const ConvertSource source = ConvertSource::file(in, raw_of(d, ScalarType::u16));
    const ConvertReport r = convert(source, dir.file("tight.oct"), BuildOptions{}, streamed(4, tight));
    EXPECT_GT(r.spilled_bytes, 0u);
    convert(source, dir.file("mem.oct"), BuildOptions{});
    EXPECT_TRUE(slurp(dir.file("tight.oct")) == slurp(dir.file("mem.oct")));
    EXPECT_EQ(dir.entries(), (std::vector<std::string>{"in.raw", "mem.oct", "tight.oct"}));
}

TEST(StreamBuild, BudgetTooSmallForOneSlabIsRefusedBeforeAnyWork) {
    const Dims d{300, 200, 50};
    ScratchDir dir("stream_budget");
    const std::vector<uint8_t> v(d.voxels(), 3);
    const std::string in = dir.file("in.raw");
    write_bytes(in, v.data(), v.size());
    try {
        convert(ConvertSource::file(in, raw_of(d, ScalarType::u8)), dir.file("out.oct"), BuildOptions{},
                streamed(0, 64 * 1024));
        FAIL() << "a 64 KiB budget was accepted";
    } catch (const Error& e) {
        EXPECT_EQ(e.exit_status(), 2);
        EXPECT_EQ(e.subject(), in);
        EXPECT_NE(std::string(e.what()).find("out of memory"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("--memory"), std::string::npos) << e.what();
    }
    EXPECT_EQ(dir.entries(), std::vector<std::string>{"in.raw"});
}

// Wide layers (3072^2, the larger-than-RAM benchmark): no side leaves half of 2 GiB to the
// spill store, so the plan takes the side that needs least (16: smaller pieces add per-piece
// summaries for the whole volume, larger ones a bigger slab) instead of the smallest side,
// whose 768^3 pieces would need 30 GiB; and 1 GiB is refused naming what the cheapest needs.
TEST(StreamBuild, WideLayersTakeTheSideThatNeedsLeast) {
    const Dims d{3072, 3072, 3072};
    const convert_detail::StreamPlan p =
        convert_detail::plan_stream(d, ScalarType::u8, BuildOptions{}, uint64_t(2) << 30, 0, "wide.raw");
    EXPECT_EQ(p.piece_side, 16u);
    EXPECT_LE(p.slab_bytes + p.fixed_bytes, uint64_t(2) << 30);
    for (uint32_t side : {4u, 8u, 32u, 64u}) {
        const convert_detail::StreamPlan q =
            convert_detail::plan_stream(d, ScalarType::u8, BuildOptions{}, uint64_t(64) << 30, side, "wide.raw");
        EXPECT_GT(q.slab_bytes + q.fixed_bytes, p.slab_bytes + p.fixed_bytes) << side;
    }
    try {
        convert_detail::plan_stream(d, ScalarType::u8, BuildOptions{}, uint64_t(1) << 30, 0, "wide.raw");
        ADD_FAILURE() << "1 GiB accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("one slab of 16 layers"), std::string::npos) << e.what();
    }
}

TEST(StreamBuild, FailureInALaterStepLeavesNoTemporaries) {
    const Dims d{12, 12, 40};
    ScratchDir dir("stream_fail");
    std::vector<float> good = field<float>(d, 1), bad = good;
    bad[d.voxels() / 2] = std::numeric_limits<float>::quiet_NaN();
    write_bytes(dir.file("s0.raw"), good.data(), good.size() * sizeof(float));
    write_bytes(dir.file("s1.raw"), bad.data(), bad.size() * sizeof(float));
    const convert_detail::StreamPlan p = convert_detail::plan_stream(d, ScalarType::f32, BuildOptions{}, uint64_t(1) << 30, 4, "s0.raw");
    try {
        convert(ConvertSource::files({dir.file("s0.raw"), dir.file("s1.raw")}, raw_of(d, ScalarType::f32)), dir.file("out.oct"),
                BuildOptions{}, streamed(4, p.slab_bytes + p.fixed_bytes + 1024));
        FAIL() << "a NaN in step 1 was accepted";
    } catch (const Error& e) {
        EXPECT_EQ(e.subject(), dir.file("s1.raw"));
        EXPECT_NE(std::string(e.what()).find("NaN"), std::string::npos) << e.what();
    }
    EXPECT_EQ(dir.entries(), (std::vector<std::string>{"s0.raw", "s1.raw"}));
}

}  // namespace
}  // namespace octiso::test
