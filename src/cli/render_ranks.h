// octiso-render's place among MPI ranks (issue 15): what the tool asks of the distribution,
// answered by src/mpi/ in the MPI build under mpirun, and as one rank of one otherwise. Keeping
// this seam in one file leaves render_main.cpp free of #if and the non-MPI tool unchanged.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "octiso/depth_composite.h"
#include "octiso/frame.h"
#include "octiso/look.h"
#include "octiso/tiles.h"
#include "octiso/volume.h"

namespace octiso::cli {

/// How work is split over the ranks of an mpirun: whole frames of a series dealt to whichever
/// rank is free (steps, the default), the tiles of each frame (image, sort-first) or the cells of
/// the volume (data, sort-last: slab bricks composited by depth).
enum class Distribute { steps, image, data };
Distribute parse_distribute(const std::string& text);   ///< throws Error("--distribute", ...)
const char* distribute_name(Distribute d);

/// One rank's part in one image, for the report.
struct FrameRecord {
    long long index = 0, step = 0;
    int rank = 0;
    double seconds = 0, frame_seconds = 0, exchange_seconds = 0, rank_wall_seconds = 0;
    /// Per-frame phases (issue 12: the serial parts visible in --json): thread seconds inside
    /// tiles (RenderStats::busy_seconds), the deferred shading and clip-cap passes, the image
    /// writes, and the step's Renderer set-up (on the first frame of a step only).
    double busy_seconds = 0, shade_seconds = 0, write_seconds = 0, step_setup_seconds = 0;
    uint64_t rays = 0, hits = 0, bytes_sent = 0;
    std::array<uint64_t, 32> hits_by_cell_log2{};   ///< RenderStats::hits_by_cell_log2, summed over samples
    uint64_t file_resident_bytes = 0;   ///< of the rank's mapping of the .oct after its frames (smaps)
    int threads = 0;
    LookStats look;       ///< secondary rays of the look pass (issue 17 item 7)
    bool wrote = false;   ///< this rank wrote the image (its own step, or rank 0 of a split frame)
};

struct RankExchange {
    uint64_t bytes_sent = 0;
    double seconds = 0;
};

class Ranks {
public:
    /// One rank of one (no mpirun, or the non-MPI build).
    Ranks();
    ~Ranks();
    /// Starts MPI if this process was launched by mpirun (MPI build only).
    static Ranks for_process(int& argc, char**& argv);
    Ranks(Ranks&&) noexcept;

    int rank = 0, size = 1;
    bool mpi_built() const;   ///< whether this build has the MPI modes

    /// Collective, once: every rank says whether it is ready (status 0). Returns 0 when all are,
    /// else the worst status; the caller then returns it (the lowest failing rank printed why).
    int agree_ready(int status);
    /// After a failure on this rank: whether it reports it (the caller rethrows for run_main to
    /// print) or exits quietly with `status`, because a lower rank reports the same. Before
    /// agreement this is this rank's side of agree_ready(); after it, a failure cannot wait for
    /// the others: the rank prints `message` and aborts every rank (never returns).
    bool should_report(int status, const std::string& message);

    /// Collective: the union of every rank's range (none where no rank has one).
    std::optional<std::array<double, 2>> unite_range(const std::optional<std::array<double, 2>>& mine);
    std::vector<int> tiles_of(int tile_count) const;   ///< sort-first: tile i with i % size == rank
    RankExchange gather_tiles(const TileGrid& grid, bool colour, bool depth, bool normal, Frame& frame);
    RankExchange composite(const CompositeLayout& layout, Frame& frame);
    /// Sort-last, collective: this rank's ghost plane (mpi/ghost_exchange.h) for `bricks`, from
    /// the rank that owns it; `decode(x)` gives this rank's own first plane to the rank before.
    std::shared_ptr<const std::vector<double>> ghost_plane(const std::vector<CellBox>& bricks,
                                                           const std::function<std::vector<double>(uint32_t)>& decode,
                                                           uint64_t& bytes_sent);
    /// Runs render(n) for the jobs 0 .. count-1 dealt to this rank.
    void deal(size_t count, const std::function<void(size_t)>& render);
    /// Rank 0: every rank's records (this rank's first); others: their own. Collective.
    std::vector<FrameRecord> gather_records(std::vector<FrameRecord> mine, double wall_seconds, uint64_t file_resident_bytes);

private:
    struct Mpi;
    std::unique_ptr<Mpi> mpi_;
    bool agreed_ = false;
};

}  // namespace octiso::cli
