// The policy for a mapped input that changes under octiso (issue 18: `cp other.oct live.oct` or
// `truncate` during a render gave SIGBUS; rewriting indices in place after validation, SIGSEGV).
//  - octiso's writers never write into an existing file: they publish a new inode by rename
//    (AtomicOutput), so a mapping octiso holds is never changed by octiso itself;
//  - readers hold a shared flock on every file they map, for the mapping's lifetime, and refuse
//    (exit 2, no wait) a file someone holds an exclusive flock on, so a cooperating writer
//    (`flock -x live.oct cp new.oct live.oct`) and a render exclude each other;
//  - for anything else, a SIGBUS inside a registered mapping, or a SIGSEGV/SIGBUS anywhere while
//    a registered file's size or modification time differs from when it was mapped, ends the
//    process with one line naming the file and exit status 2, instead of dying on the signal.
//  - a SIGSEGV in a registered mapping that its resolver claims (the touch validator's blocks,
//    still protected until their nodes are checked: format/touch_validation.h) is retried;
//    any other fault goes on to the previous handler (the default action: a core dump).
#pragma once

#include <cstdint>
#include <string>

namespace octiso::io {

/// Takes a shared, non-blocking flock on `fd`; throws Error(path, ...) (bad input) if another
/// process holds an exclusive one. Filesystems without flock support are accepted silently.
void lock_shared_or_refuse(int fd, const std::string& path);

/// Registers the mapping [base, base + bytes) of file `path`, open as `fd` (which must stay open
/// until unregister_mapping). Returns a slot, or -1 if all slots are taken (then unguarded).
int register_mapping(const void* base, uint64_t bytes, int fd, const std::string& path);
void unregister_mapping(int slot);

/// Called in the signal handler for a SIGSEGV at `address` inside slot's mapping (`write`: the
/// access was a store, where the CPU says so); returns true when it made the access valid, so
/// that the faulting instruction runs again. Async-signal-safe code only.
using FaultResolver = bool (*)(void* context, const void* address, bool write) noexcept;
/// Sets (or, with nullptr, clears) the resolver of a live slot; a slot of -1 is ignored.
void set_fault_resolver(int slot, FaultResolver resolver, void* context);

}  // namespace octiso::io
