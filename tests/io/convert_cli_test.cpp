// octiso-convert end to end (CONVENTIONS 3): raw, VTK-format and synthetic inputs become .oct
// files that decode back to the input exactly; --json prints one object whose sizes match the
// file; a time series converts into one file; every bad input or usage exits 2 and leaves no
// output file (nor a temporary) behind. Skipped (failed under OCTISO_REQUIRE_ALL=1) when the tool is not built next to the tests.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "test_util/run_shell.h"
#include "octiso/decode.h"
#include "octiso/oct_file.h"
#include "octiso/synthetic.h"
#include "test_util/scratch_dir.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

namespace fs = std::filesystem;
const std::string kConvert = std::string(OCTISO_TOOLS_DIR) + "/octiso-convert";

struct CliDir : ScratchDir {
    CliDir() : ScratchDir("octiso_convert") {}
};

/// Exit status of `args` run through the shell with stdout captured; stderr is discarded.
int run(const std::string& args, std::string* out = nullptr) {
    return run_shell("'" + kConvert + "' " + args + " 2>/dev/null", out);
}

template <typename T> std::vector<T> ramp(Dims d, int salt) {
    std::vector<T> v(d.voxels());
    for (uint64_t i = 0; i < v.size(); ++i) v[i] = T((i * 7 + uint64_t(salt) * 13) % 97 / (i % 5 == 0 ? 1 : 3));
    return v;
}

template <typename T> void write_raw(const std::string& path, const std::vector<T>& v, bool big, size_t offset = 0) {
    std::ofstream f(path, std::ios::binary);
    f << std::string(offset, 'h');
    for (T x : v) {
        char b[sizeof(T)];
        std::memcpy(b, &x, sizeof(T));
        if (big == (std::endian::native == std::endian::little)) std::reverse(b, b + sizeof(T));
        f.write(b, sizeof(T));
    }
}

template <typename T> std::vector<T> decoded(const OctFile& f, uint32_t step) {
    std::vector<T> out(f.info().dims.voxels());
    decode_to_dense(f.step<T>(step), out.data());
    return out;
}

/// The unsigned integer after "key": in a flat JSON text (enough for our own report).
uint64_t json_uint(const std::string& json, const std::string& key) {
    const size_t at = json.find("\"" + key + "\":");
    if (at == std::string::npos) return UINT64_MAX;
    return std::stoull(json.substr(at + key.size() + 3));
}

class ConvertCli : public ::testing::Test {
protected:
    void SetUp() override {
        if (!fs::exists(kConvert)) {
            OCTISO_SKIP(kConvert << " not built");
        }
    }
};

TEST_F(ConvertCli, RawBigEndianWithOffsetRoundTrips) {
    CliDir dir;
    const Dims d{13, 7, 9};
    const std::vector<int16_t> v = ramp<int16_t>(d, 1);
    write_raw(dir.file("in.raw"), v, true, 5);
    const std::string out = dir.file("out.oct");
    ASSERT_EQ(run(dir.file("in.raw") + " -o " + out + " --dims 13,7,9 --type i16 --endian big --offset 5 "
                  "--spacing 0.5,1,2 --origin 1,2,3 --threads 1"), 0);
    const OctFile f = OctFile::open(out);
    EXPECT_EQ(f.info().type, ScalarType::i16);
    EXPECT_EQ(f.info().dims, d);
    EXPECT_EQ(f.info().placement.spacing, (std::array<double, 3>{0.5, 1, 2}));
    EXPECT_EQ(f.info().placement.origin, (std::array<double, 3>{1, 2, 3}));
    EXPECT_EQ(f.info().step_count, 1u);
    EXPECT_TRUE(decoded<int16_t>(f, 0) == v);
}

