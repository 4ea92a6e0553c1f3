// Memory readings of the calling process, for the converter's --json report, the benchmarks and
// the tests that check "peak memory close to input + output" and "a mapped series is resident
// only for the steps used". Linux only (getrusage, /proc/self/statm, /proc/self/smaps).
#pragma once

#include <cstdint>
#include <string>

namespace octiso {

uint64_t peak_rss_bytes();      ///< high-water resident set size (getrusage ru_maxrss)
uint64_t current_rss_bytes();   ///< resident set size now (/proc/self/statm)
/// Resident bytes of this process's mappings of `path` (/proc/self/smaps): the part of an
/// mmap'd file it has touched, plus the kernel's fault-around (up to 64 KiB per fault).
uint64_t mapped_resident_bytes(const std::string& path);

}  // namespace octiso
