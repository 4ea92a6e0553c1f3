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
//              | step 0, depth 0:        InteriorNode<T>[1], bases (the root) |
//              | step 0, depth 1:        InteriorNode<T>[n1], group bases     |
//              |   ...                                                        |
//              | step 0, depth dmax-2:   InteriorNode<T>[n(dmax-2)], bases    |
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
//  Interior section of depth d (format 5, issue 19): count InteriorNode<T> records, zero bytes up
//  to a multiple of 8, then node_groups(count) = ceil(count / 128) u64 group bases:
//    +-----------------------------+-----------+------------------------------------------+
//    | InteriorNode<T>[count]      | 0..7 zero | u64 group_base[ceil(count / 128)]        |
//    +-----------------------------+-----------+------------------------------------------+
//  Node i's first child is group_base[i / 128] + its child_offset: a node index at depth d+1, or
//  (d = dmax-2) a byte offset into the caps. Canonical: every node's first child is the sum of
//  the children spans of the nodes before it, so child_offset of a group's first node is 0.
//
//  InteriorNode<T> record (s = sizeof(T)), no padding:
//    +-----------+---------------------------------------+--------------+------------+----------+------+
//    | scalar[8] | bounds                                 | child_offset | child_mask | cap_bits | tail |
//    | 8 T       | s == 1: min[8], max[8] (T, exact)      | u16          | u8         | u8       | s==8:|
//    |           | s > 1:  lo, hi (T), qmin[8], qmax[8]   |              |            | (dmax-2  | u32  |
//    |           |         (u8)                           |              |            |  only)   | zero |
//    +-----------+---------------------------------------+--------------+------------+----------+------+
//    28 bytes for 1-byte scalars, 40 for 2, 60 for 4, 104 for 8 (format 4: 32, 44, 64, 104; format 2:
//    24 s + 8).
//  Caps section: a byte array (record_bytes 1, count = its bytes). The caps of one depth dmax-2
//  parent follow each other from its first child (a byte offset). Each is 8 deltas of b bits,
//  little-endian bit order, delta k at bits [k b, (k+1) b) of a little-endian word:
//    s > 1:  b = cap_bits; the word is the cap's b bytes; voxel k = key (ScalarKey) of the
//            parent's scalar[c] + delta k; b == 8 s: the 8 voxels stored whole;
//    s == 1: b = cap_bits & 0x7f (1 .. 8), anchor a = cap_bits >> 7 (format 6, CapAnchor in
//            octree.h); the word's byte 0 is the parent's scalar[c], bytes 1 .. b-1 the cap's
//            b - 1 bytes; voxel k = min[c] + delta k (a = 0) or max[c] - (2^b - 1) + delta k
//            (a = 1), keys mod 256.
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
/// 5: first children as group bases plus 16-bit offsets, the scalars first in the record (issue
/// 19); version 4 files are refused with a message to convert again.
/// 6: 1-byte caps take their base from the child's lower or upper bound, their first byte in the
/// parent's scalar slot (CapAnchor, issue 19); version 5 files are refused with a message to
/// convert again.
inline constexpr uint32_t kFormatVersion = 6;
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
    uint32_t record_bytes;   // 12  sizeof(InteriorNode<T>), or 1 (caps: bytes)
    uint64_t offset;         // 16  multiple of 64
    uint64_t bytes;          // 24  caps: count; interior: interior_section_bytes(count)
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
    constexpr size_t bounds = s == 1 ? 16 : 2 * s + 16;
    return std::is_trivially_copyable_v<N> && std::is_standard_layout_v<N> &&
           sizeof(N) == 8 * s + bounds + 4 + (s == 8 ? 4 : 0) && offsetof(N, scalar) == 0 &&
           offsetof(N, bounds) == 8 * s && offsetof(N, child_offset) == 8 * s + bounds &&
           offsetof(N, child_mask) == 8 * s + bounds + 2 && offsetof(N, cap_bits) == 8 * s + bounds + 3 &&
           alignof(N) <= 8;
}
static_assert(record_layout_ok<uint8_t>() && record_layout_ok<int8_t>() && record_layout_ok<uint16_t>() &&
              record_layout_ok<int16_t>() && record_layout_ok<uint32_t>() && record_layout_ok<int32_t>() &&
              record_layout_ok<float>() && record_layout_ok<double>());

/// Size of one record of each kind for a scalar of `scalar_bytes` bytes (1, 2, 4 or 8); the cap
/// level is a byte array.
inline constexpr uint64_t interior_record_bytes(uint64_t scalar_bytes) {
    return scalar_bytes == 1 ? 28 : 10 * scalar_bytes + (scalar_bytes == 8 ? 24 : 20);
}
inline constexpr uint64_t cap_record_bytes(uint64_t) { return 1; }
static_assert(interior_record_bytes(1) == sizeof(InteriorNode<uint8_t>) &&
              interior_record_bytes(2) == sizeof(InteriorNode<int16_t>) &&
              interior_record_bytes(4) == sizeof(InteriorNode<float>) &&
              interior_record_bytes(8) == sizeof(InteriorNode<double>));
/// Where an interior section's group bases start, and its whole size, for `count` records
/// (callers keep count * record far below 2^64, checked before use).
inline constexpr uint64_t group_bases_offset(uint64_t count, uint64_t scalar_bytes) {
    return group_bases_at(count * interior_record_bytes(scalar_bytes));
}
inline constexpr uint64_t interior_section_bytes(uint64_t count, uint64_t scalar_bytes) {
    return level_bytes(count, interior_record_bytes(scalar_bytes));
}

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
