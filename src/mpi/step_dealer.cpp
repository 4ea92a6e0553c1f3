// StepDealer (step_dealer.h).
#include "mpi/step_dealer.h"

#include <mpi.h>

#include <chrono>

#include "octiso/error.h"

namespace octiso::mpi {
namespace {
constexpr int kAskTag = 15001, kJobTag = 15002;
}

StepDealer::StepDealer(const World& world, long long job_count) : world_(world), count_(job_count) {
    if (world_.active() && world_.rank() == 0 && world_.size() > 1) service_ = std::thread([this] { serve(); });
}

StepDealer::~StepDealer() { finish(); }

void StepDealer::finish() {
    if (service_.joinable()) service_.join();
}

long long StepDealer::next() {
    if (!world_.active() || world_.rank() == 0) {
        const long long job = next_.fetch_add(1);
        return job < count_ ? job : -1;
    }
    const int ask = 0;
    long long job = -1;
    if (MPI_Send(&ask, 1, MPI_INT, 0, kAskTag, MPI_COMM_WORLD) != MPI_SUCCESS ||
        MPI_Recv(&job, 1, MPI_LONG_LONG, 0, kJobTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE) != MPI_SUCCESS)
        throw Error("mpi", "asking rank 0 for the next step failed", ErrorKind::Other);
    return job;
}

void StepDealer::serve() {
    int still_working = world_.size() - 1;   // ranks not yet told "no more"
    while (still_working > 0) {
        int waiting = 0;
        MPI_Status status;
        MPI_Iprobe(MPI_ANY_SOURCE, kAskTag, MPI_COMM_WORLD, &waiting, &status);
        if (!waiting) {
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
            continue;
        }
        int ask = 0;
        MPI_Recv(&ask, 1, MPI_INT, status.MPI_SOURCE, kAskTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        long long job = next_.fetch_add(1);
        if (job >= count_) job = -1, --still_working;
        MPI_Send(&job, 1, MPI_LONG_LONG, status.MPI_SOURCE, kJobTag, MPI_COMM_WORLD);
    }
}

}  // namespace octiso::mpi
