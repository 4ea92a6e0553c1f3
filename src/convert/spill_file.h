// SpillFile: an append-only store of bytes for the out-of-core converter's finished node arrays
// (one per depth), kept in memory while a shared allowance lasts and moved to a temporary file
// beside the output once it runs out. The temporary goes through AtomicOutput (never committed),
// so it is removed on success, on any error and on SIGINT/SIGTERM/SIGHUP/SIGQUIT.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "util/atomic_output.h"

namespace octiso::convert_detail {

/// Bytes that the SpillFiles of one conversion may still keep in memory. Not thread-safe.
struct SpillAllowance {
    uint64_t bytes_left = 0;
};

class SpillFile {
public:
    /// `name` is the file the temporary is named after (OUT.oct.spill-dN; the temporary itself is
    /// .tmp-PID-OUT.oct.spill-dN in the same folder). Nothing is created until memory runs out.
    SpillFile(std::string name, SpillAllowance& allowance);
    ~SpillFile();
    SpillFile(const SpillFile&) = delete;
    SpillFile& operator=(const SpillFile&) = delete;

    /// Appends `n` bytes; returns their offset. Throws Error(OUT...) (ErrorKind::Other) on a failed write.
    uint64_t append(const void* data, uint64_t n);
    /// Copies bytes [offset, offset + n) (appended before) into `dst`.
    void read(uint64_t offset, uint64_t n, void* dst) const;
    uint64_t size() const { return size_; }
    uint64_t disk_bytes() const { return on_disk_ ? size_ : 0; }
    /// Drops everything (the next step starts empty), handing the memory back to the allowance.
    void clear();

private:
    void move_to_disk();
    void release_memory();
    std::string name_;
    SpillAllowance& allowance_;
    // In memory: blocks of kBlockBytes, so that growing never copies (a doubling vector copied
    // and faulted in fresh pages for every byte: octiso-bench outofcore, 1024^3, perf).
    static constexpr uint64_t kBlockBytes = uint64_t(8) << 20;
    std::vector<std::unique_ptr<std::byte[]>> blocks_;
    std::unique_ptr<AtomicOutput> temp_;
    int fd_ = -1;
    bool on_disk_ = false;
    uint64_t size_ = 0;
    uint64_t charged_ = 0;   // what this file took from the allowance (whole blocks), given back on release
};

}  // namespace octiso::convert_detail
