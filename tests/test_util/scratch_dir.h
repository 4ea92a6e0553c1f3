// ScratchDir: a fresh directory under the system temp dir for one test, removed with everything
// in it when the test ends. entries() lets CLI tests assert that a failed run left nothing behind.
// Before removal every .oct file left in it that passes the loader's validation is checked with
// verify_octree() (octiso-info --verify, issue 18): each min/max and scalar recomputed from the
// leaves, so no test writes a file whose metadata lies without failing. Files that fail
// validation are the rejection tests' own business; a test that forges lying metadata on purpose
// says so with allow_lying_metadata(). Steps larger than kVerifyBytes as dense arrays are skipped.
// The one ScratchDir of the test binary (every suite includes this header; a second class of the
// same name elsewhere would be an ODR violation).
#pragma once

#include <signal.h>
#include <unistd.h>

#include <cerrno>

#include <gtest/gtest.h>

#include <filesystem>
#include <algorithm>
#include <string>
#include <system_error>
#include <vector>

#include "octiso/error.h"
#include "octiso/oct_file.h"
#include "octiso/verify.h"

namespace octiso::test {

class ScratchDir {
public:
    explicit ScratchDir(const std::string& prefix = "octiso_test") : prefix_(prefix) {
        static int n = 0;
        path_ = std::filesystem::temp_directory_path() /
                (prefix + "_" + std::to_string(::getpid()) + "_" + std::to_string(n++));
        std::filesystem::create_directories(path_);
    }
    ~ScratchDir() {
        if (!lies_allowed_) verify_octree_files();
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
        remove_orphans();
    }
    /// For tests that write files with valid checksums and lying min/max on purpose.
    void allow_lying_metadata() { lies_allowed_ = true; }
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;

    const std::filesystem::path& path() const { return path_; }
    std::string file(const std::string& name) const { return (path_ / name).string(); }
    /// Names of the entries in the directory (outputs, and any temporaries a tool left behind), sorted.
    std::vector<std::string> entries() const {
        std::vector<std::string> out;
        for (const auto& e : std::filesystem::directory_iterator(path_)) out.push_back(e.path().filename().string());
        std::sort(out.begin(), out.end());
        return out;
    }

private:
    static constexpr uint64_t kVerifyBytes = uint64_t(64) << 20;

    void verify_octree_files() const {
        std::error_code ec;
        for (const auto& e : std::filesystem::recursive_directory_iterator(path_, ec)) {
            if (!e.is_regular_file() || e.path().extension() != ".oct") continue;
            const std::string p = e.path().string();
            try {
                const OctFile f = OctFile::open(p);
                const Dims d = f.info().dims;   // in double: a 2^30-cubed grid overflows 64 bits
                if (double(d.x) * double(d.y) * double(d.z) * double(scalar_type_bytes(f.info().type)) > double(kVerifyBytes))
                    continue;
                for (uint32_t k = 0; k < f.info().step_count; ++k) (void)f.step_sizes(k);   // validates each step
                try {
                    (void)verify_octree(f);
                } catch (const Error& lie) {
                    ADD_FAILURE() << "a test wrote a file whose metadata lies (octiso-info --verify): " << lie.what();
                }
            } catch (const Error&) {
                // Not a valid .oct file: refused by the loader, which is what rejection tests check.
            }
        }
    }

    /// A death test's child (gtest's threadsafe style re-runs the test in a new process) builds
    /// its own fixture and ends in _Exit or a fatal signal handler, so its directory outlives it.
    /// The parent removes the directories of this prefix whose process no longer exists.
    void remove_orphans() const {
        std::error_code ec;
        const std::string lead = prefix_ + "_";
        for (const auto& e : std::filesystem::directory_iterator(path_.parent_path(), ec)) {
            const std::string name = e.path().filename().string();
            if (name.rfind(lead, 0) != 0) continue;
            const std::string rest = name.substr(lead.size());
            const size_t cut = rest.find('_');
            if (cut == 0 || cut == std::string::npos || rest.find_first_not_of("0123456789") != cut) continue;
            const pid_t pid = pid_t(std::stol(rest.substr(0, cut)));
            if (pid == ::getpid() || ::kill(pid, 0) == 0 || errno != ESRCH) continue;
            std::error_code gone;
            std::filesystem::remove_all(e.path(), gone);
        }
    }

    std::filesystem::path path_;
    std::string prefix_;
    bool lies_allowed_ = false;
};

}  // namespace octiso::test