TEST_F(ConvertCli, VtkFormatAndSyntheticRoundTrip) {
    CliDir dir;
    // a NRRD written by hand, with its placement
    const Dims d{12, 5, 6};
    const std::vector<float> v = ramp<float>(d, 2);
    std::ofstream(dir.file("in.nrrd"), std::ios::binary)
        << "NRRD0004\ntype: float\ndimension: 3\nsizes: 12 5 6\nspacings: 2 3 4\nencoding: raw\nendian: little\n\n";
    write_raw(dir.file("in.raw"), v, false);
    {
        std::ifstream data(dir.file("in.raw"), std::ios::binary);
        std::ofstream(dir.file("in.nrrd"), std::ios::binary | std::ios::app) << data.rdbuf();
    }
    ASSERT_EQ(run(dir.file("in.nrrd") + " -o " + dir.file("n.oct")), 0);
    const OctFile n = OctFile::open(dir.file("n.oct"));
    EXPECT_EQ(n.info().placement.spacing, (std::array<double, 3>{2, 3, 4}));
    EXPECT_TRUE(decoded<float>(n, 0) == v);

    // a synthetic plume with a type override
    ASSERT_EQ(run("--synthetic plume:20,18,16 --type u16 -o " + dir.file("p.oct")), 0);
    const OctFile p = OctFile::open(dir.file("p.oct"));
    EXPECT_EQ(p.info().type, ScalarType::u16);
    EXPECT_TRUE(decoded<uint16_t>(p, 0) == generate_synthetic<uint16_t>("plume", {20, 18, 16}));
}

TEST_F(ConvertCli, JsonIsOneObjectThatMatchesTheFile) {
    CliDir dir;
    const std::string out = dir.file("s.oct");
    std::string json;
    ASSERT_EQ(run("--synthetic sphere:24 --type u8 --json -o " + out, &json), 0);
    ASSERT_FALSE(json.empty());
    EXPECT_EQ(json.front(), '{');
    EXPECT_EQ(json[json.find_last_not_of('\n')], '}');
    EXPECT_EQ(json.find('\n'), json.size() - 1) << "one line, one object";
    EXPECT_EQ(json_uint(json, "file_bytes"), fs::file_size(out));
    EXPECT_EQ(json_uint(json, "input_bytes"), 24u * 24u * 24u);
    for (const char* key : {"\"split\"", "\"interior_bytes\"", "\"cap_bytes\"", "\"minmax_bytes\"", "\"ratio\"",
                            "\"depths\"", "\"scalar_leaves\"", "\"build_seconds\"", "\"total_seconds\"",
                            "\"mvoxels_per_second\"", "\"peak_rss_bytes\"", "\"threads\"", "\"type\":\"u8\"",
                            "\"dims\":[24,24,24]", "\"phases\"", "\"pieces\"", "\"concatenate\"", "\"release\"",
                            "\"read\"", "\"write\""})
        EXPECT_NE(json.find(key), std::string::npos) << key;
    EXPECT_GT(json_uint(json, "peak_rss_bytes"), 0u);
}

TEST_F(ConvertCli, TimeSeriesFromPatternAndSynthetic) {
    CliDir dir;
    const Dims d{9, 10, 11};
    std::vector<std::vector<uint8_t>> steps;
    for (int k = 3; k <= 5; ++k) {
        steps.push_back(ramp<uint8_t>(d, k));
        char name[32];
        std::snprintf(name, sizeof name, "t_%02d.raw", k);
        write_raw(dir.file(name), steps.back(), false);
    }
    const std::string out = dir.file("series.oct");
    ASSERT_EQ(run("--steps 3:5 '" + dir.file("t_%02d.raw") + "' --dims 9,10,11 --type u8 -o " + out), 0);
    const OctFile f = OctFile::open(out);
    ASSERT_EQ(f.info().step_count, 3u);
    for (uint32_t k = 0; k < 3; ++k) EXPECT_TRUE(decoded<uint8_t>(f, k) == steps[k]) << k;

    ASSERT_EQ(run("--synthetic plume-series:16,3 -o " + dir.file("ps.oct")), 0);
    const OctFile ps = OctFile::open(dir.file("ps.oct"));
    ASSERT_EQ(ps.info().step_count, 3u);
    for (uint32_t k = 0; k < 3; ++k)
        EXPECT_TRUE(decoded<uint8_t>(ps, k) == generate_synthetic<uint8_t>("plume-series", {16, 16, 16}, k)) << k;

    // a missing or mismatched step fails before anything is written
    fs::remove(out);
    write_raw(dir.file("t_06.raw"), std::vector<uint8_t>(10, 1), false);
    EXPECT_EQ(run("--steps 3:6 '" + dir.file("t_%02d.raw") + "' --dims 9,10,11 --type u8 -o " + out), 2);
    EXPECT_FALSE(fs::exists(out));
    EXPECT_EQ(run("--steps 3:7 '" + dir.file("t_%02d.raw") + "' --dims 9,10,11 --type u8 -o " + out), 2);
    EXPECT_FALSE(fs::exists(out));
}

