// Dynamic hand-out of the jobs of a series across ranks (octiso-render --distribute steps, the
// default under mpirun): each rank asks rank 0 for the next job when it is free, so a slow step
// holds up only its own rank (issue 15). Rank 0 renders too: its own jobs come from the same
// counter, and a service thread answers the other ranks.
//
// Why a service thread that polls (MPI_Iprobe, then 1 ms asleep) instead of a blocking receive:
// Open MPI waits by spinning, and on a machine with one core per rank a spinning thread would take
// rank 0's core from its renderer. A request waits at most ~1 ms, against frames of tens of
// milliseconds to seconds (at 200 us the thread woke 5000 times a second on rank 0's core).
#pragma once

#include <atomic>
#include <thread>

#include "mpi/world.h"

namespace octiso::mpi {

class StepDealer {
public:
    /// Collective: all ranks construct it with the same `job_count`.
    StepDealer(const World& world, long long job_count);
    ~StepDealer();   ///< rank 0: waits until every other rank has been told there is no more
    StepDealer(const StepDealer&) = delete;
    StepDealer& operator=(const StepDealer&) = delete;

    /// The next job for this rank, or -1 when all are handed out.
    long long next();
    /// Rank 0: blocks until every other rank has been told "no more" (also done by the destructor).
    void finish();

private:
    void serve();

    const World& world_;
    const long long count_;
    std::atomic<long long> next_{0};   ///< rank 0: the next job not yet handed out
    std::thread service_;
};

}  // namespace octiso::mpi
