// Shared by the hostile-input suite (issue 18): the built tools, a runner that captures stderr
// and the exit status (or the signal), and the one assertion every refusal must pass: exit 2,
// exactly one stderr line naming the file, and nothing left in the output folder.
#pragma once

#include <gtest/gtest.h>

#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "test_util/skip.h"
#include "test_util/scratch_dir.h"

namespace octiso::test {

inline std::string tool(const std::string& name) { return std::string(OCTISO_TOOLS_DIR) + "/" + name; }

/// How a child run ended: exit status, or the signal that killed it (exit_status -1 then).
struct RunResult {
    int exit_status = -1;
    int signal = 0;
    std::string err;   ///< everything it wrote to stderr
    std::string out;   ///< stdout
};

/// Runs `command` through the shell (stderr captured into `err`); never throws.
inline RunResult run_capture(const std::string& command, const std::string& err_file) {
    RunResult r;
    std::FILE* p = ::popen((command + " 2>'" + err_file + "'").c_str(), "r");
    if (!p) return r;
    char buf[4096];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
    const int status = ::pclose(p);
    if (WIFEXITED(status)) {
        r.exit_status = WEXITSTATUS(status);
        // The shell reports a child killed by a signal as 128 + signal.
        if (r.exit_status > 128 && r.exit_status < 128 + 65) r.signal = r.exit_status - 128;
    } else if (WIFSIGNALED(status)) {
        r.signal = WTERMSIG(status);
    }
    std::ifstream e(err_file);
    r.err.assign(std::istreambuf_iterator<char>(e), std::istreambuf_iterator<char>());
    return r;
}

inline void write_bytes(const std::string& path, const void* data, size_t n) {
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f.write(static_cast<const char*>(data), std::streamsize(n));
}
inline void write_text(const std::string& path, const std::string& text) { write_bytes(path, text.data(), text.size()); }
inline std::string read_all(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

/// Names in `dir` that look like an octiso temporary (".tmp-PID-NAME").
inline std::vector<std::string> temporaries(const std::filesystem::path& dir) {
    std::vector<std::string> t;
    for (const auto& e : std::filesystem::directory_iterator(dir))
        if (e.path().filename().string().rfind(".tmp-", 0) == 0) t.push_back(e.path().filename().string());
    return t;
}

/// A refusal as CONVENTIONS 3 wants it: exit 2, no signal, one line naming `subject`.
inline void expect_refused(const RunResult& r, const std::string& subject, const std::string& what = {}) {
    SCOPED_TRACE(what);
    EXPECT_EQ(r.signal, 0) << "killed by signal " << r.signal << "; stderr: " << r.err;
    EXPECT_EQ(r.exit_status, 2) << r.err;
    EXPECT_NE(r.err.find(subject), std::string::npos) << "stderr does not name " << subject << ": " << r.err;
    const size_t lines = size_t(std::count(r.err.begin(), r.err.end(), '\n'));
    EXPECT_EQ(lines, 1u) << "expected exactly one stderr line: " << r.err;
}

/// OCTISO_REQUIRE_ALL=1 (CI): a test that cannot run its real check fails instead of skipping
/// (the one rule of test_util/skip.h).
inline bool required() { return skips_must_fail(); }

/// A tmpfs of 1 MiB mounted for one test (root only); why() says why not.
class SmallTmpfs {
public:
    explicit SmallTmpfs(const std::string& where) : where_(where) {
        std::filesystem::create_directories(where_);
        if (::geteuid() != 0) {
            why_ = "not running as root";
        } else if (::mount("tmpfs", where_.c_str(), "tmpfs", 0, "size=1m") != 0) {
            why_ = std::string("mount -t tmpfs failed: ") + std::strerror(errno);
        } else {
            mounted_ = true;
        }
    }
    ~SmallTmpfs() {
        if (mounted_) ::umount2(where_.c_str(), MNT_DETACH);
    }
    bool mounted() const { return mounted_; }
    const std::string& why() const { return why_; }

    /// Fills the filesystem, then frees `spare` bytes again.
    void fill_leaving(size_t spare) {
        const std::string filler = where_ + "/filler";
        std::FILE* f = std::fopen(filler.c_str(), "wb");
        ASSERT_NE(f, nullptr);
        std::vector<char> block(4096, 'f');
        while (std::fwrite(block.data(), 1, block.size(), f) == block.size()) {}
        std::fclose(f);
        const auto size = std::filesystem::file_size(filler);
        ASSERT_GT(size, spare);
        std::filesystem::resize_file(filler, size - spare);
    }

private:
    std::string where_, why_;
    bool mounted_ = false;
};

}  // namespace octiso::test
