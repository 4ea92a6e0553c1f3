// AtomicOutput: write to a temporary sibling ("NAME.tmp-PID"), rename onto NAME on commit(), remove
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
        : path_(std::move(path)), temp_(path_ + ".tmp-" + std::to_string(::getpid())) {}
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
    std::string path_, temp_;
    bool committed_ = false;
};

}  // namespace octiso
