// Verify::Touched: block protection and the fault-time node checks (see touch_validation.h).
// on_fault() and everything it calls run inside a signal handler: no allocation, no locks, no
// exceptions; only loads, atomics and the mprotect / mmap / madvise system calls.
#include "format/touch_validation.h"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstring>

#include <sys/mman.h>
#include <unistd.h>

#include "format/validate.h"
#include "octiso/error.h"
#include "util/mapping_guard.h"

namespace octiso::format {

namespace {

uint64_t page_bytes() {
    static const uint64_t page = uint64_t(::sysconf(_SC_PAGESIZE));
    return page;
}

}  // namespace

TouchValidator::TouchValidator(const std::string& path, int fd, const std::byte* base, uint64_t bytes, const OctInfo& info,
                               uint64_t table_offset, int guard_slot)
    : path_(path), base_(base), bytes_(bytes), info_(info), guard_slot_(guard_slot) {
    void* v = ::mmap(nullptr, size_t(bytes), PROT_READ, MAP_PRIVATE, fd, 0);
    if (v == MAP_FAILED) throw Error(path, std::string("cannot map: ") + std::strerror(errno), ErrorKind::Other);
    view_ = static_cast<const std::byte*>(v);
    table_ = reinterpret_cast<const SectionEntry*>(view_ + table_offset);
    section_count_ = uint64_t(info.step_count) * uint64_t(info.dmax);
    // Power-of-two blocks of whole pages, few enough for the kernel's mapping limit.
    block_bytes_ = std::max({kMinBlockBytes, std::bit_ceil((bytes + kMaxBlocks - 1) / kMaxBlocks), page_bytes()});
    block_count_ = (bytes + block_bytes_ - 1) / block_bytes_;
    state_ = std::make_unique<std::atomic<uint8_t>[]>(size_t(block_count_));   // all kReadable (0)
    const uint64_t dmax = uint64_t(info.dmax);
    for (uint64_t k = 0; k < info.step_count; ++k) {
        const SectionEntry& first = table_[k * dmax];
        const SectionEntry& last = table_[k * dmax + dmax - 2];   // the cap parents
        const uint64_t lo = first.offset, hi = last.offset + last.bytes;
        if (hi <= lo) continue;
        for (uint64_t b = lo / block_bytes_; b < (hi + block_bytes_ - 1) / block_bytes_; ++b) state_[b].store(kProtected);
    }
    // The resolver first, so that no protected byte is ever read without it.
    io::set_fault_resolver(guard_slot_, &TouchValidator::resolve, this);
    const uint64_t mapped = (bytes + page_bytes() - 1) / page_bytes() * page_bytes();
    for (uint64_t b = 0; b < block_count_;) {
        if (state_[b].load() != kProtected) {
            ++b;
            continue;
        }
        uint64_t e = b;
        while (e < block_count_ && state_[e].load() == kProtected) ++e;
        const uint64_t lo = b * block_bytes_, hi = std::min(mapped, e * block_bytes_);
        if (::mprotect(const_cast<std::byte*>(base_) + lo, size_t(hi - lo), PROT_NONE) != 0) {
            const int err = errno;
            io::set_fault_resolver(guard_slot_, nullptr, nullptr);
            ::mprotect(const_cast<std::byte*>(base_), size_t(mapped), PROT_READ);
            ::munmap(const_cast<std::byte*>(view_), size_t(bytes_));
            throw Error(path, std::string("cannot protect the mapping for on-touch validation: ") + std::strerror(err),
                        ErrorKind::Other);
        }
        b = e;
    }
}

TouchValidator::~TouchValidator() {
    io::set_fault_resolver(guard_slot_, nullptr, nullptr);
    ::munmap(const_cast<std::byte*>(view_), size_t(bytes_));
}

bool TouchValidator::resolve(void* self, const void* address, bool write) noexcept {
    return static_cast<TouchValidator*>(self)->on_fault(address, write);
}

bool TouchValidator::on_fault(const void* address, bool write) noexcept {
    const auto* a = static_cast<const std::byte*>(address);
    if (a < base_ || a >= base_ + bytes_) return false;
    const uint64_t b = uint64_t(a - base_) / block_bytes_;
    if (state_[b].load(std::memory_order_acquire) != kProtected)
        // Another thread opened the block between this fault and now: run the load again. A
        // store into the read-only mapping is a bug, not ours to hide.
        return !write;
    const uint64_t lo = b * block_bytes_, hi = std::min(bytes_, lo + block_bytes_);
    const uint64_t len = (hi - lo + page_bytes() - 1) / page_bytes() * page_bytes();
    std::byte* block = const_cast<std::byte*>(base_) + lo;
    // Threads faulting on one block together all check it and reach the same verdict, so the
    // block opens only after some thread has checked every node in it.
    if (check_range(lo, hi)) {
        if (::mprotect(block, size_t(len), PROT_READ) != 0) return false;
        state_[b].store(kReadable, std::memory_order_release);
    } else {
        // Zero pages over the block: a zero node has no stored child, so nothing beyond it is
        // followed while the frame that is about to be refused runs out.
        if (::mmap(block, size_t(len), PROT_READ, MAP_PRIVATE | MAP_ANONYMOUS | MAP_FIXED, -1, 0) == MAP_FAILED) return false;
        state_[b].store(kReadable, std::memory_order_release);
    }
    // What the check read through the view need not stay resident twice.
    ::madvise(const_cast<std::byte*>(view_) + lo, size_t(len), MADV_DONTNEED);
    checked_.fetch_add(1, std::memory_order_relaxed);
    return true;
}

bool TouchValidator::check_range(uint64_t lo, uint64_t hi) noexcept {
    // Sections lie in file order (the loader checked canonical offsets): the first one ending
    // after lo, then on while they start before hi.
    uint64_t i = uint64_t(std::partition_point(table_, table_ + section_count_,
                                               [lo](const SectionEntry& s) { return s.offset + s.bytes <= lo; }) -
                          table_);
    const uint64_t dmax = uint64_t(info_.dmax);
    for (; i < section_count_ && table_[i].offset < hi; ++i) {
        if (table_[i].depth == dmax - 1 || table_[i].count == 0) continue;   // caps: data, no indices
        const bool ok = dispatch_scalar_type(info_.type, [&](auto t) { return check_section<decltype(t)>(i, lo, hi); });
        if (!ok) return false;
    }
    return true;
}

template <typename T> bool TouchValidator::check_section(uint64_t i, uint64_t lo, uint64_t hi) noexcept {
    const SectionEntry& s = table_[i];
    const uint64_t rec = sizeof(InteriorNode<T>);   // = s.record_bytes (check_table)
    const uint64_t from = lo > s.offset ? (lo - s.offset) / rec : 0;
    const uint64_t end = std::min(hi, s.offset + s.bytes);
    const uint64_t to = std::min(s.count, (end - s.offset + rec - 1) / rec);
    const bool caps_below = s.depth == uint64_t(info_.dmax) - 2;
    const uint64_t below = next_count(i);
    const auto* nodes = reinterpret_cast<const InteriorNode<T>*>(view_ + s.offset);
    const auto* bases = reinterpret_cast<const uint64_t*>(view_ + s.offset + group_bases_offset(s.count, sizeof(T)));
    for (uint64_t n = from; n < to; ++n)
        if (node_defect(nodes[n], bases[n >> kNodeGroupShift], caps_below, below) != NodeDefect::none) {
            if (!failed_.exchange(true, std::memory_order_acq_rel)) {
                bad_section_ = i;
                bad_node_ = n;
                recorded_.store(true, std::memory_order_release);
            }
            return false;
        }
    return true;
}

uint64_t TouchValidator::next_count(uint64_t i) const noexcept {
    const SectionEntry& next = table_[i + 1];   // depth + 1 of the same step: exists below the caps
    return next.depth == uint64_t(info_.dmax) - 1 ? next.count - kCapReadSlack : next.count;   // >= slack (check_table)
}

std::optional<std::string> TouchValidator::failure() const {
    if (!recorded_.load(std::memory_order_acquire)) return std::nullopt;
    const SectionEntry& s = table_[bad_section_];
    const bool caps_below = s.depth == uint64_t(info_.dmax) - 2;
    const std::string problem = dispatch_scalar_type(info_.type, [&](auto t) {
        using T = decltype(t);
        const auto* bases = reinterpret_cast<const uint64_t*>(view_ + s.offset + group_bases_offset(s.count, sizeof(T)));
        return node_problem(reinterpret_cast<const InteriorNode<T>*>(view_ + s.offset)[bad_node_],
                            bases[bad_node_ >> kNodeGroupShift], caps_below, next_count(bad_section_));
    });
    return where(s.step, int(s.depth), info_.dmax) + ", node " + std::to_string(bad_node_) + ": " + problem;
}

}  // namespace octiso::format
