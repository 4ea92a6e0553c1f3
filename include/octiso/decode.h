// Decompression of an Octree<T> back to the dense x-fastest array it was built from, whole or a
// range of z layers at a time (octiso-info --extract-raw, tests). Uniform blocks are filled run
// by run, caps voxel by voxel, subtrees in parallel; padding beyond the data is never written.
#pragma once

#include "octiso/octree.h"

namespace octiso {

/// Writes every voxel of the grid into out[x + NX*(y + NY*z)], NX*NY*NZ values in all; `out`
/// must hold that many. Runs on the TBB threads of the caller's arena. The tree must be valid
/// (built in memory or validated by OctFile::step).
template <typename T> void decode_to_dense(const Octree<T>& octree, T* out);

/// Layers z0 .. z1-1 only (z0 <= z1 <= NZ): out[x + NX*(y + NY*(z - z0))], NX*NY*(z1-z0) values.
/// Subtrees outside the layers are not entered, so decoding a volume slab by slab costs about
/// what decoding it whole does (octiso-info --extract-raw of a step larger than memory).
template <typename T> void decode_layers(const Octree<T>& octree, uint32_t z0, uint32_t z1, T* out);

}  // namespace octiso
