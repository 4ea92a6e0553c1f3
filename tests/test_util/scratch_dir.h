// ScratchDir: a fresh directory under the system temp dir for one test, removed with everything
// in it when the test ends. entries() lets CLI tests assert that a failed run left nothing behind.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <iterator>
#include <string>
#include <system_error>

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
    /// Number of entries in the directory (outputs, and any temporaries a tool left behind).
    size_t entries() const {
        return size_t(std::distance(std::filesystem::directory_iterator(path_), std::filesystem::directory_iterator()));
    }

private:
    std::filesystem::path path_;
};

}  // namespace octiso::test
