// Per-step validation of .oct octrees (see validate.h): section checksums, then the child indices
// of every interior node, in parallel over chunks of nodes with a serial stitch of the chunk
// boundaries. The only file that includes xxhash.h.
#include "format/validate.h"

#include <algorithm>
#include <new>
#include <bit>
#include <cmath>
#include <cstdio>
#include <optional>
#include <vector>

#include <tbb/parallel_for.h>
// XXH3 compiled in from the header (its documented XXH_INLINE_ALL mode), not linked from
// libxxhash: the many-core probe then needs no library beyond TBB and Embree (issue 12); the
// hash values are the same algorithm's.
#define XXH_INLINE_ALL
#include <xxhash.h>

#include "octiso/error.h"

namespace octiso::format {

uint64_t checksum(const void* data, size_t bytes) { return XXH3_64bits(data, bytes); }

ChecksumStream::ChecksumStream() : state_(XXH3_createState()) {
    if (!state_) throw std::bad_alloc();
    reset();
}
ChecksumStream::~ChecksumStream() { XXH3_freeState(static_cast<XXH3_state_t*>(state_)); }
void ChecksumStream::reset() { XXH3_64bits_reset(static_cast<XXH3_state_t*>(state_)); }
void ChecksumStream::update(const void* data, size_t bytes) {
    if (bytes != 0) XXH3_64bits_update(static_cast<XXH3_state_t*>(state_), data, bytes);
}
uint64_t ChecksumStream::digest() const { return XXH3_64bits_digest(static_cast<const XXH3_state_t*>(state_)); }

namespace {

std::string hex(uint64_t v) {
    char buf[19];
    std::snprintf(buf, sizeof buf, "0x%016llx", static_cast<unsigned long long>(v));
    return buf;
}


/// What one chunk of nodes at a depth found on its own; the stitch checks the boundaries.
struct ChunkResult {
    uint64_t first_start = 0;               ///< the first child of the chunk's first node
    uint64_t children = 0;                  ///< what the chunk's children take below: nodes, or cap bytes
    uint64_t stored = 0;                    ///< sum of popcount(child_mask) over the chunk
    uint64_t leaves = 0;                    ///< sum of 8 - popcount
    std::optional<uint64_t> bad_node;       ///< first node failing a check
    std::string problem;
};

/// A multiple of kNodeGroup, so that no group straddles two chunks.
constexpr uint64_t kChunk = 1u << 15;

}  // namespace

std::string where(uint32_t step, int depth, int dmax) {
    return "step " + std::to_string(step) + ", depth " + std::to_string(depth) +
           (depth == dmax - 1 ? " (caps)" : " (interior nodes)");
}

// A width of kWholeCapBits or at most kMaxDeltaBits; 1-byte scalars (format 6, CapAnchor): a
// width of 1 .. 8 below the anchor bit, either anchor (the slot keeps the first of the b bytes),
// or 0 in a cap parent with no stored child (all its children scalar leaves, never packed).
template <typename T> bool cap_bits_valid(const InteriorNode<T>& n) noexcept {
    const unsigned width = n.cap_width();
    if constexpr (sizeof(T) == 1) return width <= 8 && (width >= 1 || n.child_mask == 0);
    else return width == kWholeCapBits<T> || width <= kMaxDeltaBits<T>;
}

// The node's own fields (format 6, octree.h): the cap width and anchor where caps lie below and zero width
// elsewhere, a zero tail, ordered finite bounds (wider scalars), lattice samples inside their ranges; then its
// children inside the level below. Allocation-free: the touch validator runs it in a fault
// handler (touch_validation.h); node_problem() words the same checks for a message.
template <typename T>
NodeDefect node_defect(const InteriorNode<T>& n, uint64_t group_base, bool caps_below, uint64_t next_count) noexcept {
    if (caps_below) {
        if (!cap_bits_valid(n)) return NodeDefect::cap_bits;
    } else if (n.cap_bits != 0) {
        return NodeDefect::high_fields;
    }
    if constexpr (sizeof(T) == 8)
        if (n.tail.zero != 0) return NodeDefect::tail;
    if constexpr (sizeof(T) > 1) {
        const double lo = double(n.bounds.lo), hi = double(n.bounds.hi);
        if (!(std::isfinite(lo) && std::isfinite(hi) && lo <= hi)) return NodeDefect::bounds;
    }
    // A stored interior child's scalar is the voxel at its lower corner (format 4 on), a corner
    // of one of its data cells, so it lies in the child's range whenever that range is not empty.
    // Level of detail traces it; outside the range it would draw a surface the culling denies.
    if (!caps_below)
        for (int c = 0; c < 8; ++c) {
            if (!((n.child_mask >> c) & 1u) || n.bounds.empty(c)) continue;
            const double v = double(n.scalar[c]);
            if (!(n.bounds.lower(c) <= v && v <= n.bounds.upper(c))) return NodeDefect::lattice_sample;
        }
    // Compared without wrapping: the base comes from the file, the offset is 16 bits and the span
    // at most 8 x 64.
    const uint64_t span = n.children_span(caps_below);
    if (group_base > next_count || n.child_offset > next_count - group_base) return NodeDefect::children_past_end;
    const uint64_t start = group_base + n.child_offset;
    if (span > next_count - start) return NodeDefect::children_past_end;
    return NodeDefect::none;
}

template <typename T>
std::string node_problem(const InteriorNode<T>& n, uint64_t group_base, bool caps_below, uint64_t next_count) {
    switch (node_defect(n, group_base, caps_below, next_count)) {
    case NodeDefect::none: return {};
    case NodeDefect::cap_bits:
        if constexpr (sizeof(T) == 1)
            return "cap_bits out of range (expected a width of 1 .. 8 in bits 0-6 and the anchor in bit 7, or 0 without "
                   "stored children; found " + std::to_string(n.cap_bits) + " with child_mask " + std::to_string(n.child_mask) + ")";
        return "cap_bits out of range (expected 0 .. " + std::to_string(kMaxDeltaBits<T>) + " or " +
               std::to_string(kWholeCapBits<T>) + ", found " + std::to_string(n.cap_bits) + ")";
    case NodeDefect::high_fields:
        return "cap_bits must be zero above the cap parents (found " + std::to_string(n.cap_bits) + ")";
    case NodeDefect::tail:
        if constexpr (sizeof(T) == 8) return "the record's last 4 bytes must be zero (found " + std::to_string(n.tail.zero) + ")";
        return "the record's tail must be zero";
    case NodeDefect::bounds:
        if constexpr (sizeof(T) > 1)
            return "bounds range is not finite and ordered (found lo " + std::to_string(double(n.bounds.lo)) + ", hi " +
                   std::to_string(double(n.bounds.hi)) + ")";
        return "bounds range is not finite and ordered";
    case NodeDefect::lattice_sample:
        for (int c = 0; c < 8; ++c) {
            if (!((n.child_mask >> c) & 1u) || n.bounds.empty(c)) continue;
            const double v = double(n.scalar[c]);
            if (!(n.bounds.lower(c) <= v && v <= n.bounds.upper(c)))
                return "child " + std::to_string(c) + ": its lattice sample (scalar) lies outside its range (expected " +
                       std::to_string(n.bounds.lower(c)) + " .. " + std::to_string(n.bounds.upper(c)) + ", found " +
                       std::to_string(v) + ")";
        }
        return "a lattice sample lies outside its range";
    case NodeDefect::children_past_end: {
        const uint64_t span = n.children_span(caps_below);
        const char* what = caps_below ? "group base + child_offset + popcount(child_mask) x cap_bits"
                                      : "group base + child_offset + popcount(child_mask)";
        // The terms, not their sum: a hostile base near 2^64 would wrap it.
        return std::string(what) + " runs past the " + std::to_string(next_count) + " " +
               (caps_below ? "bytes of caps" : "nodes") + " below (expected <= " + std::to_string(next_count) +
               ", found " + std::to_string(group_base) + " + " + std::to_string(n.child_offset) + " + " +
               std::to_string(span) + ")";
    }
    }
    return {};
}

namespace {

template <typename T>
ChunkResult check_chunk(const InteriorNode<T>* nodes, const uint64_t* bases, uint64_t begin, uint64_t end,
                        uint64_t next_count, bool caps_below) {
    ChunkResult r;
    uint64_t expected_start = 0;   // where the next node's children must start (after the first)
    for (uint64_t i = begin; i < end; ++i) {
        const InteriorNode<T>& n = nodes[i];
        const uint64_t base = bases[i >> kNodeGroupShift];
        const uint64_t pc = uint64_t(std::popcount(unsigned(n.child_mask)));
        const uint64_t span = n.children_span(caps_below);   // bytes of caps, or nodes
        auto fail = [&](std::string problem) {
            r.bad_node = i;
            r.problem = std::move(problem);
        };
        if (node_defect(n, base, caps_below, next_count) != NodeDefect::none) {
            fail(node_problem(n, base, caps_below, next_count));
            return r;
        }
        if ((i & (kNodeGroup - 1)) == 0 && n.child_offset != 0) {
            fail("the first node of a group must have child_offset 0 (found " + std::to_string(n.child_offset) + ")");
            return r;
        }
        const uint64_t start = base + n.child_offset;   // <= next_count: node_defect
        if (i == begin) {
            r.first_start = start;
        } else if (start != expected_start) {
            fail(std::string(start < expected_start ? "children overlap those of an earlier node"
                                                    : "children leave a gap after those of an earlier node") +
                 " (expected first child " + std::to_string(expected_start) + ", found " + std::to_string(start) + ")");
            return r;
        }
        expected_start = start + span;
        r.children += span;
        r.stored += pc;
        r.leaves += 8 - pc;
    }
    return r;
}

}  // namespace

void verify_section_checksum(const std::string& subject, const std::byte* base, const SectionEntry& s) {
    const uint64_t found = checksum(base + s.offset, size_t(s.bytes));
    if (found != s.checksum)
        throw Error(subject, "checksum mismatch in step " + std::to_string(s.step) + ", depth " +
                                 std::to_string(s.depth) + " (" + std::to_string(s.bytes) + " bytes at offset " +
                                 std::to_string(s.offset) + "; expected XXH3 " + hex(s.checksum) + ", found " +
                                 hex(found) + ")");
}

template <typename T> StepSizes validate_counts(const std::string& subject, const OctreeArrays<T>& a, uint32_t step) {
    const int dmax = a.dmax;
    if (dmax < 2 || dmax >= kMaxDepth)
        throw Error(subject, "step " + std::to_string(step) + ": dmax out of range (expected 2 .. " +
                                 std::to_string(kMaxDepth - 1) + ", found " + std::to_string(dmax) + ")");
    // 1. Counts: one root, and every depth addressable with 32-bit indices.
    if (a.node_count[0] != 1)
        throw Error(subject, where(step, 0, dmax) + ": the root level must hold exactly one node (expected 1, found " +
                                 std::to_string(a.node_count[0]) + ")");
    // Node indices are 32-bit (Octree::child_index, the traversal's parent traces), so no depth
    // may hold more than 2^32; the cap level holds at most 2^48 bytes.
    constexpr uint64_t kMaxPerDepth = uint64_t(1) << 32;
    for (int d = 1; d + 1 < dmax; ++d) {
        const uint64_t n = a.node_count[size_t(d)];
        if (n > kMaxPerDepth)
            throw Error(subject, where(step, d, dmax) + ": too many records for 32-bit child indices (expected <= " +
                                     std::to_string(kMaxPerDepth) + ", found " + std::to_string(n) + ")");
    }
    if (a.cap_bytes > kMaxCapByteOffset)
        throw Error(subject, where(step, dmax - 1, dmax) + ": too many bytes for 48-bit cap offsets (expected <= " +
                                 std::to_string(kMaxCapByteOffset) + ", found " + std::to_string(a.cap_bytes) + ")");
    if (a.caps == nullptr) throw Error(subject, where(step, dmax - 1, dmax) + ": no cap level");
    for (uint64_t i = 0; i < kCapReadSlack; ++i)
        if (a.caps[a.cap_bytes + i] != 0)
            throw Error(subject, where(step, dmax - 1, dmax) + ": the " + std::to_string(kCapReadSlack) +
                                     " bytes after the last cap are not zero");
    StepSizes sizes;
    sizes.nodes_per_depth.assign(size_t(dmax), 0);
    sizes.scalar_leaves_per_depth.assign(size_t(dmax), 0);
    for (int d = 0; d <= dmax - 2; ++d) {
        const uint64_t count = a.node_count[size_t(d)];
        if (count != 0 && (a.nodes[size_t(d)] == nullptr || a.group_base[size_t(d)] == nullptr))
            throw Error(subject, where(step, d, dmax) + ": " + std::to_string(count) + " nodes but no data");
        sizes.nodes_per_depth[size_t(d)] = count;
        sizes.interior_bytes += interior_level_bytes<T>(count);
        sizes.minmax_bytes += count * sizeof(ChildBounds<T>);
    }
    sizes.cap_bytes = a.cap_bytes;
    return sizes;
}

template <typename T> StepSizes validate_tree(const std::string& subject, const OctreeArrays<T>& a, uint32_t step) {
    const int dmax = a.dmax;
    StepSizes sizes = validate_counts(subject, a, step);

    for (int d = 0; d <= dmax - 2; ++d) {
        const uint64_t count = a.node_count[size_t(d)];
        const bool next_is_caps = d + 1 == dmax - 1;
        const uint64_t next_count = next_is_caps ? a.cap_bytes : a.node_count[size_t(d + 1)];
        const InteriorNode<T>* nodes = a.nodes[size_t(d)];

        // 2. Local checks per chunk in parallel, each chunk stopping at its first bad node.
        const uint64_t n_chunks = (count + kChunk - 1) / kChunk;
        std::vector<ChunkResult> chunks(n_chunks);
        const char* next_name = next_is_caps ? "bytes of caps" : "nodes";
        tbb::parallel_for(uint64_t(0), n_chunks, [&](uint64_t c) {
            const uint64_t begin = c * kChunk;
            const uint64_t end = std::min(count, begin + kChunk);
            chunks[c] = check_chunk(nodes, a.group_base[size_t(d)], begin, end, next_count, next_is_caps);
        });

        // 3. Stitch: each chunk's first children start where the previous chunks' children end;
        // the earliest failing node (local or boundary) is the one reported.
        uint64_t covered = 0, leaves = 0, stored = 0;
        for (uint64_t c = 0; c < n_chunks; ++c) {
            const ChunkResult& r = chunks[c];
            const uint64_t first = c * kChunk;
            if (r.first_start != covered && (!r.bad_node || first < *r.bad_node))
                throw Error(subject, where(step, d, dmax) + ", node " + std::to_string(first) + ": " +
                                         (r.first_start < covered ? "children overlap those of an earlier node"
                                                                  : "children leave a gap after those of an earlier node") +
                                         " (expected first child " + std::to_string(covered) + ", found " +
                                         std::to_string(r.first_start) + ")");
            if (r.bad_node) throw Error(subject, where(step, d, dmax) + ", node " + std::to_string(*r.bad_node) + ": " + r.problem);
            covered += r.children;
            leaves += r.leaves;
            stored += r.stored;
        }
        if (covered != next_count)
            throw Error(subject, where(step, d + 1, dmax) + ": the parents' child masks do not cover the level exactly (expected " +
                                     std::to_string(covered) + " " + next_name + ", found " + std::to_string(next_count) +
                                     ")");
        sizes.scalar_leaves_per_depth[size_t(d)] = leaves;
        if (next_is_caps) sizes.nodes_per_depth[size_t(dmax - 1)] = stored;
    }
    return sizes;
}

#define OCTISO_INSTANTIATE(T)                                                                                 \
    template StepSizes validate_tree<T>(const std::string&, const OctreeArrays<T>&, uint32_t);                \
    template StepSizes validate_counts<T>(const std::string&, const OctreeArrays<T>&, uint32_t);              \
    template NodeDefect node_defect<T>(const InteriorNode<T>&, uint64_t, bool, uint64_t) noexcept;           \
    template std::string node_problem<T>(const InteriorNode<T>&, uint64_t, bool, uint64_t);
OCTISO_FOR_EACH_SCALAR_TYPE(OCTISO_INSTANTIATE)
#undef OCTISO_INSTANTIATE

}  // namespace octiso::format
