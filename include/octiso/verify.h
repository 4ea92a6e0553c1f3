// verify_octree(): the derived metadata of a .oct file recomputed from its leaves (issue 18: a
// file with valid checksums whose min/max tree lied rendered blank while --extract-raw returned
// the right data). Checksums prove the bytes are the ones written, indices that they are safe
// to follow; this proves that what they say about the data is true.
#pragma once

#include <cstdint>

#include "octiso/oct_file.h"

namespace octiso {

struct VerifyStats {
    uint64_t nodes = 0;    ///< interior nodes checked, all steps
    uint64_t ranges = 0;   ///< child min/max ranges checked
};

/// For every step: decodes the leaves, then checks at every interior node and child octant that
/// [min, max] contains the value of every finite voxel of every data cell whose lower corner lies
/// in the child (cells with a NaN or infinite corner are skipped, CONVENTIONS 2b; with an
/// iso-range only values inside it count), and that an interior child's scalar lies within its
/// range. Throws Error(file, "step K, depth D, node I, child C: ...") at the first lie; the file
/// must already have passed OctFile's validation. Needs one step's dense array in memory.
VerifyStats verify_octree(const OctFile& file);

}  // namespace octiso
