// AtomicOutput's registry of live temporaries and its signal handler, the stale-temporary sweep
// and the checked write path. The registry is a fixed array of path buffers so that the handler
// only touches memory that is already there (unlink, sigaction and raise are async-signal-safe).
#include "util/atomic_output.h"

#include <atomic>
#include <cerrno>
#include <climits>
#include <csignal>
#include <cstring>
#include <mutex>
#include <set>

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace octiso {

namespace {

constexpr int kSlots = 64;
constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};

struct Slot {
    std::atomic<bool> live{false};
    char path[PATH_MAX];
};
Slot g_slots[kSlots];
struct sigaction g_previous[sizeof kSignals / sizeof kSignals[0]];

extern "C" void remove_temporaries_and_reraise(int sig) {
    for (Slot& s : g_slots)
        if (s.live.load(std::memory_order_acquire)) ::unlink(s.path);
    // Hand the signal to whatever was there before (normally the default action: terminate).
    for (size_t i = 0; i < sizeof kSignals / sizeof kSignals[0]; ++i)
        if (kSignals[i] == sig) ::sigaction(sig, &g_previous[i], nullptr);
    ::raise(sig);
}

void install_handlers_once() {
    static std::once_flag once;
    std::call_once(once, [] {
        for (size_t i = 0; i < sizeof kSignals / sizeof kSignals[0]; ++i) {
            struct sigaction old {};
            ::sigaction(kSignals[i], nullptr, &old);
            g_previous[i] = old;
            // A signal the parent chose to ignore (nohup) stays ignored; a host program's own
            // handler is kept and still runs after ours.
            if (!(old.sa_flags & SA_SIGINFO) && old.sa_handler == SIG_IGN) continue;
            struct sigaction sa {};
            sa.sa_handler = remove_temporaries_and_reraise;
            sigemptyset(&sa.sa_mask);
            sa.sa_flags = SA_RESETHAND;
            ::sigaction(kSignals[i], &sa, nullptr);
        }
    });
}

int register_temporary(const std::string& path) {
    if (path.size() >= PATH_MAX) return -1;
    install_handlers_once();
    static std::mutex m;   // claims slots; the handler only reads `live` and the path
    std::lock_guard<std::mutex> lock(m);
    for (int i = 0; i < kSlots; ++i)
        if (!g_slots[i].live.load(std::memory_order_relaxed)) {
            std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
            g_slots[i].live.store(true, std::memory_order_release);
            return i;
        }
    return -1;   // more than kSlots outputs at once: still removed on every other exit path
}

void unregister_temporary(int slot) {
    if (slot >= 0) g_slots[slot].live.store(false, std::memory_order_release);
}

std::string folder_of(const std::string& path) {
    const size_t slash = path.find_last_of('/');
    if (slash == std::string::npos) return ".";
    return slash == 0 ? "/" : path.substr(0, slash);
}

std::string temp_name(const std::string& path) {
    const size_t slash = path.find_last_of('/');
    const size_t base = slash == std::string::npos ? 0 : slash + 1;
    return path.substr(0, base) + ".tmp-" + std::to_string(::getpid()) + "-" + path.substr(base);
}

std::string errno_text() { return std::strerror(errno); }

}  // namespace

