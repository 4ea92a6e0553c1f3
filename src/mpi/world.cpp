// World (world.h).
#include "mpi/world.h"

#include <mpi.h>

#include <cstdlib>

#include "octiso/error.h"

namespace octiso::mpi {

bool launched_by_mpirun() {
    for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
        if (std::getenv(v)) return true;
    return false;
}

World::World(int& argc, char**& argv) {
    if (!launched_by_mpirun()) return;
    int provided = 0;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided);
    active_ = true;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    // Errors are reported by return code and turned into one line and an abort (octiso-render).
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    if (provided < MPI_THREAD_SERIALIZED) {
        MPI_Finalize();
        active_ = false;
        throw Error("mpi", "this MPI library does not provide MPI_THREAD_SERIALIZED", ErrorKind::Other);
    }
}

World::~World() {
    if (active_) MPI_Finalize();
}

int World::agree(int status, int& worst) {
    agreed_ = true;
    if (!active_) {
        worst = status;
        return status ? 0 : size_;
    }
    int mine[2] = {status, status ? rank_ : size_}, all[2] = {0, 0};
    int lowest = size_;
    MPI_Allreduce(&mine[0], &all[0], 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    MPI_Allreduce(&mine[1], &all[1], 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    worst = all[0];
    lowest = all[1];
    return lowest;
}

void World::abort(int status) const {
    if (active_) MPI_Abort(MPI_COMM_WORLD, status);
    std::exit(status);
}

void World::barrier() const {
    if (active_) MPI_Barrier(MPI_COMM_WORLD);
}

std::string World::gather_equal(const std::string& bytes) const {
    if (!active_) return bytes;
    std::string all(rank_ == 0 ? bytes.size() * size_t(size_) : 0, '\0');
    if (MPI_Gather(bytes.data(), int(bytes.size()), MPI_BYTE, all.data(), int(bytes.size()), MPI_BYTE, 0, MPI_COMM_WORLD) !=
        MPI_SUCCESS)
        throw Error("mpi", "gathering the ranks' reports failed", ErrorKind::Other);
    return all;
}

std::array<double, 2> World::unite(double lo, double hi) const {
    std::array<double, 2> out{lo, hi};
    if (active_ && (MPI_Allreduce(&lo, &out[0], 1, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD) != MPI_SUCCESS ||
                    MPI_Allreduce(&hi, &out[1], 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD) != MPI_SUCCESS))
        throw Error("mpi", "uniting the steps' value ranges failed", ErrorKind::Other);
    return out;
}

std::string World::broadcast(std::string bytes) const {
    if (active_ && MPI_Bcast(bytes.data(), int(bytes.size()), MPI_BYTE, 0, MPI_COMM_WORLD) != MPI_SUCCESS)
        throw Error("mpi", "broadcasting from rank 0 failed", ErrorKind::Other);
    return bytes;
}

}  // namespace octiso::mpi
