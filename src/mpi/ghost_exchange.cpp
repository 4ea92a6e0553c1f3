// exchange_ghost_planes (ghost_exchange.h).
#include "mpi/ghost_exchange.h"

#include <mpi.h>

#include <climits>

#include "octiso/error.h"

namespace octiso::mpi {
namespace {
constexpr int kGhostTag = 15003;

/// The rank that owns plane x = bricks[r].hi[0] (the first later non-empty brick starting there),
/// or -1 when brick r needs no ghost.
int ghost_source(const std::vector<CellBox>& bricks, size_t r) {
    if (bricks[r].empty()) return -1;
    for (size_t q = r + 1; q < bricks.size(); ++q)
        if (!bricks[q].empty()) return bricks[q].lo[0] == bricks[r].hi[0] ? int(q) : -1;
    return -1;   // the last non-empty brick ends at the data's last cell
}

}  // namespace

std::shared_ptr<const std::vector<double>> exchange_ghost_planes(const World& world, const std::vector<CellBox>& bricks,
                                                                 const std::function<std::vector<double>(uint32_t)>& decode,
                                                                 uint64_t& bytes_sent) {
    bytes_sent = 0;
    const size_t me = size_t(world.rank());
    std::vector<size_t> needers;   // ranks whose ghost is my first plane
    for (size_t r = 0; r < bricks.size(); ++r)
        if (ghost_source(bricks, r) == int(me)) needers.push_back(r);
    std::vector<double> mine;
    if (!needers.empty()) mine = decode(bricks[me].lo[0]);
    if (mine.size() > size_t(INT_MAX)) throw Error("--distribute", "the ghost plane is too large for one MPI message", ErrorKind::Other);
    std::vector<MPI_Request> sends(needers.size());
    for (size_t i = 0; i < needers.size(); ++i) {
        MPI_Isend(mine.data(), int(mine.size()), MPI_DOUBLE, int(needers[i]), kGhostTag, MPI_COMM_WORLD, &sends[i]);
        bytes_sent += mine.size() * sizeof(double);
    }
    std::shared_ptr<std::vector<double>> ghost;
    const int source = ghost_source(bricks, me);
    int received = MPI_SUCCESS;
    if (source >= 0) {
        ghost = std::make_shared<std::vector<double>>(size_t(bricks[me].hi[1] + 1) * size_t(bricks[me].hi[2] + 1));
        received = MPI_Recv(ghost->data(), int(ghost->size()), MPI_DOUBLE, source, kGhostTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    }
    const int sent = sends.empty() ? MPI_SUCCESS : MPI_Waitall(int(sends.size()), sends.data(), MPI_STATUSES_IGNORE);
    if (received != MPI_SUCCESS || sent != MPI_SUCCESS)
        throw Error("mpi", "exchanging the bricks' ghost planes failed", ErrorKind::Other);
    return ghost;
}

}  // namespace octiso::mpi