TEST_F(ConvertCli, BadInputExitsTwoAndLeavesNothing) {
    CliDir dir;
    const std::string raw = dir.file("in.raw");
    write_raw(raw, std::vector<uint8_t>(60, 7), false);
    std::ofstream(dir.file("trunc.vti")) << "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\">\n<Image";
    fs::create_directories(dir.file("adir"));
    const auto before = dir.entries();
    const std::string out = dir.file("out.oct");
    const std::string bad[] = {
        raw + " -o " + out,                                        // raw without --dims/--type
        raw + " -o " + out + " --dims 3,4,5",                      // without --type
        raw + " -o " + out + " --dims 3,4,6 --type u8",            // size mismatch
        raw + " -o " + out + " --dims 3,4,5 --type u16",           // size mismatch by type
        raw + " -o " + out + " --dims 3,4,5 --type u9",            // unknown type
        raw + " -o " + out + " --dims 0,4,5 --type u8",            // zero dims
        raw + " -o " + out + " --dims 1073741824,1073741824,1073741824 --type f64",   // overflow
        raw + " -o " + out + " --dims 3,4,5 --type u8 --offset 61",
        raw + " -o " + out + " --dims 3,4,5 --type u8 --endian middle",
        raw + " -o " + out + " --dims 3,4,5 --type u8 --bogus",    // unknown flag
        raw + " -o " + out + " --dims 3,4,5 --type u8 --threads -1",   // 0 means all cores
        raw + " -o " + out + " --dims 3,4,5 --type u8 --spacing 1,0,1",
        raw + " --dims 3,4,5 --type u8",                           // no -o
        dir.file("missing.raw") + " -o " + out + " --dims 3,4,5 --type u8",
        dir.file("adir") + " -o " + out + " --dims 3,4,5 --type u8",
        dir.file("trunc.vti") + " -o " + out,
        "--synthetic teapot:8 -o " + out,
        "--synthetic sphere:8 --dims 8,8,8 -o " + out,
        "--steps 0:1 '" + dir.file("none_%d.raw") + "' --dims 3,4,5 --type u8 -o " + out,
        "--steps 0:1 '" + dir.file("none.raw") + "' --dims 3,4,5 --type u8 -o " + out,   // no %d field
        "",
    };
    for (const std::string& args : bad) {
        EXPECT_EQ(run(args), 2) << args;
        EXPECT_FALSE(fs::exists(out)) << args;
        EXPECT_EQ(dir.entries(), before) << "leftover file after: " << args;
    }
}

TEST_F(ConvertCli, UnwritableOutputLeavesNothing) {
    CliDir dir;
    const std::string out = dir.file("no/such/dir/out.oct");
    // A directory that does not exist is an environment failure, not bad input: CONVENTIONS 3
    // gives it status 1, with one line on stderr naming the file. Exactly 1 and exactly one line,
    // so that a crash or a sanitizer report (a signal, or pages of stderr) cannot pass.
    std::string err;
    EXPECT_EQ(run_shell("'" + kConvert + "' --synthetic sphere:8 -o '" + out + "' 2>&1 >/dev/null", &err), 1) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_NE(err.find("no/such/dir"), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace octiso::test
