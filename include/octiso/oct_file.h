// The .oct file: a versioned header, one or more time steps of one octree each, a section table,
// 64-byte aligned sections with an XXH3 checksum each. OctWriter streams steps to a temporary
// file and renames it on success (never a partial output). OctFile maps a file read-only and
// hands out zero-copy Octree<T> views, each step validated completely before its first use.
// The byte layout is drawn in src/format/oct_layout.h.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "octiso/octree.h"
#include "octiso/volume.h"

namespace octiso {

/// What a .oct file says about its data, shared by all steps.
struct OctInfo {
    ScalarType type = ScalarType::u8;
    Dims dims;
    Placement placement;
    int dmax = 0;
    std::optional<std::array<double, 2>> iso_range;   ///< converted with --iso-range LO,HI
    double tolerance = 0.0;                            ///< 0: lossless
    uint32_t step_count = 0;
    /// Stored-to-real values (NIfTI scl_slope/scl_inter). iso_range and tolerance above, the
    /// nodes' min/max and the renderer's isovalues are stored values; tools report real ones.
    ValueScale value_scale;
    uint8_t flipped_axes = 0;                          ///< source axes reversed at conversion (volume.h)
};

/// Streams an .oct file: open, add_step() once per time step in order, finish(). Until finish()
/// returns, only a temporary sibling file exists; the destructor removes it if finish() never ran.
class OctWriter {
public:
    OctWriter(std::string path, const OctInfo& info);   ///< info.step_count is filled in by finish()
    ~OctWriter();
    OctWriter(const OctWriter&) = delete;
    OctWriter& operator=(const OctWriter&) = delete;

    template <typename T> void add_step(const Octree<T>& octree);

    /// A step streamed section by section (the out-of-core converter, whose arrays never sit in
    /// memory whole): for d = 0 .. dmax-1 in order, begin_section(d, count), append_records() with
    /// exactly count records (InteriorNode<T>, Caps at dmax-1) in as many calls as convenient, and
    /// after an interior level's records 0-7 zero bytes to a multiple of 8 and its group bases
    /// (oct_layout.h: the section is interior_section_bytes(count) in all), then
    /// end_section(); the step counts once its caps section ends. The checksum is computed as the
    /// bytes pass. The caller validates the records (it alone sees them all, one chunk at a time).
    void begin_section(int depth, uint64_t count);
    void append_records(const void* data, uint64_t bytes);
    void end_section();

    void finish();
    uint64_t bytes_written() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// How much of each step the loader checks, and when.
///  - Full: at the step's first use, every section checksum, then every node (validate.h).
///  - IndicesOnly: the same without the checksums.
///  - Touched: at first use only the counts; each block of nodes when a thread first reads it,
///    with the node checks of Full that memory safety rests on (no read outside the file on any
///    input), and neither checksums nor the rules across nodes (format/touch_validation.h).
///    A defect is reported by check_unchanged(). Costs the first frame what it touches, not
///    the file (issue 13: a 30 GB file is no longer read whole before its first pixel).
enum class Verify { Full, IndicesOnly, Touched };

/// Verify::Touched's progress: the file in blocks, and how many were checked so far.
struct TouchStats {
    uint64_t blocks = 0, checked = 0, block_bytes = 0;
};

/// Section sizes of one step, for reports.
struct StepSizes {
    uint64_t interior_bytes = 0, minmax_bytes = 0, cap_bytes = 0;
    std::vector<uint64_t> nodes_per_depth;          ///< d = 0 .. dmax-1 (caps last)
    std::vector<uint64_t> scalar_leaves_per_depth;  ///< leaf children of depth-d nodes
};

class OctFile {
public:
    /// Maps `path` and validates header and section table. Throws Error(path, ...) on any defect.
    static OctFile open(const std::string& path, Verify verify = Verify::Full);
    OctFile(OctFile&&) noexcept;
    OctFile& operator=(OctFile&&) noexcept;
    ~OctFile();

    const OctInfo& info() const;
    const std::string& path() const;
    uint64_t file_bytes() const;
    /// Step k as a zero-copy view; its sections are validated on the first call (thread-safe).
    /// Throws Error(path, ...) if T is not the file's type, k is out of range, or the step is bad.
    template <typename T> Octree<T> step(uint32_t k) const;
    /// Sizes of step k (validates it first, like step(); under Verify::Touched it reads every node).
    StepSizes step_sizes(uint32_t k) const;
    /// The mode in force: Touched falls back to Full when the fault handler has no free slot.
    Verify verify() const;
    std::optional<TouchStats> touch_stats() const;   ///< Verify::Touched only
    /// Throws Error(path, ...) (bad input) if the file's size or modification time differs from
    /// when it was opened: another program rewrote it in place, so what was read from the
    /// mapping since is not what was validated (issue 18; policy in src/util/mapping_guard.h);
    /// or, under Verify::Touched, if a node read since failed its checks (named in the message).
    /// Tools call it before publishing anything computed from the file.
    void check_unchanged() const;
    /// Unmaps this process's copies of the file's pages (madvise MADV_DONTNEED on the read-only
    /// mapping; the data stay valid and fault back in on their next read). Sort-last rendering
    /// calls it after the steps were validated (which reads every byte), so that what the process
    /// holds while rendering is what its brick touches (issue 15).
    void release_resident_pages() const;

private:
    OctFile();
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace octiso
