// octiso-info end to end (CONVENTIONS 3): --json gives one JSON object on stdout, --extract-raw
// gives the input array back byte for byte (little or big endian), bad files exit 2 and leave no
// output behind. Skipped when the tool has not been built next to the tests.
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>

#include "test_util/run_shell.h"
#include "format/oct_test_util.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

const std::string kInfo = std::string(OCTISO_TOOLS_DIR) + "/octiso-info";

/// Runs a shell command; returns its exit status and captures stdout.
int run(const std::string& cmd, std::string& out) { return run_shell(cmd, &out); }

class InfoCli : public ::testing::Test {
protected:
    void SetUp() override {
        if (!std::filesystem::exists(kInfo)) {
            OCTISO_SKIP(kInfo << " not built");
        }
    }
};

TEST_F(InfoCli, JsonReportAndRawExtraction) {
    ScratchDir dir;
    const auto v0 = make_volume<int16_t>({21, 9, 14}, Pattern::Sparse, 1);
    const auto v1 = make_volume<int16_t>({21, 9, 14}, Pattern::Random, 2);
    const auto b0 = build_octree(v0.view(), {});
    const auto b1 = build_octree(v1.view(), {});
    const std::string oct = dir.file("s.oct");
    write_oct<int16_t>(oct, info_for(ScalarType::i16, v0.dims), {b0.view(), b1.view()});

    std::string out;
    ASSERT_EQ(run(kInfo + " " + oct + " --json 2>/dev/null", out), 0);
    EXPECT_EQ(out.front(), '{');
    EXPECT_EQ(out.substr(out.size() - 2), "}\n");
    EXPECT_NE(out.find("\"type\":\"i16\""), std::string::npos) << out;
    EXPECT_NE(out.find("\"dims\":[21,9,14]"), std::string::npos) << out;
    EXPECT_NE(out.find("\"steps\":2"), std::string::npos) << out;
    EXPECT_NE(out.find("\"raw_bytes\":" + std::to_string(21 * 9 * 14 * 2 * 2)), std::string::npos) << out;
    EXPECT_NE(out.find("\"file_bytes\":" + std::to_string(std::filesystem::file_size(oct))), std::string::npos);
    EXPECT_NE(out.find("\"iso_range\":[-1.5,7]"), std::string::npos) << out;

    // Without --json the human report goes to stdout.
    ASSERT_EQ(run(kInfo + " " + oct + " 2>/dev/null", out), 0);
    EXPECT_NE(out.find("i16"), std::string::npos);

    const std::string raw = dir.file("out.raw");
    ASSERT_EQ(run(kInfo + " " + oct + " --extract-raw " + raw + " --step 1 >/dev/null 2>&1", out), 0);
    const std::vector<char> got = read_bytes(raw);
    ASSERT_EQ(got.size(), v1.values.size() * 2);
    EXPECT_EQ(0, std::memcmp(got.data(), v1.values.data(), got.size()));

    ASSERT_EQ(run(kInfo + " " + oct + " --extract-raw " + raw + " --endian big >/dev/null 2>&1", out), 0);
    const std::vector<char> big = read_bytes(raw);
    ASSERT_EQ(big.size(), v0.values.size() * 2);
    for (size_t i = 0; i < v0.values.size(); ++i) {
        const uint16_t u = uint16_t(v0.values[i]);
        ASSERT_EQ(uint8_t(big[2 * i]), uint8_t(u >> 8)) << i;
        ASSERT_EQ(uint8_t(big[2 * i + 1]), uint8_t(u & 0xff)) << i;
    }
}

TEST_F(InfoCli, BadInputExitsTwoAndWritesNothing) {
    ScratchDir dir;
    const auto v = make_volume<uint8_t>({5, 5, 5}, Pattern::Random, 1);
    const auto b = build_octree(v.view(), {});
    const std::string oct = dir.file("a.oct");
    write_oct<uint8_t>(oct, info_for(ScalarType::u8, v.dims), {b.view()});
    std::vector<char> bytes = read_bytes(oct);
    bytes[bytes.size() / 2] ^= 0x10;
    write_bytes(dir.file("bad.oct"), bytes.data(), bytes.size());

    std::string out;
    EXPECT_EQ(run(kInfo + " " + dir.file("bad.oct") + " --extract-raw " + dir.file("x.raw") + " 2>/dev/null", out), 2);
    EXPECT_EQ(run(kInfo + " " + dir.file("missing.oct") + " 2>/dev/null", out), 2);
    EXPECT_EQ(run(kInfo + " " + oct + " --step 3 2>/dev/null", out), 2);       // --step without --extract-raw
    EXPECT_EQ(run(kInfo + " " + oct + " --extract-raw " + dir.file("x.raw") + " --step 1 2>/dev/null", out), 2);
    EXPECT_EQ(run(kInfo + " " + oct + " --bogus 2>/dev/null", out), 2);
    EXPECT_EQ(run(kInfo + " 2>/dev/null", out), 2);
    EXPECT_FALSE(std::filesystem::exists(dir.file("x.raw")));
    for (const std::string& e : dir.entries()) EXPECT_EQ(e.find(".tmp-"), std::string::npos) << e;
}

}  // namespace
}  // namespace octiso::test
