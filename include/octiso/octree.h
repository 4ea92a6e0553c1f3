// Octree<T>: the read-only view of a lossless octree volume (Knoll et al. 2006, Sec. 4.1, App. A),
// over memory owned elsewhere (an OctreeData built in memory, or an mmap'd .oct file). It owns the
// node layout, the packed caps and the octree hashing of App. B: point location and neighbour
// finding with a parent trace. Building lives in build.h (packing in src/octree/pack.h), files in
// oct_file.h.
//
// Index space: voxel (x,y,z) of the data, 0 <= x < dims.x (likewise y, z); the tree spans the
// power-of-two cube [0, N)^3, N = 2^dmax >= max(dims), N >= 4. Depth d runs from 0 (root) to
// dmax-1 (caps). A node at depth d covers a cube of side 2^(dmax-d); its children have side
// child_bit(d) = 2^(dmax-d-1). Child octant c = x<<2 | y<<1 | z, where x = 1 for the upper half.
//
// The compact layout (issue 19; measured by `octiso-bench compression`, BENCHMARKS.md):
//  - child bounds are quantized conservatively to 8 bits inside the node's own exact range
//    (Knoll 2006 stored 8-bit min/max too); 1-byte scalars keep their exact bounds, which are
//    no larger;
//  - a node's first child is a 64-bit base per group of 128 nodes plus a 16-bit offset
//    (format 5), not a 48-bit number per node;
//  - a cap is stored as 8 deltas of b bits, all caps of one parent with the same width, so that
//    a cap is found by a multiply. Wider scalars: from a base held in its parent's scalar slot
//    (the cap's smallest voxel, in the order of ScalarKey), b bytes a cap, or the cap stored whole
//    where that saves nothing. 1-byte scalars (format 6): from the child's lower or upper bound,
//    which the parent holds anyway, so that the slot carries the first of the b bytes and the cap
//    level b - 1 (CapAnchor below).
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>

#include "octiso/inline.h"
#include "octiso/volume.h"

