// Shared by the libFuzzer targets: the input as a file (octiso's readers take paths) in a memfd,
// so no disk is touched, and the .oct re-checksumming that lets the fuzzer past the XXH3 checks
// to the structural validation behind them (checksums themselves are covered by the tests).
#pragma once

#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "format/oct_layout.h"

namespace octiso::fuzz {

/// A memfd holding `bytes`; path() names it through /proc/self/fd.
class MemFile {
public:
    MemFile(const uint8_t* data, size_t n, const char* name = "fuzz") : fd_(::memfd_create(name, MFD_CLOEXEC)) {
        if (fd_ >= 0 && n > 0 && ::write(fd_, data, n) != ssize_t(n)) {
            ::close(fd_);
            fd_ = -1;
        }
    }
    ~MemFile() {
        if (fd_ >= 0) ::close(fd_);
    }
    bool ok() const { return fd_ >= 0; }
    std::string path() const { return "/proc/self/fd/" + std::to_string(fd_); }

private:
    int fd_;
};

/// Rewrites every checksum of a would-be .oct file whose bounds are sane (as the tests' OctBytes).
inline void rechecksum(std::vector<uint8_t>& b) {
    if (b.size() < sizeof(format::FileHeader)) return;
    format::FileHeader h;
    std::memcpy(&h, b.data(), sizeof h);
    const uint64_t size = b.size();
    if (h.section_entry_bytes == sizeof(format::SectionEntry) && h.section_table_offset <= size &&
        h.section_count <= (size - h.section_table_offset) / sizeof(format::SectionEntry)) {
        for (uint64_t i = 0; i < h.section_count; ++i) {
            format::SectionEntry s;
            uint8_t* at = b.data() + h.section_table_offset + i * sizeof s;
            std::memcpy(&s, at, sizeof s);
            if (s.bytes <= size && s.offset <= size - s.bytes) {
                s.checksum = format::checksum(b.data() + s.offset, size_t(s.bytes));
                std::memcpy(at, &s, sizeof s);
            }
        }
        h.section_table_checksum =
            format::checksum(b.data() + h.section_table_offset, size_t(h.section_count * sizeof(format::SectionEntry)));
    }
    h.header_checksum = format::checksum(&h, format::kHeaderChecksummedBytes);
    std::memcpy(b.data(), &h, sizeof h);
}

}  // namespace octiso::fuzz
