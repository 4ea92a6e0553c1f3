// Ranks (render_ranks.h): src/mpi/ behind the seam in the MPI build, one rank otherwise.
#include "cli/render_ranks.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <limits>
#include <optional>

#include "octiso/error.h"

#if OCTISO_WITH_MPI
#include "mpi/frame_exchange.h"
#include "mpi/ghost_exchange.h"
#include "mpi/step_dealer.h"
#include "mpi/world.h"
#endif

namespace octiso::cli {

Distribute parse_distribute(const std::string& text) {
    if (text == "steps") return Distribute::steps;
    if (text == "image") return Distribute::image;
    if (text == "data") return Distribute::data;
    throw Error("--distribute", "expected steps, image or data, found '" + text + "'");
}

const char* distribute_name(Distribute d) {
    switch (d) {
        case Distribute::steps: return "steps";
        case Distribute::image: return "image";
        case Distribute::data: return "data";
    }
    return "steps";
}

#if OCTISO_WITH_MPI
struct Ranks::Mpi {
    mpi::World world;
    Mpi(int& argc, char**& argv) : world(argc, argv) {}
};
#else
struct Ranks::Mpi {};
#endif

Ranks::Ranks() = default;
Ranks::~Ranks() = default;
Ranks::Ranks(Ranks&&) noexcept = default;

bool Ranks::mpi_built() const { return OCTISO_WITH_MPI + 0 != 0; }

Ranks Ranks::for_process([[maybe_unused]] int& argc, [[maybe_unused]] char**& argv) {
    Ranks r;
#if OCTISO_WITH_MPI
    if (mpi::launched_by_mpirun()) {
        r.mpi_ = std::make_unique<Mpi>(argc, argv);
        r.rank = r.mpi_->world.rank();
        r.size = r.mpi_->world.size();
    }
#endif
    return r;
}

int Ranks::agree_ready(int status) {
    agreed_ = true;
#if OCTISO_WITH_MPI
    if (mpi_) {
        int worst = 0;
        mpi_->world.agree(status, worst);
        return worst;
    }
#endif
    return status;
}

bool Ranks::should_report([[maybe_unused]] int status, [[maybe_unused]] const std::string& message) {
#if OCTISO_WITH_MPI
    if (mpi_) {
        if (!agreed_) {
            agreed_ = true;
            int worst = 0;
            return mpi_->world.agree(status, worst) == rank;
        }
        std::fprintf(stderr, "octiso-render: %s\n", message.c_str());
        std::fflush(stderr);
        mpi_->world.abort(status);
    }
#endif
    return true;
}

std::optional<std::array<double, 2>> Ranks::unite_range(const std::optional<std::array<double, 2>>& mine) {
#if OCTISO_WITH_MPI
    if (mpi_) {
        const double inf = std::numeric_limits<double>::infinity();
        const std::array<double, 2> united = mpi_->world.unite(mine ? (*mine)[0] : inf, mine ? (*mine)[1] : -inf);
        if (united[0] > united[1]) return std::nullopt;
        return united;
    }
#endif
    return mine;
}

std::vector<int> Ranks::tiles_of(int tile_count) const {
#if OCTISO_WITH_MPI
    return mpi::tiles_of_rank(tile_count, rank, size);   // the split gather_tiles() assumes
#else
    std::vector<int> tiles(size_t(std::max(tile_count, 0)));
    for (int i = 0; i < tile_count; ++i) tiles[size_t(i)] = i;   // one rank renders every tile
    return tiles;
#endif
}

RankExchange Ranks::gather_tiles([[maybe_unused]] const TileGrid& grid, [[maybe_unused]] bool colour,
                                 [[maybe_unused]] bool depth, [[maybe_unused]] bool normal, [[maybe_unused]] Frame& frame) {
#if OCTISO_WITH_MPI
    if (mpi_) {
        const mpi::ExchangeCost c = mpi::gather_tiles(mpi_->world, grid, colour, depth, normal, frame);
        return {c.bytes_sent, c.seconds};
    }
#endif
    return {};
}

RankExchange Ranks::composite(const CompositeLayout& layout, Frame& frame) {
#if OCTISO_WITH_MPI
    if (mpi_) {
        const mpi::ExchangeCost c = mpi::composite_to_root(mpi_->world, layout, uint32_t(rank), frame);
        return {c.bytes_sent, c.seconds};
    }
#endif
    (void)layout, (void)frame;   // one rank: its slab is every cell, its frame already the image
    return {};
}

std::shared_ptr<const std::vector<double>> Ranks::ghost_plane(
    [[maybe_unused]] const std::vector<CellBox>& bricks,
    [[maybe_unused]] const std::function<std::vector<double>(uint32_t)>& decode, uint64_t& bytes_sent) {
    bytes_sent = 0;
#if OCTISO_WITH_MPI
    if (mpi_) return mpi::exchange_ghost_planes(mpi_->world, bricks, decode, bytes_sent);
#endif
    return nullptr;   // one rank: its brick is the volume
}

void Ranks::deal(size_t count, const std::function<void(size_t)>& render) {
#if OCTISO_WITH_MPI
    if (mpi_) {
        mpi::StepDealer dealer(mpi_->world, (long long)count);
        for (long long n; (n = dealer.next()) >= 0;) render(size_t(n));
        dealer.finish();
        return;
    }
#endif
    for (size_t n = 0; n < count; ++n) render(n);
}

std::vector<FrameRecord> Ranks::gather_records(std::vector<FrameRecord> mine, double wall_seconds,
                                               uint64_t file_resident_bytes) {
    for (FrameRecord& r : mine) r.rank_wall_seconds = wall_seconds, r.file_resident_bytes = file_resident_bytes;
#if OCTISO_WITH_MPI
    if (mpi_ && size > 1) {
        // Fixed-size rows: first how many each rank has, then every rank padded to the most.
        std::string count(sizeof(uint64_t), '\0');
        const uint64_t n = mine.size();
        std::memcpy(count.data(), &n, sizeof n);
        const std::string counts = mpi_->world.gather_equal(count);
        uint64_t most = n;
        for (int r = 0; rank == 0 && r < size; ++r) {
            uint64_t c;
            std::memcpy(&c, counts.data() + size_t(r) * sizeof c, sizeof c);
            most = std::max(most, c);
        }
        std::string most_bytes(sizeof most, '\0');
        std::memcpy(most_bytes.data(), &most, sizeof most);
        most_bytes = mpi_->world.broadcast(most_bytes);
        std::memcpy(&most, most_bytes.data(), sizeof most);
        std::string rows(size_t(most) * sizeof(FrameRecord), '\0');
        if (!mine.empty()) std::memcpy(rows.data(), mine.data(), mine.size() * sizeof(FrameRecord));   // a rank with no step has no data()
        const std::string all = mpi_->world.gather_equal(rows);
        if (rank != 0) return mine;
        std::vector<FrameRecord> out;
        for (int r = 0; r < size; ++r) {
            uint64_t c;
            std::memcpy(&c, counts.data() + size_t(r) * sizeof c, sizeof c);
            for (uint64_t i = 0; i < c; ++i) {
                FrameRecord rec;
                std::memcpy(&rec, all.data() + (size_t(r) * size_t(most) + size_t(i)) * sizeof(FrameRecord), sizeof rec);
                out.push_back(rec);
            }
        }
        return out;
    }
#endif
    return mine;
}

}  // namespace octiso::cli
