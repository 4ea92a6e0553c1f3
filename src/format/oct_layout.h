// The on-disk layout of a .oct file: header, section table entries, alignment and the checksum
// helper. Plain structs written and mapped byte for byte (little-endian hosts only), so a mapped
// file hands out InteriorNode<T> / Cap<T> arrays without copying. writer.cpp produces exactly this
// layout; loader.cpp and validate.cpp reject anything else.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "octiso/octree.h"

// ---------------------------------------------------------------------------------------------
//  A .oct file (every multi-byte number little-endian, every section start 64-byte aligned)
//
//  offset 0    +-------------------------------------------------------------+
//              | FileHeader (256 bytes)                                       |
//              |   magic "OCTISO\0\x1a" | version | header_bytes | endian tag |
//              |   scalar type, dims, dmax, spacing, origin, iso-range,        |
//              |   tolerance, step count, table offset/count, file bytes,      |
//              |   XXH3-64 of the table, value slope/intercept, flipped axes,  |
//              |   XXH3-64 of header bytes [0, 248)                            |
//  256         +-------------------------------------------------------------+
//              | zero padding to the next multiple of 64                      |
//              +-------------------------------------------------------------+
//              | step 0, depth 0:        InteriorNode<T>[1]       (the root)  |
//              | step 0, depth 1:        InteriorNode<T>[n1]                  |
//              |   ...                                                        |
//              | step 0, depth dmax-2:   InteriorNode<T>[n(dmax-2)]           |
//              | step 0, depth dmax-1:   packed caps (bytes), 8 zero bytes    |
//              | step 1, depth 0 ...     (each section starts at the next     |
//              |   ...                    multiple of 64; gaps are zero)      |
//              | step S-1, depth dmax-1: packed caps ...                      |
//              +-------------------------------------------------------------+
//              | SectionEntry[S * dmax]  (64-aligned, in (step, depth) order) |
//  file_bytes  +-------------------------------------------------------------+
//
//  The layout is canonical: section i of the table sits at align64(end of section i-1) (the
//  first at align64(256)), the table at align64(end of the last section), and the file ends
//  with the table. So every byte of the file is covered by a checksum or must be zero, and a
//  single flipped bit anywhere is detected (Verify::Full).
//
//  InteriorNode<T> record (formats 3 and 4, issue 19; s = sizeof(T)), no padding:
//    +-------------+----------------+------------+----------+-----------+------------------------+
//    | child_start | child_start_hi | child_mask | cap_bits | scalar[8] | bounds                 |
//    | u32         | u16            | u8         | u8       | 8 T       | s == 1: min[8], max[8] |
//    |             | (caps: byte    |            | (dmax-2  |           |   (8 T each, exact)    |
//    |             |  offset bits   |            |  only)   |           | s > 1: lo, hi (T),     |
//    |             |  32..47)       |            |          |           |   qmin[8], qmax[8] (u8)|
//    +-------------+----------------+------------+----------+-----------+------------------------+
//    32 bytes for 1-byte scalars, 44 for 2, 64 for 4, 104 for 8 (format 2: 24 s + 8).
//  Caps section: a byte array (record_bytes 1, count = its bytes). The caps of one depth dmax-2
//  parent follow each other from its first_child() byte, each cap_bits bytes: 8 deltas of
//  cap_bits bits, little-endian bit order, voxel k at bits [k b, (k+1) b) of the record, added to
//  the key (ScalarKey) of the parent's scalar[c]; cap_bits == 8 s: the 8 voxels stored whole.
//  The section ends with kCapReadSlack zero bytes (every delta is one 8-byte load). Octant
//  c = x<<2 | y<<1 | z.
// ---------------------------------------------------------------------------------------------

