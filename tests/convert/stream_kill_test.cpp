// The out-of-core converter killed while its spill temporaries exist (issue 13): after SIGTERM,
// SIGINT or SIGHUP neither the output's temporary nor any spill file remains, and the final path
// still holds the old file. The kill waits for a spill file to appear (polling the folder, not a
// clock), so it always lands while the temporaries are live.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <random>

#include "hostile/hostile_util.h"

namespace octiso::test {
namespace {

bool has_spill(const std::filesystem::path& dir) {
    for (const std::string& t : temporaries(dir))
        if (t.find(".spill-d") != std::string::npos) return true;
    return false;
}

struct StreamKill : ::testing::TestWithParam<int> {};

TEST_P(StreamKill, SignalWhileSpillingLeavesNoTemporary) {
    const int sig = GetParam();
    ScratchDir dir("stream_kill");
    const std::string out = dir.file("out.oct");
    std::ofstream(out, std::ios::binary) << "old";
    std::vector<uint8_t> v(256 * 256 * 256);
    std::mt19937 rng(3);
    for (auto& x : v) x = uint8_t(rng() % 4 * 60);   // incompressible enough to spill under 24 MiB
    const std::string in = dir.file("in.raw");
    std::ofstream(in, std::ios::binary).write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size()));

    // 300 steps of the same file, one thread: minutes of work, killed in the first few steps.
    std::vector<std::string> argv{tool("octiso-convert")};
    for (int i = 0; i < 300; ++i) argv.push_back(in);
    for (const char* a : {"--dims", "256,256,256", "--type", "u8", "--memory", "24M", "--threads", "1", "-o"}) argv.push_back(a);
    argv.push_back(out);
    const pid_t pid = ::fork();
    if (pid == 0) {
        for (int s : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) ::signal(s, SIG_DFL);
        const int null = ::open("/dev/null", O_WRONLY);
        ::dup2(null, 1);
        ::dup2(null, 2);
        std::vector<char*> args;
        for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
        args.push_back(nullptr);
        ::execv(args[0], args.data());
        ::_exit(127);
    }
    int status = 0;
    bool spilling = false;
    while (!(spilling = has_spill(dir.path())))
        if (::waitpid(pid, &status, WNOHANG) == pid) break;
        else ::usleep(500);
    ASSERT_TRUE(spilling) << "the conversion ended (status " << status << ") before a spill file appeared";
    ASSERT_EQ(::kill(pid, sig), 0);
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFSIGNALED(status)) << "status " << status;
    EXPECT_EQ(WTERMSIG(status), sig);
    EXPECT_TRUE(temporaries(dir.path()).empty()) << temporaries(dir.path()).front();
    EXPECT_EQ(read_all(out), "old");
}

INSTANTIATE_TEST_SUITE_P(Signals, StreamKill, ::testing::Values(SIGTERM, SIGINT, SIGHUP),
                         [](const auto& info) { return std::string(sigabbrev_np(info.param)); });

}  // namespace
}  // namespace octiso::test
