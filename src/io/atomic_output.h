// AtomicOutput: write to a temporary sibling (".tmp-PID-NAME", so the extension that picks the
// image format survives), rename onto NAME on commit(), remove
// the temporary in the destructor otherwise. Every octiso output file goes through it, so a failed
// or interrupted run never leaves a partial file under the requested name (CONVENTIONS 3).
#pragma once

#include <cstdio>
#include <string>
#include <unistd.h>

#include "octiso/error.h"

namespace octiso {

class AtomicOutput {
public:
    explicit AtomicOutput(std::string path)
        : path_(std::move(path)), temp_(temp_name(path_)) {}
    ~AtomicOutput() {
        if (!committed_) std::remove(temp_.c_str());
    }
    AtomicOutput(const AtomicOutput&) = delete;
    AtomicOutput& operator=(const AtomicOutput&) = delete;

    const std::string& temp_path() const { return temp_; }
    const std::string& path() const { return path_; }
    void commit() {
        if (std::rename(temp_.c_str(), path_.c_str()) != 0)
            throw Error(path_, "cannot move the finished file into place", ErrorKind::Other);
        committed_ = true;
    }

private:
    static std::string temp_name(const std::string& path) {
        const size_t slash = path.find_last_of('/');
        const size_t base = slash == std::string::npos ? 0 : slash + 1;
        return path.substr(0, base) + ".tmp-" + std::to_string(::getpid()) + "-" + path.substr(base);
    }
    std::string path_, temp_;
    bool committed_ = false;
};

}  // namespace octiso
