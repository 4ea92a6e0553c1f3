// The MPI world of one octiso-render process (issue 15): initialised only when the process was
// started by mpirun/mpiexec (their environment variables say so), so the same binary run alone
// never touches MPI and behaves as the non-MPI build. Only src/mpi/ includes <mpi.h>.
//
// Threads: MPI_THREAD_SERIALIZED is asked for, because rank 0 hands out series steps from a
// service thread while its main thread renders (step_dealer.h); TBB's workers never call MPI.
#pragma once

#include <array>
#include <cstdint>
#include <string>

namespace octiso::mpi {

/// Whether mpirun/mpiexec (Open MPI, MPICH/PMI, PMIx) started this process.
bool launched_by_mpirun();

class World {
public:
    /// Calls MPI_Init_thread when launched_by_mpirun(), else stays inactive (rank 0 of 1).
    /// Throws Error(..., Other) when MPI cannot give MPI_THREAD_SERIALIZED.
    World(int& argc, char**& argv);
    ~World();   ///< MPI_Finalize, if initialised
    World(const World&) = delete;
    World& operator=(const World&) = delete;

    bool active() const { return active_; }
    int rank() const { return rank_; }
    int size() const { return size_; }

    /// Collective: every rank states the exit status of its preparation (0: ready). Returns the
    /// lowest rank whose status is non-zero (size() if none) and sets `worst` to the largest
    /// status. Called once, after which failures are fatal for all (abort()).
    int agree(int status, int& worst);
    bool agreed() const { return agreed_; }
    /// MPI_Abort of every rank with `status` (after the caller printed why).
    [[noreturn]] void abort(int status) const;

    // Collectives used by the distribution modes (all ranks call them in the same order).
    void barrier() const;
    /// Gathers `bytes` of equal size from every rank to rank 0 (rank order). Returns them on
    /// rank 0, empty elsewhere.
    std::string gather_equal(const std::string& bytes) const;
    /// {min of lo, max of hi} over the ranks.
    std::array<double, 2> unite(double lo, double hi) const;
    /// Rank 0's `bytes` (of the same size on every rank) on every rank.
    std::string broadcast(std::string bytes) const;

private:
    bool active_ = false, agreed_ = false;
    int rank_ = 0, size_ = 1;
};

}  // namespace octiso::mpi