namespace octiso::format {

static_assert(std::endian::native == std::endian::little,
              ".oct files are mapped without byte swapping: little-endian hosts only");

inline constexpr char kMagic[8] = {'O', 'C', 'T', 'I', 'S', 'O', '\0', '\x1a'};
/// 2: value slope/intercept and flipped axes (NIfTI scl_slope/scl_inter and negative affine
/// axes, issue 17). Version 1 files are refused: they may hold NIfTI data stored unscaled.
/// 3: the compact node layout and packed caps (issue 19). Version 2 files are refused with a
/// message to convert again (their records are not this layout).
/// 4: a stored interior child's scalar is the voxel at its lower corner, the level-of-detail
/// lattice sample (issue 14), where format 3 kept the midpoint of its range; same layout, and
/// version 3 files are refused with a message to convert again (`--lod` would misread them).
inline constexpr uint32_t kFormatVersion = 4;
inline constexpr uint32_t kEndianTag = 0x01020304u;   ///< reads back as 0x04030201 if swapped
inline constexpr uint64_t kSectionAlign = 64;

enum class SectionKind : uint32_t { Interior = 1, Caps = 2 };

/// The 256-byte header at offset 0. Field offsets are fixed by the static_asserts below.
struct FileHeader {
    char magic[8];                    //   0  kMagic
    uint32_t version;                 //   8  kFormatVersion
    uint32_t header_bytes;            //  12  sizeof(FileHeader)
    uint32_t endian_tag;              //  16  kEndianTag
    uint8_t scalar_type;              //  20  ScalarType numeric value
    uint8_t scalar_bytes;             //  21  sizeof(T)
    uint8_t has_iso_range;            //  22  0 or 1
    uint8_t dmax;                     //  23  dmax_for(dims)
    uint32_t dims[3];                 //  24  NX, NY, NZ in [1, Dims::kMaxExtent]
    uint32_t step_count;              //  36  >= 1
    double spacing[3];                //  40  finite, > 0
    double origin[3];                 //  64  finite
    double iso_range[2];              //  88  lo < hi if has_iso_range, else zero
    double tolerance;                 // 104  finite, >= 0 (0: lossless)
    uint64_t section_table_offset;    // 112  multiple of 64
    uint64_t section_count;           // 120  step_count * dmax
    uint32_t section_entry_bytes;     // 128  sizeof(SectionEntry)
    uint32_t reserved0;               // 132  zero
    uint64_t file_bytes;              // 136  length of the whole file
    uint64_t section_table_checksum;  // 144  XXH3-64 of the table bytes
    double value_slope;               // 152  real = stored * slope + inter: finite, != 0 (1: identity)
    double value_inter;               // 160  finite
    uint8_t flipped_axes;             // 168  bit a: source axis a reversed (0 .. kAllAxesFlipped)
    uint8_t reserved[79];             // 169  zero
    uint64_t header_checksum;         // 248  XXH3-64 of header bytes [0, 248)
};

/// One entry of the section table: where the records of (step, depth) live.
struct SectionEntry {
    uint32_t kind;           //  0  SectionKind: Interior for depth <= dmax-2, Caps at dmax-1
    uint32_t step;           //  4  0 .. step_count-1
    uint32_t depth;          //  8  0 .. dmax-1
    uint32_t record_bytes;   // 12  sizeof(InteriorNode<T>) or sizeof(Cap<T>)
    uint64_t offset;         // 16  multiple of 64
    uint64_t bytes;          // 24  count * record_bytes
    uint64_t count;          // 32  records
    uint64_t checksum;       // 40  XXH3-64 of the section bytes
};

static_assert(std::is_trivially_copyable_v<FileHeader> && std::is_standard_layout_v<FileHeader>);
static_assert(sizeof(FileHeader) == 256);
static_assert(offsetof(FileHeader, version) == 8 && offsetof(FileHeader, endian_tag) == 16);
static_assert(offsetof(FileHeader, scalar_type) == 20 && offsetof(FileHeader, dims) == 24);
static_assert(offsetof(FileHeader, step_count) == 36 && offsetof(FileHeader, spacing) == 40);
static_assert(offsetof(FileHeader, origin) == 64 && offsetof(FileHeader, iso_range) == 88);
static_assert(offsetof(FileHeader, tolerance) == 104 && offsetof(FileHeader, section_table_offset) == 112);
static_assert(offsetof(FileHeader, section_entry_bytes) == 128 && offsetof(FileHeader, file_bytes) == 136);
static_assert(offsetof(FileHeader, section_table_checksum) == 144 && offsetof(FileHeader, value_slope) == 152);
static_assert(offsetof(FileHeader, value_inter) == 160 && offsetof(FileHeader, flipped_axes) == 168);
static_assert(offsetof(FileHeader, reserved) == 169);
static_assert(offsetof(FileHeader, header_checksum) == 248);
inline constexpr size_t kHeaderChecksummedBytes = offsetof(FileHeader, header_checksum);

static_assert(std::is_trivially_copyable_v<SectionEntry> && sizeof(SectionEntry) == 48);
static_assert(offsetof(SectionEntry, offset) == 16 && offsetof(SectionEntry, checksum) == 40);

/// The node records are written as raw bytes: their size must be exactly the drawing above.
template <typename T> constexpr bool record_layout_ok() {
    using N = InteriorNode<T>;
    constexpr size_t s = sizeof(T);
    return std::is_trivially_copyable_v<N> && std::is_standard_layout_v<N> &&
           sizeof(N) == 8 + 8 * s + (s == 1 ? 16 : 2 * s + 16) && offsetof(N, child_start_hi) == 4 &&
           offsetof(N, child_mask) == 6 && offsetof(N, cap_bits) == 7 && offsetof(N, scalar) == 8 &&
           offsetof(N, bounds) == 8 + 8 * s && alignof(N) <= kSectionAlign;
}
static_assert(record_layout_ok<uint8_t>() && record_layout_ok<int8_t>() && record_layout_ok<uint16_t>() &&
              record_layout_ok<int16_t>() && record_layout_ok<uint32_t>() && record_layout_ok<int32_t>() &&
              record_layout_ok<float>() && record_layout_ok<double>());

/// Size of one record of each kind for a scalar of `scalar_bytes` bytes (1, 2, 4 or 8); the cap
/// level is a byte array.
inline constexpr uint64_t interior_record_bytes(uint64_t scalar_bytes) {
    return 8 + 8 * scalar_bytes + (scalar_bytes == 1 ? 16 : 2 * scalar_bytes + 16);
}
inline constexpr uint64_t cap_record_bytes(uint64_t) { return 1; }

/// Next multiple of 64 at or above `x`; callers keep x far below 2^64 (checked before use).
inline constexpr uint64_t align_up(uint64_t x) { return (x + kSectionAlign - 1) & ~(kSectionAlign - 1); }

/// XXH3-64 (seed 0) of a byte range; defined in validate.cpp so only one file includes xxhash.h.
uint64_t checksum(const void* data, size_t bytes);

/// The same XXH3-64 (seed 0) over bytes handed in pieces, for sections streamed from disk
/// (the out-of-core builder): update() in order, then digest() equals checksum() of them all.
class ChecksumStream {
public:
    ChecksumStream();
    ~ChecksumStream();
    ChecksumStream(const ChecksumStream&) = delete;
    ChecksumStream& operator=(const ChecksumStream&) = delete;
    void reset();
    void update(const void* data, size_t bytes);
    uint64_t digest() const;

private:
    void* state_;   // XXH3_state_t, opaque so that only validate.cpp includes xxhash.h
};

}  // namespace octiso::format
