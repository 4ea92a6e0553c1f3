// Cutting one volume into bricks for sort-last rendering (octiso-render --distribute data, issue
// 15): rank r of R renders only the cells of brick r (RenderOptions::owned_cells) and the ranks
// composite their frames by depth (octiso/depth_composite.h).
//
// The bricks are slabs along x. Why x: the converter appends each depth's nodes in depth-first
// order of their path, octant c = x<<2 | y<<1 | z (build.cpp), so x is the most significant bit of
// each octant. The two halves of the root are therefore one contiguous run of every section of the
// file each; a slab of 1/4 is 4 runs per level (one per depth-1 octant of its x half), 1/2^L is
// 4^(L-1) runs. A rank maps the pages of its runs, plus what the kernel maps around each run's
// ends (whole large folios of the page cache, about 1 MiB measured here), so the overhead is a
// constant per run and level: 1.01-1.09x the slab's own bytes at 2 ranks on a 135 MiB file,
// 1.3-2.5x at 4 (octiso-bench mpi, BENCHMARKS.md). Faces are rounded to a multiple of a power of
// two (the largest with at least 8 of them per slab), which keeps the slabs within 1/8 of equal.
#pragma once

#include <vector>

#include "octiso/render.h"
#include "octiso/volume.h"

namespace octiso {

/// `count` >= 1 half-open cell boxes that partition the cells of a dims volume, in order of x;
/// some are empty when there are fewer cells than bricks.
std::vector<CellBox> slab_bricks(Dims dims, int count);

}  // namespace octiso
