// Sort-first gathering and sort-last compositing over MPI (frame_exchange.h).
#include "mpi/frame_exchange.h"

#include <mpi.h>

#include <chrono>
#include <climits>
#include <cstring>
#include <limits>

#include "octiso/error.h"

namespace octiso::mpi {
namespace {

double since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int checked_count(uint64_t bytes) {
    if (bytes > uint64_t(INT_MAX))
        throw Error("--distribute", "a frame part of " + std::to_string(bytes) + " bytes exceeds what one MPI message takes",
                    ErrorKind::Other);
    return int(bytes);
}

void check(int code, const char* what) {
    if (code != MPI_SUCCESS) throw Error("mpi", std::string(what) + " failed", ErrorKind::Other);
}

/// Bytes of tile `rect` in the outputs asked for.
uint64_t tile_bytes(const PixelRect& r, bool colour, bool depth, bool normal) {
    const uint64_t px = uint64_t(r.x1 - r.x0) * uint64_t(r.y1 - r.y0);
    return px * ((colour ? 3 : 0) + (depth ? 4 : 0) + (normal ? 12 : 0));
}

/// Copies the rows of `r` between the frame's outputs and a packed buffer (out: frame -> buffer).
std::byte* copy_tile(Frame& f, const PixelRect& r, bool colour, bool depth, bool normal, std::byte* p, bool out) {
    const size_t w = size_t(r.x1 - r.x0);
    auto move = [&](void* frame_bytes, size_t n) {
        if (out) std::memcpy(p, frame_bytes, n);
        else std::memcpy(frame_bytes, p, n);
        p += n;
    };
    for (int y = r.y0; y < r.y1; ++y) {
        const size_t i = size_t(y) * size_t(f.width) + size_t(r.x0);
        if (colour) move(&f.rgb[3 * i], 3 * w);
        if (depth) move(&f.depth[i], 4 * w);
        if (normal) move(&f.normal[3 * i], 12 * w);
    }
    return p;
}

/// The reduction: the layout is read back from the sample size (8, 12, 20 or 24 bytes).
void nearer_op(void* in, void* inout, int* len, MPI_Datatype* type) {
    int bytes = 0;
    MPI_Type_size(*type, &bytes);
    const CompositeLayout layout = CompositeLayout::from_sample_bytes(size_t(bytes));
    composite_nearer(static_cast<const std::byte*>(in), static_cast<std::byte*>(inout), size_t(*len), layout);
}

}  // namespace

std::vector<int> tiles_of_rank(int tile_count, int rank, int size) {
    std::vector<int> tiles;
    for (int i = rank; i < tile_count; i += size) tiles.push_back(i);
    return tiles;
}

ExchangeCost gather_tiles(const World& world, const TileGrid& grid, bool colour, bool depth, bool normal, Frame& frame) {
    const auto t0 = std::chrono::steady_clock::now();
    colour &= !frame.rgb.empty(), depth &= !frame.depth.empty(), normal &= !frame.normal.empty();
    if (!world.active() || world.size() == 1) return {};
    const int size = world.size(), rank = world.rank();
    std::vector<int> counts(size_t(size), 0), displs(size_t(size), 0);
    for (int r = 0; r < size; ++r) {
        uint64_t bytes = 0;
        for (const int t : tiles_of_rank(grid.count(), r, size)) bytes += tile_bytes(grid.rect(t), colour, depth, normal);
        counts[size_t(r)] = checked_count(bytes);
        if (r > 0) displs[size_t(r)] = checked_count(uint64_t(displs[size_t(r) - 1]) + uint64_t(counts[size_t(r) - 1]));
    }
    std::vector<std::byte> mine(static_cast<size_t>(counts[size_t(rank)]));
    std::byte* p = mine.data();
    for (const int t : tiles_of_rank(grid.count(), rank, size)) p = copy_tile(frame, grid.rect(t), colour, depth, normal, p, true);
    std::vector<std::byte> all(rank == 0 ? size_t(displs.back()) + size_t(counts.back()) : 0);
    check(MPI_Gatherv(mine.data(), counts[size_t(rank)], MPI_BYTE, all.data(), counts.data(), displs.data(), MPI_BYTE, 0,
                      MPI_COMM_WORLD),
          "gathering the tiles");
    if (rank == 0) {
        for (int r = 1; r < size; ++r) {
            std::byte* q = all.data() + displs[size_t(r)];
            for (const int t : tiles_of_rank(grid.count(), r, size)) q = copy_tile(frame, grid.rect(t), colour, depth, normal, q, false);
        }
    }
    return {rank == 0 ? 0 : uint64_t(counts[size_t(rank)]), since(t0)};
}

ExchangeCost composite_to_root(const World& world, const CompositeLayout& layout, uint32_t ordinal, Frame& frame) {
    const auto t0 = std::chrono::steady_clock::now();
    const size_t pixels = size_t(frame.width) * size_t(frame.height);
    const int size = world.active() ? world.size() : 1, rank = world.rank();
    const size_t sample = layout.sample_bytes();
    const size_t chunk = (pixels + size_t(size) - 1) / size_t(size);   // samples per rank's slice
    // Padding samples past the frame: depth +inf, ordinal 0; they composite to themselves.
    std::vector<std::byte> mine(chunk * size_t(size) * sample, std::byte{0});
    pack_composite(frame, ordinal, layout, std::span<std::byte>(mine.data(), pixels * sample));
    const float inf = std::numeric_limits<float>::infinity();
    for (size_t i = pixels; i < chunk * size_t(size); ++i) std::memcpy(&mine[i * sample], &inf, 4);
    if (size == 1) {
        unpack_composite(std::span<const std::byte>(mine.data(), pixels * sample), layout, frame);
        return {0, since(t0)};
    }
    checked_count(chunk * sample * size_t(size));
    MPI_Datatype type;
    MPI_Op op;
    check(MPI_Type_contiguous(int(sample), MPI_BYTE, &type), "MPI_Type_contiguous");
    MPI_Type_commit(&type);
    MPI_Op_create(&nearer_op, 1, &op);   // commutative: nearest depth, then lowest ordinal
    std::vector<std::byte> slice(chunk * sample);
    const int reduced = MPI_Reduce_scatter_block(mine.data(), slice.data(), int(chunk), type, op, MPI_COMM_WORLD);
    std::vector<std::byte> all(rank == 0 ? chunk * size_t(size) * sample : 0);
    const int gathered = reduced == MPI_SUCCESS ? MPI_Gather(slice.data(), int(chunk), type, all.data(), int(chunk), type, 0,
                                                             MPI_COMM_WORLD)
                                                : reduced;
    MPI_Op_free(&op);
    MPI_Type_free(&type);
    check(reduced, "the depth reduce-scatter");
    check(gathered, "gathering the composite");
    if (rank == 0) unpack_composite(std::span<const std::byte>(all.data(), pixels * sample), layout, frame);
    const uint64_t slice_bytes = chunk * sample;
    return {uint64_t(size - 1) * slice_bytes + (rank == 0 ? 0 : slice_bytes), since(t0)};
}

}  // namespace octiso::mpi
