// The fault handler behind mapping_guard.h. It only uses async-signal-safe calls (fstat, write,
// sigaction, _exit) and memory that exists before any fault: a fixed table of slots. A slot's
// resolver (the touch validator) keeps to the same rule.
#include "util/mapping_guard.h"

#include <atomic>
#include <cerrno>
#include <climits>
#include <csignal>
#include <cstring>
#include <mutex>

#include <sys/file.h>
#include <ucontext.h>
#include <sys/stat.h>
#include <unistd.h>

#include "octiso/error.h"

extern char* program_invocation_short_name;   // glibc

namespace octiso::io {

namespace {

constexpr int kSlots = 64;

struct Slot {
    std::atomic<bool> live{false};
    const char* base = nullptr;
    uint64_t bytes = 0;
    int fd = -1;
    off_t size = 0;
    struct timespec mtime {};
    std::atomic<FaultResolver> resolver{nullptr};
    void* resolver_context = nullptr;   // written before resolver is stored (release)
    char path[PATH_MAX];
};
Slot g_slots[kSlots];
struct sigaction g_prev_bus, g_prev_segv;

bool changed_since_mapped(const Slot& s) {
    struct stat st {};
    if (::fstat(s.fd, &st) != 0) return false;
    return st.st_size != s.size || st.st_mtim.tv_sec != s.mtime.tv_sec || st.st_mtim.tv_nsec != s.mtime.tv_nsec;
}

void put(char* buf, size_t& n, size_t cap, const char* text) {
    for (; *text && n + 1 < cap; ++text) buf[n++] = *text;
}

[[noreturn]] void report_and_exit(const Slot& s) {
    char line[PATH_MAX + 256];
    size_t n = 0;
    put(line, n, sizeof line, program_invocation_short_name ? program_invocation_short_name : "octiso");
    put(line, n, sizeof line, ": ");
    put(line, n, sizeof line, s.path);
    put(line, n, sizeof line, ": the file changed while it was being read (truncated or rewritten by another program); "
                              "run again on a file nobody modifies\n");
    ssize_t w = ::write(2, line, n);
    (void)w;
    ::_exit(2);
}

/// Whether the faulting access was a store: x86-64 puts the page-fault error code in REG_ERR
/// (bit 1: write). Elsewhere unknown, taken as a load.
bool fault_was_write([[maybe_unused]] void* ucontext) {
#if defined(__x86_64__) && defined(REG_ERR)
    return ucontext && (static_cast<ucontext_t*>(ucontext)->uc_mcontext.gregs[REG_ERR] & 2) != 0;
#else
    return false;
#endif
}

extern "C" void on_fault(int sig, siginfo_t* info, void* ucontext) {
    const char* addr = static_cast<const char*>(info ? info->si_addr : nullptr);
    // 1. A SIGBUS inside a mapping: the pages behind it are gone (the file shrank).
    if (sig == SIGBUS)
        for (const Slot& s : g_slots)
            if (s.live.load(std::memory_order_acquire) && addr >= s.base && addr < s.base + s.bytes) report_and_exit(s);
    // 2. Any fault while a mapped file differs from what was validated: its bytes are no longer
    //    the ones the checks saw (lying indices can send a read anywhere).
    for (const Slot& s : g_slots)
        if (s.live.load(std::memory_order_acquire) && changed_since_mapped(s)) report_and_exit(s);
    // 3. A protected block of a mapping whose resolver checks it and makes it readable.
    if (sig == SIGSEGV)
        for (Slot& s : g_slots)
            if (s.live.load(std::memory_order_acquire) && addr >= s.base && addr < s.base + s.bytes)
                if (FaultResolver r = s.resolver.load(std::memory_order_acquire))
                    if (r(s.resolver_context, addr, fault_was_write(ucontext))) return;
    // 4. Not ours: restore the previous action; returning re-executes the fault under it.
    ::sigaction(sig, sig == SIGBUS ? &g_prev_bus : &g_prev_segv, nullptr);
}

void install_once() {
    static std::once_flag once;
    std::call_once(once, [] {
        struct sigaction sa {};
        sa.sa_sigaction = on_fault;
        sigemptyset(&sa.sa_mask);
        sa.sa_flags = SA_SIGINFO | SA_NODEFER;
        ::sigaction(SIGBUS, &sa, &g_prev_bus);
        ::sigaction(SIGSEGV, &sa, &g_prev_segv);
    });
}

}  // namespace

void lock_shared_or_refuse(int fd, const std::string& path) {
    if (::flock(fd, LOCK_SH | LOCK_NB) == 0) return;
    if (errno == EWOULDBLOCK)
        throw Error(path, "is locked for writing by another process (flock); run again when it has finished");
    // ENOLCK, EINVAL, ENOTSUP: no locks on this filesystem; the fault handler still applies.
}

int register_mapping(const void* base, uint64_t bytes, int fd, const std::string& path) {
    install_once();
    struct stat st {};
    if (::fstat(fd, &st) != 0) return -1;
    static std::mutex m;
    std::lock_guard<std::mutex> lock(m);
    for (int i = 0; i < kSlots; ++i) {
        Slot& s = g_slots[i];
        if (s.live.load(std::memory_order_relaxed)) continue;
        s.base = static_cast<const char*>(base);
        s.bytes = bytes;
        s.fd = fd;
        s.size = st.st_size;
        s.mtime = st.st_mtim;
        const size_t n = path.size() < sizeof s.path - 1 ? path.size() : sizeof s.path - 1;
        std::memcpy(s.path, path.data(), n);
        s.path[n] = '\0';
        s.resolver.store(nullptr, std::memory_order_relaxed);
        s.live.store(true, std::memory_order_release);
        return i;
    }
    return -1;
}

void unregister_mapping(int slot) {
    if (slot < 0) return;
    g_slots[slot].resolver.store(nullptr, std::memory_order_release);
    g_slots[slot].live.store(false, std::memory_order_release);
}

void set_fault_resolver(int slot, FaultResolver resolver, void* context) {
    if (slot < 0) return;
    g_slots[slot].resolver.store(nullptr, std::memory_order_release);
    g_slots[slot].resolver_context = context;
    g_slots[slot].resolver.store(resolver, std::memory_order_release);
}

}  // namespace octiso::io
