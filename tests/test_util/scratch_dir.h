// ScratchDir: a fresh directory under the system temp dir for one test, removed with everything
// in it when the test ends. entries() lets CLI tests assert that a failed run left nothing behind.
// The one ScratchDir of the test binary (every suite includes this header; a second class of the
// same name elsewhere would be an ODR violation).
#pragma once

#include <unistd.h>

#include <filesystem>
#include <algorithm>
#include <string>
#include <system_error>
#include <vector>

namespace octiso::test {

class ScratchDir {
public:
    explicit ScratchDir(const std::string& prefix = "octiso_test") {
        static int n = 0;
        path_ = std::filesystem::temp_directory_path() /
                (prefix + "_" + std::to_string(::getpid()) + "_" + std::to_string(n++));
        std::filesystem::create_directories(path_);
    }
    ~ScratchDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
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
    std::filesystem::path path_;
};

}  // namespace octiso::test
