// Moving partial frames between ranks (issue 15) for one frame rendered by all of them:
// sort-first (--distribute image: each rank traces an interleaved share of the tiles, gathered to
// rank 0) and sort-last (--distribute data: each rank traces its brick's cells into a full frame;
// the frames are reduced by depth, octiso/depth_composite.h, and the image assembled on rank 0).
//
// Compositing uses MPI's own collectives with a user-defined operation, not IceT: the operation
// must carry an exact tie-break (the brick ordinal) and float normals besides depth and 8-bit
// colour, which IceT's z-buffer mode (RGBA8 + depth in [0, 1]) does not; and it adds no library
// (IceT ships only inside paraview-dev). MPI_Reduce_scatter_block lets Open MPI pick its own
// reduction schedule (recursive halving, ring) for the rank count, then one gather of the slices.
#pragma once

#include <cstdint>
#include <vector>

#include "mpi/world.h"
#include "octiso/depth_composite.h"
#include "octiso/frame.h"
#include "octiso/tiles.h"

namespace octiso::mpi {

/// What one exchange cost this rank: payload bytes it had to send (the least any schedule sends:
/// its tiles; or, sort-last, (R - 1) / R of its frame in the reduce-scatter plus its slice to rank
/// 0) and the wall time of the exchange.
struct ExchangeCost {
    uint64_t bytes_sent = 0;
    double seconds = 0;
};

/// The tiles rank `rank` of `size` renders in sort-first: tile i where i % size == rank.
std::vector<int> tiles_of_rank(int tile_count, int rank, int size);

/// Sort-first: every rank rendered tiles_of_rank(grid) into `frame` (sized by prepare_frame);
/// afterwards rank 0's frame holds every rank's tiles of the outputs asked for (colour, depth,
/// normal, each only if `frame` holds it and it is asked for). Collective.
ExchangeCost gather_tiles(const World& world, const TileGrid& grid, bool colour, bool depth, bool normal, Frame& frame);

/// Sort-last: every rank rendered its brick into `frame` (depth, and colour / normal as `layout`
/// carries); afterwards rank 0's frame holds the composite (octiso/depth_composite.h), its
/// stats.hits the composite's hits. `ordinal` is this rank's brick order. Collective.
ExchangeCost composite_to_root(const World& world, const CompositeLayout& layout, uint32_t ordinal, Frame& frame);

}  // namespace octiso::mpi
