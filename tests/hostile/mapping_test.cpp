// Issue 18, class 5: a mapped file that changes under octiso. Policy (src/util/mapping_guard.h):
// readers hold a shared flock and refuse a file locked exclusively; a file truncated or rewritten
// while mapped ends the process with one line naming it and exit 2, never a signal. Death tests
// fork, so each case runs in a child whose fault cannot take the test binary down.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include "hostile/hostile_util.h"
#include "octiso/error.h"
#include "octiso/oct_file.h"
#include "octiso/reader.h"
#include "octiso/render.h"

namespace octiso::test {
namespace {

struct HostileMapping : ::testing::Test {
    ScratchDir dir{"octiso_hostile_mapping"};
    std::string oct = dir.file("live.oct");
    void SetUp() override {
        GTEST_FLAG_SET(death_test_style, "threadsafe");
        const RunResult r = run_capture("'" + tool("octiso-convert") + "' --synthetic noise:64 -o '" + oct + "'", dir.file("err"));
        ASSERT_EQ(r.exit_status, 0) << r.err;
    }
};

// SIGBUS: the file shrinks after it was opened; the first validation touches the lost pages.
TEST_F(HostileMapping, TruncatedWhileMappedExits2NamingTheFile) {
    EXPECT_EXIT(
        {
            const OctFile f = OctFile::open(oct, Verify::Full);
            ::truncate(oct.c_str(), 8192);
            (void)f.step_sizes(0);   // reads past the new end of file
            std::_Exit(0);           // not reached if the pages are gone
        },
        ::testing::ExitedWithCode(2), "live.oct: the file changed while it was being read");
}

// SIGBUS or SIGSEGV during a render: `cp other.oct live.oct` truncates and rewrites in place.
TEST_F(HostileMapping, OverwrittenInPlaceDuringRenderNeverDiesOnASignal) {
    const std::string other = dir.file("other.oct");
    ASSERT_EQ(run_capture("'" + tool("octiso-convert") + "' --synthetic sphere:16 -o '" + other + "'", dir.file("err")).exit_status, 0);
    EXPECT_EXIT(
        {
            const OctFile f = OctFile::open(oct, Verify::Full);
            const Octree<uint8_t> tree = f.step<uint8_t>(0);   // validated
            std::filesystem::copy_file(other, oct, std::filesystem::copy_options::overwrite_existing);
            RenderOptions options;
            options.isovalues = {100};
            Frame frame;
            Renderer(tree, f.info().placement, options, RenderLimits{}).render(frame_data_box(f.info().dims, f.info().placement, 64, 64), frame);
            // No fault (every page read lay inside the new, shorter file): the result is garbage,
            // and the check the tools make before publishing must catch it.
            try {
                f.check_unchanged();
            } catch (const Error& e) {
                std::fprintf(stderr, "%s\n", e.what());
                std::_Exit(2);
            }
            std::_Exit(3);
        },
        ::testing::ExitedWithCode(2), "live.oct: the file changed while it was being read");
}

// The lock: a writer holding an exclusive flock makes readers refuse at once (no wait, exit 2).
TEST_F(HostileMapping, ExclusivelyLockedFileIsRefused) {
    const int fd = ::open(oct.c_str(), O_RDONLY);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::flock(fd, LOCK_EX), 0);
    EXPECT_THROW(OctFile::open(oct), Error);
    const RunResult r = run_capture("'" + tool("octiso-info") + "' '" + oct + "'", dir.file("err"));
    expect_refused(r, oct, "octiso-info on a locked file");
    ::flock(fd, LOCK_UN);
    EXPECT_NO_THROW(OctFile::open(oct));
    ::close(fd);
}

// Readers hold LOCK_SH: a cooperating writer's LOCK_EX|LOCK_NB fails while a file is open.
TEST_F(HostileMapping, OpenFileHoldsASharedLock) {
    const OctFile f = OctFile::open(oct);
    const int fd = ::open(oct.c_str(), O_RDONLY);
    ASSERT_GE(fd, 0);
    EXPECT_NE(::flock(fd, LOCK_EX | LOCK_NB), 0);
    EXPECT_EQ(errno, EWOULDBLOCK);
    EXPECT_EQ(::flock(fd, LOCK_SH | LOCK_NB), 0) << "other readers share it";
    ::close(fd);
}

// A raw input truncated while it is mapped for conversion.
TEST_F(HostileMapping, RawInputTruncatedWhileMappedExits2) {
    const std::string raw = dir.file("in.raw");
    write_text(raw, std::string(64 * 64 * 64, 'a'));
    EXPECT_EXIT(
        {
            const LoadedVolume v = read_raw(raw, Dims{64, 64, 64}, ScalarType::u8);
            ::truncate(raw.c_str(), 0);
            volatile uint64_t sum = 0;
            for (uint64_t i = 0; i < v.bytes(); i += 4096) sum = sum + uint64_t(v.data()[i]);
            std::_Exit(0);
        },
        ::testing::ExitedWithCode(2), "in.raw: the file changed while it was being read");
}

}  // namespace
}  // namespace octiso::test
