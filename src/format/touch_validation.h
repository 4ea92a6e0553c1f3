// Verify::Touched (issue 13): a step's interior nodes are checked when a thread first reads them,
// not all at open, so a frame of a 30 GB file reads and checks what it touches.
//
// How: at open, every block of the mapping that holds interior-node bytes is protected
// (PROT_NONE). The first read of such a block faults; the mapping guard's handler calls
// on_fault(), which checks every interior node intersecting the block through a second,
// always-readable view of the file (node_defect: fields, and children inside the level below,
// exactly the local checks of Verify::Full) and only then makes the block readable, so no
// thread ever reads an unchecked node. A block with a bad node is replaced by zero pages (a zero
// node has no children: nothing past it is followed) and the first defect is kept; the tools
// ask failure() before they publish anything (OctFile::check_unchanged) and exit 2 naming the
// node, as Verify::Full would have at open.
//
// What it does not check, against Verify::Full: section checksums (a flipped bit in a value
// is drawn, not refused) and the cross-node rules (children of consecutive nodes follow each
// other without gap or overlap, and cover the level below). Neither is needed to keep every
// read inside the file; `octiso-info --verify` runs them all.
//
// Cost: one fault and one block check per block a frame first touches; nothing in the hot loops.
// Blocks are at least 256 KiB and at most kMaxBlocks per file, so a file never splits into more
// mappings than the kernel allows (vm.max_map_count, 65530 by default). A frame's nodes are
// scattered over the levels, so a smaller block reads and checks fewer bytes that no ray needs:
// against 2 MiB, a 512^2 frame of a 1.2-1.5 GiB file (plume, mixing 2048^3) from a cold page
// cache took 0.80-0.88 x the time exact and 0.73-0.83 x at --lod 1 (min of 5 interleaved pairs,
// build_ab_cold_blocks_256k_*.json; BENCHMARKS "Level of detail", tenth session), its checked
// bytes down from 614 to 359 MiB and from 246 to 116 MiB (plume;
// cold_blocks_scratch_counts_stop43.json). Blocks of 256 KiB stand from 1 GiB (where --verify
// auto turns to touched) up to 2 GiB; larger files take kMaxBlocks.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "format/oct_layout.h"
#include "octiso/oct_file.h"

namespace octiso::format {

class TouchValidator {
public:
    static constexpr uint64_t kMinBlockBytes = uint64_t(256) << 10;
    static constexpr uint64_t kMaxBlocks = 8192;

    /// Protects the interior blocks of `base` (the whole file, `bytes`, mapped read-only from
    /// `fd` and registered with the mapping guard as `guard_slot`, >= 0; header and section
    /// table already validated, `table_offset` from the header). Throws Error(path, ...) if the
    /// second view cannot be mapped or a block cannot be protected (the mapping is left readable).
    TouchValidator(const std::string& path, int fd, const std::byte* base, uint64_t bytes, const OctInfo& info,
                   uint64_t table_offset, int guard_slot);
    ~TouchValidator();
    TouchValidator(const TouchValidator&) = delete;
    TouchValidator& operator=(const TouchValidator&) = delete;

    /// The fault handler's entry (io::FaultResolver). True when the block at `address` is now
    /// readable (checked, or zeroed after a defect), false when the fault is not this
    /// validator's (outside its blocks, a block already readable and the access a store).
    static bool resolve(void* self, const void* address, bool write) noexcept;

    /// The first defect found so far, worded like Verify::Full's message; empty if none.
    std::optional<std::string> failure() const;
    uint64_t blocks() const { return block_count_; }
    uint64_t blocks_checked() const { return checked_.load(std::memory_order_relaxed); }
    uint64_t block_bytes() const { return block_bytes_; }

private:
    enum State : uint8_t { kReadable = 0, kProtected = 1 };   // a zeroed block is readable too
    bool on_fault(const void* address, bool write) noexcept;
    /// Checks every interior node intersecting [lo, hi) of the file through the view; records
    /// the first defect and returns false if there is one.
    bool check_range(uint64_t lo, uint64_t hi) noexcept;
    template <typename T> bool check_section(uint64_t section, uint64_t lo, uint64_t hi) noexcept;
    /// What the children of interior section i may index: the next level's nodes, or the bytes
    /// of caps without their zero slack (the loader's cap_bytes).
    uint64_t next_count(uint64_t i) const noexcept;

    std::string path_;
    const std::byte* base_;
    const std::byte* view_ = nullptr;   // the second mapping: what the checks read
    uint64_t bytes_;
    OctInfo info_;
    int guard_slot_;
    const SectionEntry* table_;         // inside view_
    uint64_t section_count_;
    uint64_t block_bytes_ = kMinBlockBytes;
    uint64_t block_count_ = 0;
    std::unique_ptr<std::atomic<uint8_t>[]> state_;
    std::atomic<uint64_t> checked_{0};
    // The first defect: written once by the thread that wins `failed_`, read after `recorded_`.
    std::atomic<bool> failed_{false};
    std::atomic<bool> recorded_{false};
    uint64_t bad_section_ = 0, bad_node_ = 0;
};

}  // namespace octiso::format
