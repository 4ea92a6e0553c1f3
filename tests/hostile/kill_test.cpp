// Issue 18, class 8: kills during conversion and rendering. Whenever the signal lands, the final
// path holds the old file (or nothing) and a complete new one is never half there; after SIGTERM,
// SIGINT or SIGHUP no temporary remains; after SIGKILL (which no handler sees) the next write into
// the folder removes the dead process's temporary. The kill waits for the temporary to exist
// (polling the folder, not a clock), so it always lands while one is live.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include "hostile/hostile_util.h"
#include "util/atomic_output.h"
#include "octiso/image.h"
#include "octiso/oct_file.h"
#include "octiso/verify.h"

namespace octiso::test {
namespace {

/// Starts `argv` with stdout and stderr on /dev/null; returns the child's pid.
pid_t spawn(const std::vector<std::string>& argv) {
    const pid_t pid = ::fork();
    if (pid == 0) {
        // A shell without job control starts background jobs with SIGINT and SIGQUIT ignored, and
        // an ignored signal stays ignored across exec (octiso then keeps ignoring it, as it should):
        // give the tool the default dispositions a user's terminal would.
        for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) ::signal(sig, SIG_DFL);
        const int null = ::open("/dev/null", O_WRONLY);
        ::dup2(null, 1);
        ::dup2(null, 2);
        std::vector<char*> args;
        for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
        args.push_back(nullptr);
        ::execv(args[0], args.data());
        ::_exit(127);
    }
    return pid;
}

/// Polls `dir` until a temporary appears (true) or the child has exited (false, status in *status).
bool wait_for_temporary(pid_t pid, const std::filesystem::path& dir, int* status) {
    for (;;) {
        if (!temporaries(dir).empty()) return true;
        if (::waitpid(pid, status, WNOHANG) == pid) return false;
        ::usleep(500);
    }
}

struct HostileKill : ::testing::TestWithParam<int> {
    ScratchDir dir{"octiso_hostile_kill"};
    std::string out = dir.file("out.oct");
    void SetUp() override {
        const RunResult r = run_capture("'" + tool("octiso-convert") + "' --synthetic sphere:8 -o '" + out + "'", dir.file("err"));
        ASSERT_EQ(r.exit_status, 0) << r.err;
        std::filesystem::remove(dir.file("err"));
        old_ = read_all(out);
    }
    std::string old_;

    /// Kills a long conversion onto `out` with `sig` while its temporary exists.
    void kill_conversion(int sig) {
        const pid_t pid = spawn({tool("octiso-convert"), "--synthetic", "plume-series:40,2000", "--threads", "1", "-o", out});
        int status = 0;
        ASSERT_TRUE(wait_for_temporary(pid, dir.path(), &status)) << "the conversion ended before its temporary appeared";
        ASSERT_EQ(::kill(pid, sig), 0);
        ASSERT_EQ(::waitpid(pid, &status, 0), pid);
        ASSERT_TRUE(WIFSIGNALED(status)) << "status " << status;
        EXPECT_EQ(WTERMSIG(status), sig);
        EXPECT_EQ(read_all(out), old_) << "the final path must still hold the old file";
    }
};

TEST_P(HostileKill, CatchableSignalDuringConversionLeavesOldFileAndNoTemporary) {
    kill_conversion(GetParam());
    EXPECT_TRUE(temporaries(dir.path()).empty()) << temporaries(dir.path()).front();
}

INSTANTIATE_TEST_SUITE_P(Signals, HostileKill, ::testing::Values(SIGTERM, SIGINT, SIGHUP),
                         [](const auto& info) { return std::string(sigabbrev_np(info.param)); });

TEST_F(HostileKill, SigkillLeavesATemporaryThatTheNextWriteRemoves) {
    kill_conversion(SIGKILL);
    ASSERT_EQ(temporaries(dir.path()).size(), 1u) << "SIGKILL cannot be caught: its temporary stays";
    const RunResult r = run_capture("'" + tool("octiso-convert") + "' --synthetic sphere:10 -o '" + dir.file("next.oct") + "'",
                                    dir.file("err"));
    ASSERT_EQ(r.exit_status, 0) << r.err;
    EXPECT_TRUE(temporaries(dir.path()).empty()) << "the next write into the folder must clean the dead process's temporary";
    EXPECT_NO_THROW(verify_octree(OctFile::open(dir.file("next.oct"))));
    EXPECT_EQ(read_all(out), old_);
}

TEST(HostileKillSweep, StaleTemporariesOfDeadProcessesOnlyAreRemoved) {
    ScratchDir dir("octiso_hostile_sweep");
    const pid_t dead = ::fork();
    if (dead == 0) ::_exit(0);
    ASSERT_EQ(::waitpid(dead, nullptr, 0), dead);   // reaped: no process has this pid now
    const std::string dead_tmp = ".tmp-" + std::to_string(dead) + "-a.png";
    const std::string live_tmp = ".tmp-" + std::to_string(::getppid()) + "-b.png";   // our parent is alive
    const std::string not_ours = ".tmp-notapid-c.png";
    for (const std::string& n : {dead_tmp, live_tmp, not_ours}) write_text(dir.file(n), "x");
    EXPECT_EQ(io::remove_stale_temporaries(dir.path().string()), 1);
    EXPECT_FALSE(std::filesystem::exists(dir.file(dead_tmp)));
    EXPECT_TRUE(std::filesystem::exists(dir.file(live_tmp)));
    EXPECT_TRUE(std::filesystem::exists(dir.file(not_ours)));
}

/// A series render killed while a frame's temporary exists: the frames already there are
/// complete images, and no temporary remains (SIGTERM), or the next render removes it (SIGKILL).
TEST(HostileKillRender, KilledSeriesRenderLeavesOnlyCompleteFrames) {
    ScratchDir dir("octiso_hostile_kill_render");
    const std::string series = dir.file("s.oct");
    RunResult r = run_capture("'" + tool("octiso-convert") + "' --synthetic plume-series:24,400 -o '" + series + "'", dir.file("err"));
    ASSERT_EQ(r.exit_status, 0) << r.err;
    const std::filesystem::path frames = dir.path() / "frames";
    std::filesystem::create_directory(frames);
    for (int sig : {SIGTERM, SIGKILL}) {
        SCOPED_TRACE(sigabbrev_np(sig));
        const pid_t pid = spawn({tool("octiso-render"), series, "--iso", "0.5", "--size", "160x160", "--steps", "0:399",
                                 "--threads", "1", "-o", (frames / "f_%03d.png").string()});
        int status = 0;
        ASSERT_TRUE(wait_for_temporary(pid, frames, &status)) << "the render ended before a temporary appeared";
        ASSERT_EQ(::kill(pid, sig), 0);
        ASSERT_EQ(::waitpid(pid, &status, 0), pid);
        ASSERT_TRUE(WIFSIGNALED(status));
        if (sig != SIGKILL) {
            EXPECT_TRUE(temporaries(frames).empty());
        }
        for (const auto& e : std::filesystem::directory_iterator(frames)) {
            const std::string name = e.path().filename().string();
            if (name.rfind(".tmp-", 0) == 0) continue;
            EXPECT_NO_THROW(read_image(e.path().string())) << name << " is not a complete image";
        }
    }
    r = run_capture("'" + tool("octiso-render") + "' '" + series + "' --iso 0.5 --size 16x16 -o '" + (frames / "last.png").string() + "'",
                    dir.file("err"));
    ASSERT_EQ(r.exit_status, 0) << r.err;
    EXPECT_TRUE(temporaries(frames).empty());
}

}  // namespace
}  // namespace octiso::test
