// AtomicOutput: write to a temporary sibling (".tmp-PID-NAME", so the extension that picks the
// image format survives), rename onto NAME on commit(), remove the temporary in the destructor
// otherwise. Every octiso output file goes through it, so a failed or interrupted run never
// leaves a partial file under the requested name (CONVENTIONS 3). Issue 18 added:
//  - commit() fsyncs the temporary, renames, then fsyncs the folder: a published name never
//    points at data still only in the page cache;
//  - live temporaries sit in a process-wide registry that a SIGINT/SIGTERM/SIGHUP/SIGQUIT
//    handler unlinks before the signal's default action runs (SIGKILL cannot be caught: the
//    next write into that folder removes temporaries whose process is gone);
//  - write_file_atomically(): the one checked write loop (short writes, errno, close status).
#pragma once

#include <cstdint>
#include <string>

#include "octiso/error.h"

namespace octiso {

class AtomicOutput {
public:
    /// Registers the temporary for removal on a fatal signal and removes stale temporaries of
    /// dead processes from the destination folder.
    explicit AtomicOutput(std::string path);
    ~AtomicOutput();
    AtomicOutput(const AtomicOutput&) = delete;
    AtomicOutput& operator=(const AtomicOutput&) = delete;

    const std::string& temp_path() const { return temp_; }
    const std::string& path() const { return path_; }
    /// fsync(temporary), rename onto path(), fsync(folder). If `expected_bytes` is given, the
    /// temporary must hold exactly that many bytes. Throws Error(path(), ...) (ErrorKind::Other).
    void commit(int64_t expected_bytes = -1);

private:
    std::string path_, temp_;
    int slot_ = -1;   // registry slot of temp_
    bool committed_ = false;
};

/// An output file written piece by piece through AtomicOutput (octiso-info --extract-raw of a
/// step larger than memory): append() in order, then commit(); dropped uncommitted, nothing is
/// left under the name. Every write, the fsync and the close are checked (ENOSPC names the file).
class AtomicFileWriter {
public:
    explicit AtomicFileWriter(const std::string& path);
    ~AtomicFileWriter();
    AtomicFileWriter(const AtomicFileWriter&) = delete;
    AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;
    void append(const void* data, uint64_t bytes);
    void commit();   ///< fsync, close, rename: the file holds exactly the bytes appended

private:
    AtomicOutput out_;
    int fd_ = -1;
    uint64_t written_ = 0;
};

/// Writes `bytes` bytes at `data` to `path` through AtomicOutput with every write, the fsync and
/// the close checked (ENOSPC names the file, exit 1); nothing is left on failure.
void write_file_atomically(const std::string& path, const void* data, uint64_t bytes);

namespace io {
/// Writes all of `n` bytes to `fd` (retrying short writes and EINTR); false with errno set.
bool write_all(int fd, const void* data, uint64_t n);
/// Removes ".tmp-PID-*" entries of `dir` whose PID names no live process. Returns the count.
int remove_stale_temporaries(const std::string& dir);
}  // namespace io

}  // namespace octiso
