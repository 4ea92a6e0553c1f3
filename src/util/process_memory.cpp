#include "util/process_memory.h"

#include <sys/resource.h>
#include <unistd.h>

#include <cctype>
#include <filesystem>
#include <fstream>

namespace octiso {

uint64_t peak_rss_bytes() {
    rusage ru{};
    ::getrusage(RUSAGE_SELF, &ru);
    return uint64_t(ru.ru_maxrss) * 1024;
}

uint64_t current_rss_bytes() {
    std::ifstream statm("/proc/self/statm");
    uint64_t size = 0, resident = 0;
    statm >> size >> resident;
    return resident * uint64_t(::sysconf(_SC_PAGESIZE));
}

uint64_t mapped_resident_bytes(const std::string& path) {
    const std::string want = std::filesystem::canonical(path).string();
    std::ifstream smaps("/proc/self/smaps");
    std::string line;
    bool inside = false;
    uint64_t total = 0;
    while (std::getline(smaps, line)) {
        // A mapping header reads "start-end perms offset dev inode [path]"; its fields follow it.
        const size_t dash = line.find('-'), space = line.find(' ');
        if (dash != std::string::npos && dash > 0 && space > dash && std::isxdigit(static_cast<unsigned char>(line[0]))) {
            const size_t slash = line.find('/');
            inside = slash != std::string::npos && line.compare(slash, std::string::npos, want) == 0;
        } else if (inside && line.rfind("Rss:", 0) == 0) {
            total += std::stoull(line.substr(4)) * 1024;
        }
    }
    return total;
}

}  // namespace octiso