namespace octiso {

inline constexpr int kMaxDepth = 31;   ///< dmax <= 30 because extents are <= 2^30; one spare

/// ScalarKey<T>: an unsigned integer of T's width whose order is the order of T's values (floats
/// by their bit pattern, negatives reversed, -0 just below +0), so that cap deltas are lossless
/// for every type, floats included.
template <typename T> struct ScalarKey {
    using Key = std::conditional_t<sizeof(T) == 1, uint8_t,
                                   std::conditional_t<sizeof(T) == 2, uint16_t,
                                                      std::conditional_t<sizeof(T) == 4, uint32_t, uint64_t>>>;
    static constexpr Key kSign = Key(Key(1) << (8 * sizeof(T) - 1));
    OCTISO_ALWAYS_INLINE static Key of(T v) {
        const Key b = std::bit_cast<Key>(v);
        if constexpr (std::is_floating_point_v<T>) return (b & kSign) ? Key(~b) : Key(b | kSign);
        else if constexpr (std::is_signed_v<T>) return Key(b ^ kSign);
        else return b;
    }
    OCTISO_ALWAYS_INLINE static T value(Key k) {
        // Floats: a set top bit (positive) clears it, a clear one flips every bit; branch-free.
        if constexpr (std::is_floating_point_v<T>) return std::bit_cast<T>(Key(k ^ (kSign | Key(Key(k >> (8 * sizeof(T) - 1)) - 1))));
        else if constexpr (std::is_signed_v<T>) return std::bit_cast<T>(Key(k ^ kSign));
        else return std::bit_cast<T>(k);
    }
};

/// Bits of one voxel of a cap stored whole (no base, no deltas).
template <typename T> inline constexpr unsigned kWholeCapBits = 8 * sizeof(T);
/// The widest delta a packed (not whole) cap may have: base + deltas must be smaller than the
/// whole cap, and every delta must come out of one unaligned 64-bit load (shift <= 7).
template <typename T> inline constexpr unsigned kMaxDeltaBits = 8 * sizeof(T) - 1 < 56 ? 8 * sizeof(T) - 1 : 56;
/// 1-byte scalars (format 6): where a cap parent's caps take their base from, bit 7 of
/// cap_bits (the width b, 1 .. 8, below it). The 8 deltas of a cap form one 64-bit word whose
/// byte 0 is the parent's scalar[c] and bytes 1 .. b-1 the cap's record, b - 1 bytes in the cap
/// level; in the scalars' keys (ScalarKey), mod 256:
///   lower: voxel k = bounds.min[c] + delta k;
///   upper: voxel k = bounds.max[c] - (2^b - 1) + delta k (the deltas count up to the bound, so
///          that both anchors decode by one add).
/// The bounds cover the cap's cells, so the base costs no byte: one byte a cap less than a base
/// in the slot where the width stays, more where the data sit near one end of their range, and
/// the packer takes the end that gives the narrower width per parent (plume 256^3 32.7 -> 29.5 %
/// of raw, mixing 25.4 -> 23.3 %, ch2better 40.0 -> 35.9 %; BENCHMARKS.md "The compact octree,
/// format 6"). Where a cap holds voxels its bounds do not (the last data layer, which no cell of
/// the cap starts at), the packer widens the bounds, which only culls less; a cap child with no
/// cells keeps empty bounds (min > max) chosen so that its deltas still fit.
/// A cap lookup reads the bound by index and subtracts, a voxel is a shift, a mask and an add:
/// no branch on the per-parent choice, which would be mispredicted (a first trial with a third,
/// slot, anchor and branches or selects on it cost 3.5-6.7 % of the frame).
enum class CapAnchor : uint8_t { lower = 0, upper = 1 };
inline constexpr unsigned kCapAnchorShift = 7;
inline constexpr uint8_t kCapWidthMask = (1u << kCapAnchorShift) - 1u;
/// cap_bits of a 1-byte parent: width b in the low bits, the anchor above.
inline constexpr uint8_t cap_bits_of(unsigned width, CapAnchor anchor) {
    return uint8_t(width | (unsigned(anchor) << kCapAnchorShift));
}

/// The cap level of one step holds at most this many bytes (2^48, 256 TiB; interior levels keep
/// 32-bit node indices, which the traversal's parent traces hold).
inline constexpr uint64_t kMaxCapByteOffset = uint64_t(1) << 48;
/// Zero bytes after the last cap of a level, so that every delta is one 8-byte load in bounds.
inline constexpr uint64_t kCapReadSlack = 8;

/// ChildBounds<T>: [lower(c), upper(c)] contains the trilinear interpolant on every data cell
/// whose lower corner lies in child c (the one-voxel forward layer +x,+y,+z counts). With no
/// such cell (pure padding or the last data layer) the bounds are empty and traversal skips the
/// child. 1-byte scalars: the exact min/max (4-bit codes, tried for format 5, made u8 frames
/// 0.84-0.99 x as fast for 6 % of raw less on plume; BENCHMARKS.md "The compact octree, format
/// 5"). Wider ones: 8-bit codes inside [lo, hi], the exact range of the node's children
/// together, in steps of s = hi/255 - lo/255 (finite for every double range): a lower code q
/// stands for lo + q s (0: lo exactly), an upper code q for hi - (255 - q) s (255: hi exactly).
/// No branch and no select in the decode (the first version, 0 and 255 as special cases, cost
/// packet_node 19 %, perf on Marschner-Lobb 256^3). The packer
/// picks the largest lower and smallest upper code that still contain the true range (it runs
/// this same decode), and qmin > qmax marks an empty child.
template <typename T, bool kExact = (sizeof(T) == 1)> struct ChildBounds;

template <typename T> struct ChildBounds<T, true> {
    T min[8];
    T max[8];
    OCTISO_ALWAYS_INLINE bool empty(int c) const { return min[c] > max[c]; }
    OCTISO_ALWAYS_INLINE double lower(int c) const { return double(min[c]); }
    OCTISO_ALWAYS_INLINE double upper(int c) const { return double(max[c]); }
    /// The exact range of all children together: [lo, hi], or lo > hi when every child is empty.
    double range_lo() const {
        double v = std::numeric_limits<double>::infinity();
        for (int c = 0; c < 8; ++c) if (!empty(c) && double(min[c]) < v) v = double(min[c]);
        return v;
    }
    double range_hi() const {
        double v = -std::numeric_limits<double>::infinity();
        for (int c = 0; c < 8; ++c) if (!empty(c) && double(max[c]) > v) v = double(max[c]);
        return v;
    }
};

template <typename T> struct ChildBounds<T, false> {
    T lo, hi;
    uint8_t qmin[8];
    uint8_t qmax[8];
    static constexpr int kTop = 255;
    OCTISO_ALWAYS_INLINE double step() const { return double(hi) * (1.0 / kTop) - double(lo) * (1.0 / kTop); }
    OCTISO_ALWAYS_INLINE double decode_lower(int q, double step) const { return double(lo) + double(q) * step; }
    OCTISO_ALWAYS_INLINE double decode_upper(int q, double step) const { return double(hi) - double(kTop - q) * step; }
    OCTISO_ALWAYS_INLINE bool empty(int c) const { return qmin[c] > qmax[c]; }
    OCTISO_ALWAYS_INLINE double lower(int c) const { return decode_lower(qmin[c], step()); }
    OCTISO_ALWAYS_INLINE double upper(int c) const { return decode_upper(qmax[c], step()); }
    /// The exact range of all children together: [lo, hi], or lo > hi when every child is empty.
    double range_lo() const {
        for (int c = 0; c < 8; ++c) if (!empty(c)) return double(lo);
        return std::numeric_limits<double>::infinity();
    }
    double range_hi() const {
        for (int c = 0; c < 8; ++c) if (!empty(c)) return double(hi);
        return -std::numeric_limits<double>::infinity();
    }
};

/// Nodes per child group (format 5, issue 19): a node's first child is its group's base, a 64-bit
/// number stored after the level's records (group_base), plus the node's own 16-bit
/// child_offset. 128 keeps every offset inside 16 bits for every type: the children of 127
/// nodes take at most 127 x 8 whole caps of 8 x 8 bytes (doubles) = 65024 bytes. The bases cost
/// 1/16 byte a node; the 48-bit first child they replace cost 4 bytes more a node.
inline constexpr uint64_t kNodeGroupShift = 7;
inline constexpr uint64_t kNodeGroup = uint64_t(1) << kNodeGroupShift;
/// Group bases of a level of `count` nodes.
inline constexpr uint64_t node_groups(uint64_t count) { return (count + kNodeGroup - 1) >> kNodeGroupShift; }

/// Zero bytes that keep every record of the widest type a multiple of its alignment with no
/// padding the compiler would add (and leave indeterminate); empty for the other types.
template <typename T> struct RecordTail {};
template <> struct RecordTail<double> { uint32_t zero = 0; };

/// InteriorNode<T>: a node at depth d, 0 <= d <= dmax-2. For each child octant c:
///   child_mask bit c clear: child c is a scalar leaf; every voxel of it equals scalar[c]
///                           (padding beyond the data excepted: it is "don't care").
///   child_mask bit c set:   child c is stored at depth d+1. Below depth dmax-2 it is the
///                           InteriorNode at index first + rank(c) (first: Octree::first_child,
///                           the group base plus child_offset; rank: stored children before c)
///                           and scalar[c] is the voxel at its lower corner (the level-of-detail
///                           lattice sample, see lattice_value). At depth dmax-2 it is a cap: its
///                           record starts at byte first + rank(c) * cap_record_bytes() of the
///                           caps (8 deltas of b bits are b bytes), and scalar[c] is its base,
///                           or (1-byte scalars, CapAnchor) the first of the b bytes.
///   bounds: ChildBounds above.
/// Every node's first child is where the previous node's children end (the first node's is 0),
/// childless nodes included, so the whole index is the prefix sum of children_span(); the loader
/// validates exactly that, and that cap_bits holds a width of kWholeCapBits or at most
/// kMaxDeltaBits (1-byte scalars: 1 .. 8, and the anchor bit; 0 where no child is stored).
template <typename T> struct InteriorNode {
    T scalar[8];
    ChildBounds<T> bounds;
    uint16_t child_offset;     ///< first child, relative to the group's base
    uint8_t child_mask;
    uint8_t cap_bits;          ///< depth dmax-2: bits per cap voxel (1-byte scalars: and CapAnchor); zero above
    [[no_unique_address]] RecordTail<T> tail;

    OCTISO_ALWAYS_INLINE bool is_scalar_leaf(int c) const { return ((child_mask >> c) & 1u) == 0; }
    OCTISO_ALWAYS_INLINE uint32_t rank(int c) const { return uint32_t(std::popcount(unsigned(child_mask) & ((1u << c) - 1u))); }
    /// A cap parent's width b (bits per delta) and, 1-byte scalars only, anchor (CapAnchor).
    OCTISO_ALWAYS_INLINE unsigned cap_width() const {
        if constexpr (sizeof(T) == 1) return cap_bits & kCapWidthMask;
        else return cap_bits;
    }
    /// 1-byte scalars: the bound a cap parent's caps count from (CapAnchor).
    OCTISO_ALWAYS_INLINE CapAnchor cap_anchor() const
        requires(sizeof(T) == 1)
    {
        return CapAnchor(cap_bits >> kCapAnchorShift);
    }
    /// Bytes of one cap in the caps: b, or (1-byte scalars) b - 1, its first byte in the slot (0
    /// where b = 0, which the loader accepts only in a cap parent with no stored child).
    OCTISO_ALWAYS_INLINE unsigned cap_record_bytes() const {
        if constexpr (sizeof(T) == 1) return cap_width() - (cap_width() != 0);
        else return cap_bits;
    }
    /// What the stored children take in the level below: nodes, or (`caps_below`, a cap parent)
    /// bytes of caps. The builders and the validator place and check children by it.
    uint64_t children_span(bool caps_below) const {
        return uint64_t(std::popcount(unsigned(child_mask))) * (caps_below ? cap_record_bytes() : 1u);
    }
    OCTISO_ALWAYS_INLINE bool may_contain_any(int c, const double* isos, int count) const {
        if (bounds.empty(c)) return false;
        const double lo = bounds.lower(c), hi = bounds.upper(c);
        for (int i = 0; i < count; ++i)
            if (lo <= isos[i] && isos[i] <= hi) return true;
        return false;
    }
};

/// A level of nodes as a .oct section holds it (src/format/oct_layout.h): the records, zero bytes
/// up to a multiple of 8, then the node_groups(count) 64-bit group bases. group_bases_at: where
/// the bases start after `records` bytes of records; level_bytes: the whole level, `count`
/// records of `record` bytes (callers keep count * record far below 2^64).
inline constexpr uint64_t group_bases_at(uint64_t records) { return (records + 7) & ~uint64_t(7); }
inline constexpr uint64_t level_bytes(uint64_t count, uint64_t record) {
    return group_bases_at(count * record) + 8 * node_groups(count);
}
template <typename T> constexpr uint64_t interior_level_bytes(uint64_t count) {
    return level_bytes(count, sizeof(InteriorNode<T>));
}

/// Cap<T>: the 2x2x2 voxels of a node at depth dmax-1, octant order as above; the builders' form
/// of a cap before packing, and what CapRef decodes to.
template <typename T> struct Cap {
    T voxel[8];
};

/// Where one packed cap lives: its record, its parent's width and its base.
template <typename T> struct CapRef {
    const uint8_t* record = nullptr;
    unsigned bits = 0;
    T base{};

    /// Voxel k (octant order).
    OCTISO_ALWAYS_INLINE T voxel(int k) const {
        if (bits == kWholeCapBits<T>) {
            T v;
            std::memcpy(&v, record + size_t(k) * sizeof(T), sizeof(T));
            return v;
        }
        const unsigned pos = unsigned(k) * bits;
        uint64_t word;
        std::memcpy(&word, record + (pos >> 3), 8);   // in bounds: kCapReadSlack
        const uint64_t delta = (word >> (pos & 7u)) & ((uint64_t(1) << bits) - 1u);
        using K = ScalarKey<T>;
        return K::value(typename K::Key(K::of(base) + delta));
    }
    /// All 8 voxels.
    OCTISO_ALWAYS_INLINE void decode(T out[8]) const {
        if (bits == kWholeCapBits<T>) {
            std::memcpy(out, record, 8 * sizeof(T));
            return;
        }
        for (int k = 0; k < 8; ++k) out[k] = voxel(k);
    }
};

/// 1-byte scalars: the cap's 8 deltas of b <= 8 bits as one 64-bit word (CapAnchor), read when
/// the cap is found, so that a voxel is a shift, a mask and an add in the key's 8 bits.
template <typename T>
    requires(sizeof(T) == 1)
struct CapRef<T> {
    uint64_t word = 0;
    unsigned bits = 0;
    uint8_t base = 0;   ///< ScalarKey of the lowest value the deltas reach (CapAnchor)

