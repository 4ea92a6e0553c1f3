// Cutting one volume into bricks for sort-last rendering (octiso-render --distribute data, issue
// 15): rank r of R renders only the cells of brick r (RenderOptions::owned_cells) and the ranks
// composite their frames by depth (octiso/depth_composite.h).
//
// The bricks are slabs along x. Why x: the converter appends each depth's nodes in depth-first
// order of their path, octant c = x<<2 | y<<1 | z (build.cpp), so x is the most significant bit of
// every level's order and the nodes of an x-slab whose faces sit on multiples of the node side
// are one contiguous run of each section of the file: a rank maps the pages of its slab and
// little else (octiso-bench mpi measures it). Faces are rounded to a multiple of a power of two
// (the largest with at least 8 of them per slab), which keeps the slabs within 1/8 of equal.
#pragma once

#include <vector>

#include "octiso/render.h"
#include "octiso/volume.h"

namespace octiso {

/// `count` >= 1 half-open cell boxes that partition the cells of a dims volume, in order of x;
/// some are empty when there are fewer cells than bricks.
std::vector<CellBox> slab_bricks(Dims dims, int count);

}  // namespace octiso
