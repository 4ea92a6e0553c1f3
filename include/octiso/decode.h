// Decompression of an Octree<T> back to the dense x-fastest array it was built from (octiso-info
// --extract-raw, tests). Uniform blocks are filled run by run, caps voxel by voxel, subtrees in
// parallel; padding beyond the data is never written.
#pragma once

#include "octiso/octree.h"

namespace octiso {

/// Writes every voxel of the grid into out[x + NX*(y + NY*z)], NX*NY*NZ values in all; `out`
/// must hold that many. Runs on the TBB threads of the caller's arena. The tree must be valid
/// (built in memory or validated by OctFile::step).
template <typename T> void decode_to_dense(const Octree<T>& octree, T* out);

}  // namespace octiso