    OCTISO_ALWAYS_INLINE T voxel(int k) const {
        const unsigned delta = unsigned(word >> (unsigned(k) * bits)) & ((1u << bits) - 1u);
        return ScalarKey<T>::value(uint8_t(base + delta));
    }
    OCTISO_ALWAYS_INLINE void decode(T out[8]) const {
        for (int k = 0; k < 8; ++k) out[k] = voxel(k);
    }
};

/// Integer point in index space.
struct Coord {
    uint32_t x = 0, y = 0, z = 0;
    bool operator==(const Coord&) const = default;
};

/// Octant of `p` inside a node whose children have side `child_bit` (a power of two).
OCTISO_ALWAYS_INLINE int octant_of(Coord p, uint32_t child_bit) {
    return ((p.x & child_bit) ? 4 : 0) | ((p.y & child_bit) ? 2 : 0) | ((p.z & child_bit) ? 1 : 0);
}

/// Where point location ended: a cap voxel (`cap` is then that cap) or a scalar leaf child of an
/// interior node.
template <typename T> struct LeafRef {
    T value;            ///< a scalar leaf's value (in_cap: see voxel())
    bool in_cap;
    CapRef<T> cap;      ///< in_cap only
    int octant = 0;     ///< in_cap only: the voxel's octant in the cap

    /// The located voxel's value; a cap voxel is decoded only here, so a caller that wants the
    /// whole block (the traversal's neighbour blocks) pays for no decode it does not use.
    OCTISO_ALWAYS_INLINE T voxel() const { return in_cap ? cap.voxel(octant) : value; }
};

/// Per-depth arrays of one octree; the view's raw material. Pointers stay owned by the creator.
template <typename T> struct OctreeArrays {
    Dims dims;
    int dmax = 0;
    std::array<const InteriorNode<T>*, kMaxDepth> nodes{};   ///< depth 0 .. dmax-2
    std::array<uint64_t, kMaxDepth> node_count{};
    std::array<const uint64_t*, kMaxDepth> group_base{};   ///< depth 0 .. dmax-2: node_groups(count) each
    const uint8_t* caps = nullptr;   ///< depth dmax-1: packed cap records, then kCapReadSlack zero bytes
    uint64_t cap_bytes = 0;          ///< records only (the slack not counted)
    uint64_t cap_count = 0;
};

template <typename T> class Octree {
public:
    Octree() = default;
    explicit Octree(const OctreeArrays<T>& arrays) : a_(arrays) {}

    Dims dims() const { return a_.dims; }
    int dmax() const { return a_.dmax; }
    int cap_depth() const { return a_.dmax - 1; }
    uint32_t side() const { return 1u << a_.dmax; }
    /// Side of a child of a node at depth d: 2^(dmax-d-1) (App. A's child_bit_depth[d]).
    uint32_t child_bit(int d) const { return 1u << (a_.dmax - d - 1); }
    uint64_t node_count(int d) const { return a_.node_count[size_t(d)]; }
    uint64_t cap_count() const { return a_.cap_count; }
    uint64_t cap_bytes() const { return a_.cap_bytes; }
    const InteriorNode<T>& node(int d, uint64_t i) const { return a_.nodes[size_t(d)][i]; }
    /// Where the children of `n`, node i at depth d, start in the level below: a node index, or
    /// (d = dmax-2) a byte offset into the caps.
    OCTISO_ALWAYS_INLINE uint64_t first_child(int d, uint64_t i, const InteriorNode<T>& n) const {
        return a_.group_base[size_t(d)][i >> kNodeGroupShift] + n.child_offset;
    }
    /// Stored child c of `n`, whose first child is `first`: its index (n above dmax-2), or its cap
    /// (n at dmax-2). The traversal reads `first` once per node, on entry, so that its two
    /// dependent loads overlap the node's split.
    OCTISO_ALWAYS_INLINE uint32_t child_index_at(uint64_t first, const InteriorNode<T>& n, int c) const {
        return uint32_t(first + n.rank(c));
    }
    OCTISO_ALWAYS_INLINE CapRef<T> cap_at(uint64_t first, const InteriorNode<T>& parent, int c) const {
        if constexpr (sizeof(T) == 1) {
            using K = ScalarKey<T>;
            const unsigned bits = parent.cap_width(), upper = unsigned(parent.cap_anchor());
            // bits - 1 is cap_record_bytes(): a parent with a cap has b >= 1 (the loader checks).
            uint64_t word;   // in bounds: kCapReadSlack
            std::memcpy(&word, a_.caps + first + uint64_t(parent.rank(c)) * (bits - 1u), 8);
            CapRef<T> r;
            r.word = (word << 8) | K::of(parent.scalar[c]);
            r.bits = bits;
            // The bounds' bytes are min[8] then max[8]: the anchor's bound by index, without a
            // branch or a select; an upper anchor's deltas count up from max[c] - (2^b - 1).
            static_assert(sizeof(parent.bounds) == 16 && offsetof(ChildBounds<T>, max) == 8);
            const auto* bound_bytes = reinterpret_cast<const unsigned char*>(&parent.bounds);
            const unsigned bound = K::of(std::bit_cast<T>(bound_bytes[unsigned(c) + 8 * upper]));
            r.base = uint8_t(bound - (((1u << bits) - 1u) & (0u - upper)));
            return r;
        } else {
            return {a_.caps + first + uint64_t(parent.rank(c)) * parent.cap_bits, parent.cap_bits, parent.scalar[c]};
        }
    }
    /// Index at depth d+1 of stored child c of `n`, node i at depth d < dmax-2.
    OCTISO_ALWAYS_INLINE uint32_t child_index(int d, uint64_t i, const InteriorNode<T>& n, int c) const {
        return child_index_at(first_child(d, i, n), n, c);
    }
    /// Cap child c of `parent`, node i at depth dmax-2.
    OCTISO_ALWAYS_INLINE CapRef<T> cap(uint64_t i, const InteriorNode<T>& parent, int c) const {
        return cap_at(first_child(a_.dmax - 2, i, parent), parent, c);
    }
    const OctreeArrays<T>& arrays() const { return a_; }

    /// Value of voxel p, starting the descent at node `index` of depth `depth` <= dmax-2.
    /// Precondition: p lies inside that node's cube. Knoll 2006 App. B.1, with the child octant
    /// built by bitwise or (the paper's `||` is a slip). `side`, when given, receives the side of
    /// the scalar leaf or cap the descent ended in: the aligned cube of that side around p, whose
    /// every voxel the same reference yields.
    OCTISO_ALWAYS_INLINE LeafRef<T> locate_from(Coord p, int depth, uint32_t index, uint32_t* side = nullptr) const {
        const int cap_parents_at = a_.dmax - 2;
        for (;;) {
            const InteriorNode<T>& n = a_.nodes[size_t(depth)][index];
            const int c = octant_of(p, child_bit(depth));
            if (side) *side = child_bit(depth);
            if (n.is_scalar_leaf(c)) return {n.scalar[c], false, {}, 0};
            if (depth == cap_parents_at) return {T{}, true, this->cap(index, n, c), octant_of(p, 1u)};
            index = child_index(depth, index, n, c);
            ++depth;
        }
    }
    LeafRef<T> locate(Coord p) const { return locate_from(p, 0, 0); }
    T point_locate(Coord p) const { return locate_from(p, 0, 0).voxel(); }

    /// Value at `dest`, given the trace of node indices from the root down to the node that holds
    /// `start`: parent_trace[d] is the node at depth d containing `start`, for d = 0 .. depth
    /// (depth <= dmax-2; a cap's corners outside it start from its parent).
    /// Climbs to the deepest traced node whose cube also contains `dest`, then locates down
    /// (Knoll 2006 App. B.2; the paper's trailing root check is folded into the loop at d = 0).
    OCTISO_ALWAYS_INLINE T neighbour_find(Coord start, Coord dest, int depth, const uint32_t* parent_trace) const {
        return neighbour_locate(start, dest, depth, parent_trace).voxel();
    }
    /// The same, returning where the descent ended (the traversal then reads a whole forward
    /// neighbour block directly).
    /// `side` as for locate_from.
    OCTISO_ALWAYS_INLINE LeafRef<T> neighbour_locate(Coord start, Coord dest, int depth, const uint32_t* parent_trace,
                                                     uint32_t* side = nullptr) const {
        const TracedNode from = common_ancestor(start, dest, depth, parent_trace);
        return locate_from(dest, from.depth, from.index, side);
    }

    /// A node on a parent trace: its depth and its index there.
    struct TracedNode {
        int depth;
        uint32_t index;
    };
    /// The deepest node of the trace (as for neighbour_find) whose cube also contains `dest`:
    /// where every search from `start` for `dest` begins (the root when none deeper does).
    OCTISO_ALWAYS_INLINE TracedNode common_ancestor(Coord start, Coord dest, int depth, const uint32_t* parent_trace) const {
        for (int d = depth; d > 0; --d) {
            const int shift = a_.dmax - d;   // cube side of a depth-d node is 2^shift
            if (((start.x ^ dest.x) >> shift) == 0 && ((start.y ^ dest.y) >> shift) == 0 &&
                ((start.z ^ dest.z) >> shift) == 0)
                return {d, parent_trace[d]};
        }
        return {0, 0};
    }

    /// Where a descent towards `dest` ends at depth `target`: the node there whose cube holds
    /// dest, or, where a scalar leaf above that depth covers dest, the leaf's value.
    struct NodeAt {
        bool is_leaf;
        uint32_t index;   ///< !is_leaf: the node at depth `target`
        T value;          ///< is_leaf: the leaf's value
    };
    /// The node at depth `target` (depth <= target <= dmax-2) holding `dest`, found from the trace
    /// as neighbour_locate finds a voxel: the traversal's forward neighbours of a cap parent,
    /// located once for all the caps of that parent that need them.
    OCTISO_ALWAYS_INLINE NodeAt node_at(Coord start, Coord dest, int depth, const uint32_t* parent_trace, int target) const {
        TracedNode at = common_ancestor(start, dest, depth, parent_trace);
        for (; at.depth < target; ++at.depth) {
            const InteriorNode<T>& n = a_.nodes[size_t(at.depth)][at.index];
            const int c = octant_of(dest, child_bit(at.depth));
            if (n.is_scalar_leaf(c)) return {true, 0, n.scalar[c]};
            at.index = child_index(at.depth, at.index, n, c);
        }
        return {false, at.index, T{}};
    }

    /// Level of detail (issue 14): the voxel at `q` where q is a multiple of `unit` (a power of
    /// two), read without descending below the node whose lower corner q is: a stored child of
    /// side <= unit keeps that voxel in its parent's scalar (format 4), a cap yields it from its
    /// record, a scalar leaf holds it outright. So a coarse lattice of spacing `unit` touches
    /// only the levels above it. `start`, `depth`, `parent_trace` as for neighbour_locate.
    OCTISO_ALWAYS_INLINE T lattice_value(Coord start, Coord q, uint32_t unit, int depth, const uint32_t* parent_trace) const {
        const TracedNode from = common_ancestor(start, q, depth, parent_trace);
        int d = from.depth;
        uint32_t index = from.index;
        const int cap_parents_at = a_.dmax - 2;
        for (;;) {
            const InteriorNode<T>& n = a_.nodes[size_t(d)][index];
            const uint32_t half = child_bit(d);
            const int c = octant_of(q, half);
            if (n.is_scalar_leaf(c)) return n.scalar[c];
            if (d == cap_parents_at) return this->cap(index, n, c).voxel(octant_of(q, 1u));
            if (half <= unit) return n.scalar[c];   // q is this child's lower corner
            index = child_index(d, index, n, c);
            ++d;
        }
    }

private:
    OctreeArrays<T> a_;
};

/// dmax for a grid: log2 of the smallest power of two >= the largest extent, at least 2 so that
/// the root is always an interior node and caps sit below it.
inline int dmax_for(Dims dims) {
    const uint32_t n = std::bit_ceil(dims.max_extent());
    const int d = std::countr_zero(n);
    return d < 2 ? 2 : d;
}

}  // namespace octiso
