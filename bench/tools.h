// What the conversion benchmarks (compression, series) share: running a built octiso tool in a
// child process (so its peak RSS is its own, not the benchmark's), reading numbers out of the one
// flat JSON object the tools print, comparing a file with bytes in memory, the zstd -3 size
// of a buffer as the entropy-coder reference the compression tables print beside the octree, and
// dropping a file from the page cache for the cold-start rows (outofcore, lod --cold).
#pragma once

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "octiso/error.h"

namespace octiso::bench {

/// The directory of the running octiso-bench, where the build puts the other tools too.
inline std::string tools_dir() {
    std::error_code ec;
    const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    return ec ? std::string(".") : exe.parent_path().string();
}

/// `text` quoted for /bin/sh (single quotes; an inner ' becomes '\'').
inline std::string shell_quote(const std::string& text) {
    std::string q = "'";
    for (char c : text) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

/// Runs TOOL (octiso-convert, octiso-info, ...) from `dir` (default tools_dir()) with `args` (each quoted) and
/// returns its stdout. A non-zero exit throws Error(tool, its stderr) so a benchmark never
/// reports numbers of a failed run.
inline std::string run_tool(const std::string& tool, const std::vector<std::string>& args,
                            const std::string& dir = tools_dir()) {
    const std::string err_path = std::filesystem::temp_directory_path() /
                                 ("octiso-bench-" + std::to_string(::getpid()) + ".stderr");
    std::string cmd = shell_quote(dir + "/" + tool);
    for (const auto& a : args) cmd += " " + shell_quote(a);
    cmd += " 2>" + shell_quote(err_path);
    std::FILE* p = ::popen(cmd.c_str(), "r");
    if (!p) throw Error(tool, "cannot start child process", ErrorKind::Other);
    std::string out;
    char buf[65536];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
    const int status = ::pclose(p);
    std::ifstream err_file(err_path);
    std::string err((std::istreambuf_iterator<char>(err_file)), std::istreambuf_iterator<char>());
    std::filesystem::remove(err_path);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        while (!err.empty() && err.back() == '\n') err.pop_back();
        throw Error(tool, "failed (" + cmd + "): " + err, ErrorKind::Other);
    }
    return out;
}

/// The number after the first "key": in `json` (our tools print flat, unique keys).
inline double json_number(const std::string& json, const std::string& key) {
    const std::string needle = "\"" + key + "\":";
    const size_t at = json.find(needle);
    if (at == std::string::npos) throw Error(key, "not in the tool's JSON output", ErrorKind::Other);
    return std::strtod(json.c_str() + at + needle.size(), nullptr);
}

/// Drops the file's pages from the page cache, so that the next process to map it starts cold:
/// written back first (a converter may have just written it), then dropped (clean pages of a file
/// nobody maps: the kernel honours it without root). Best effort: a file it cannot open is left.
inline void evict_page_cache(const std::string& path) {
    const int fd = ::open(path.c_str(), O_RDONLY);
    if (fd < 0) return;
    ::fdatasync(fd);
    ::posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED);
    ::close(fd);
}

/// True if the file at `path` holds exactly the `n` bytes at `data` (read in blocks, no full copy).
inline bool file_equals(const std::string& path, const void* data, uint64_t n) {
    std::ifstream f(path, std::ios::binary);
    if (!f) return false;
    std::vector<char> block(1 << 20);
    const char* expected = static_cast<const char*>(data);
    uint64_t done = 0;
    while (done < n) {
        const size_t want = size_t(std::min<uint64_t>(block.size(), n - done));
        if (!f.read(block.data(), std::streamsize(want))) return false;
        if (std::memcmp(block.data(), expected + done, want) != 0) return false;
        done += want;
    }
    return f.peek() == std::char_traits<char>::eof();   // and nothing more
}

/// Size of ZSTD_compress(data, level) in one frame: `zstd -3` of the raw bytes when level is 3.
inline uint64_t zstd_bytes(const void* data, uint64_t n, int level = 3) {
    std::vector<char> out(ZSTD_compressBound(size_t(n)));
    const size_t r = ZSTD_compress(out.data(), out.size(), data, size_t(n), level);
    if (ZSTD_isError(r)) throw Error("zstd", ZSTD_getErrorName(r), ErrorKind::Other);
    return uint64_t(r);
}

}  // namespace octiso::bench
