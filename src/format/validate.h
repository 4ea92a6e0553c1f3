// Per-step validation of a .oct octree, shared by the loader (mapped files) and the writer (trees
// about to be written): section checksums, then every child index of every interior node. After
// it passes, the renderer trusts all indices of the step (STYLE: validate once, completely).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "format/oct_layout.h"
#include "octiso/oct_file.h"
#include "octiso/octree.h"

namespace octiso::format {

/// Recomputes the XXH3-64 of section `s` (whose bounds the loader has checked) over the mapped
/// file at `base`; throws Error(subject, ...) on a mismatch, naming the step and depth.
void verify_section_checksum(const std::string& subject, const std::byte* base, const SectionEntry& s);

/// Checks the index structure of one octree, cheap to costly, and returns its sizes:
///   1. counts: exactly one root node; counts below fit 32-bit node indices;
///   2. every interior node at depth d: its own fields, and its first child (group base plus
///      child_offset) exactly where the previous node's children end, childless nodes included
///      (so children never overlap and never leave a gap, and a group's first node has offset
///      0), with first child + span <= count(d+1);
///   3. the children of all depth-d nodes cover depth d+1 exactly (caps at d = dmax-2).
/// All arithmetic is 64-bit. Throws Error(subject, ...) naming step, depth, node and the
/// expected vs found numbers. Thread-safe (reads only).
template <typename T> StepSizes validate_tree(const std::string& subject, const OctreeArrays<T>& a, uint32_t step);

/// Step 1 of validate_tree alone, O(dmax): the counts, and the cap level's zero slack. Returns the
/// sizes that follow from the counts (no scalar leaves, no cap count: those need every node).
template <typename T> StepSizes validate_counts(const std::string& subject, const OctreeArrays<T>& a, uint32_t step);

/// What is wrong with one interior node on its own (its fields, and its children, from its group's
/// `group_base` on, inside the `next_count` nodes, or bytes of caps when `caps_below`, of the
/// level below): the local checks of validate_tree step 2, which are all that memory safety needs
/// (a renderer reads nothing but what an in-range index or cap offset points at). No
/// allocation: safe in a fault handler.
enum class NodeDefect : uint8_t { none, cap_bits, high_fields, tail, bounds, lattice_sample, children_past_end };
template <typename T>
NodeDefect node_defect(const InteriorNode<T>& n, uint64_t group_base, bool caps_below, uint64_t next_count) noexcept;
/// "step S, depth D (interior nodes)" or "(caps)": how every message names a section.
std::string where(uint32_t step, int depth, int dmax);
/// The same checks in words, as validate_tree reports them (empty when the node is fine).
template <typename T>
std::string node_problem(const InteriorNode<T>& n, uint64_t group_base, bool caps_below, uint64_t next_count);

}  // namespace octiso::format