namespace io {

bool write_all(int fd, const void* data, uint64_t n) {
    const auto* p = static_cast<const char*>(data);
    while (n > 0) {
        const size_t chunk = size_t(n < (uint64_t(1) << 30) ? n : (uint64_t(1) << 30));
        const ssize_t w = ::write(fd, p, chunk);
        if (w < 0) {
            if (errno == EINTR) continue;
            return false;
        }
        if (w == 0) {
            errno = ENOSPC;
            return false;
        }
        p += w;
        n -= uint64_t(w);
    }
    return true;
}

int remove_stale_temporaries(const std::string& dir) {
    DIR* d = ::opendir(dir.c_str());
    if (!d) return 0;
    int removed = 0;
    const pid_t self = ::getpid();
    while (const dirent* e = ::readdir(d)) {
        // ".tmp-" PID "-" NAME, PID all digits.
        const char* name = e->d_name;
        if (std::strncmp(name, ".tmp-", 5) != 0) continue;
        const char* p = name + 5;
        long long pid = 0;
        int digits = 0;
        while (*p >= '0' && *p <= '9' && digits < 10) pid = pid * 10 + (*p++ - '0'), ++digits;
        if (digits == 0 || *p != '-' || p[1] == '\0' || pid <= 0 || pid == self || pid > INT_MAX) continue;
        // Deviation: a PID is only unique on this machine (and in this PID namespace); folders
        // shared over a network with another writer are not protected.
        if (::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue;   // alive, or not ours to judge
        const std::string full = dir + "/" + name;
        struct stat st {};
        if (::lstat(full.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) continue;
        if (::unlink(full.c_str()) == 0) ++removed;
    }
    ::closedir(d);
    return removed;
}

}  // namespace io

AtomicOutput::AtomicOutput(std::string path) : path_(std::move(path)), temp_(temp_name(path_)) {
    {   // Once per folder and process: a series render writes thousands of frames into one.
        static std::mutex m;
        static std::set<std::string> swept;
        const std::string folder = folder_of(path_);
        std::lock_guard<std::mutex> lock(m);
        if (swept.insert(folder).second) io::remove_stale_temporaries(folder);
    }
    slot_ = register_temporary(temp_);
}

AtomicOutput::~AtomicOutput() {
    if (!committed_) ::unlink(temp_.c_str());
    unregister_temporary(slot_);
}

void AtomicOutput::commit(int64_t expected_bytes) {
    // 1. The temporary's bytes reach the disk (fsync reports the write-back errors that a
    //    writer's buffered writes could not) and its size is what the writer produced.
    const int fd = ::open(temp_.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw Error(path_, "cannot reopen the finished temporary: " + errno_text(), ErrorKind::Other);
    struct stat st {};
    if (::fstat(fd, &st) != 0) {
        const std::string e = errno_text();
        ::close(fd);
        throw Error(path_, "cannot stat the finished temporary: " + e, ErrorKind::Other);
    }
    if (expected_bytes >= 0 && st.st_size != expected_bytes) {
        ::close(fd);
        throw Error(path_, "write incomplete (expected " + std::to_string(expected_bytes) + " bytes, found " +
                               std::to_string(st.st_size) + ")", ErrorKind::Other);
    }
    if (::fsync(fd) != 0) {
        const std::string e = errno_text();
        ::close(fd);
        throw Error(path_, "sync failed: " + e, ErrorKind::Other);
    }
    if (::close(fd) != 0) throw Error(path_, "close failed: " + errno_text(), ErrorKind::Other);
    // 2. Publish, then make the rename itself durable.
    if (std::rename(temp_.c_str(), path_.c_str()) != 0)
        throw Error(path_, "cannot move the finished file into place: " + errno_text(), ErrorKind::Other);
    committed_ = true;
    unregister_temporary(slot_);
    slot_ = -1;
    const int dfd = ::open(folder_of(path_).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
        ::fsync(dfd);   // best effort: the file is complete and in place; some filesystems refuse
        ::close(dfd);
    }
}

AtomicFileWriter::AtomicFileWriter(const std::string& path) : out_(path) {
    fd_ = ::open(out_.temp_path().c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd_ < 0) throw Error(out_.temp_path(), "cannot create: " + errno_text(), ErrorKind::Other);
}

AtomicFileWriter::~AtomicFileWriter() {
    if (fd_ >= 0) ::close(fd_);   // uncommitted: out_ removes the temporary
}

void AtomicFileWriter::append(const void* data, uint64_t bytes) {
    if (!io::write_all(fd_, data, bytes)) throw Error(out_.path(), "write failed: " + errno_text(), ErrorKind::Other);
    written_ += bytes;
}

void AtomicFileWriter::commit() {
    if (::fsync(fd_) != 0) throw Error(out_.path(), "sync failed: " + errno_text(), ErrorKind::Other);
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) throw Error(out_.path(), "close failed: " + errno_text(), ErrorKind::Other);
    out_.commit(int64_t(written_));
}

void write_file_atomically(const std::string& path, const void* data, uint64_t bytes) {
    AtomicFileWriter out(path);
    out.append(data, bytes);
    out.commit();
}

}  // namespace octiso
