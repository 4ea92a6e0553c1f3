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
///   1. counts: exactly one root node; counts below fit the 32-bit child_start field;
///   2. every interior node at depth d: reserved bytes zero, and its children, in node order,
///      start exactly where those of the previous node with children end (so they never
///      overlap and never leave a gap), with child_start + popcount(child_mask) <= count(d+1);
///   3. the children of all depth-d nodes cover depth d+1 exactly (caps at d = dmax-2).
/// All arithmetic is 64-bit. Throws Error(subject, ...) naming step, depth, node and the
/// expected vs found numbers. Thread-safe (reads only).
template <typename T> StepSizes validate_tree(const std::string& subject, const OctreeArrays<T>& a, uint32_t step);

}  // namespace octiso::format
