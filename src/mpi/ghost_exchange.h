// The ghost face of sort-last bricks (issue 15): the last cells of a slab need the voxels of the
// plane x = hi, which belong to the next slab. Read from the file they would cost the whole next
// slab's pages (a plane of constant x is spread over every page of a Morton-ordered level), so
// the rank owning that plane decodes it from its own pages and sends it (RenderOptions::ghost_plane).
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "mpi/world.h"
#include "octiso/volume.h"

namespace octiso::mpi {

/// Collective: rank r's ghost plane (x = bricks[r].hi[0]), or null when its brick is empty or
/// ends at the data's last cell. `decode(x)` gives this rank's plane x = bricks[rank].lo[0] for
/// the ranks before it. Returns also the bytes this rank sent in `bytes_sent`.
std::shared_ptr<const std::vector<double>> exchange_ghost_planes(const World& world, const std::vector<CellBox>& bricks,
                                                                 const std::function<std::vector<double>(uint32_t)>& decode,
                                                                 uint64_t& bytes_sent);

}  // namespace octiso::mpi
