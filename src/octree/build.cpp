// Bottom-up octree construction (Knoll et al. 2006, Sec. 3.1, 3.3, 4.1) in parallel.
//
// Plan: 1. condition the input (prepare.h); 2. cut the tree at a split depth k into up to 8^k
// subtrees ("pieces") and build each one depth-first in its own Sink, in parallel; 3. build the
// few nodes above depth k serially from the pieces' root summaries; 4. concatenate each depth's
// arrays and place every node's children (child_groups.h: a prefix sum of the children spans).
//
// Why depth-first post-order works: a node is appended to its depth's array when its own children
// are complete, so the 8 children of any node are appended consecutively at depth d+1, which is
// exactly what first child + popcount indexing needs. A child is appended only if it is not a
// scalar leaf, and a node merges into a leaf only if all its children are leaves, so a merge never
// leaves orphans behind.
//
// Min/max (Sec. 3.3, Fig. 5): the cells whose lower corner lies in a 2x2x2 block use the voxels of
// the 3x3x3 box from the block's origin, clipped to the data; higher levels take the union of their
// children. A node at depth dmax-2 (4^3 voxels) loads its 5^3 neighbourhood once and derives the
// ranges of its 8 blocks from it: about 2 reads per voxel instead of 27/8 per block voxel.
// Padding beyond the data never enters a range and never blocks a merge ("don't care").
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include <malloc.h>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "octiso/build.h"
#include "octiso/error.h"
#include "octree/child_groups.h"
#include "octree/prepare.h"
#include "octree/piece_builder.h"
#include "octree/summary.h"
#include "util/check.h"
#include "util/shared_arena.h"

namespace octiso {

template <typename T> Octree<T> OctreeData<T>::view() const {
    OctreeArrays<T> a;
    a.dims = dims;
    a.dmax = dmax;
    for (size_t d = 0; d < nodes.size(); ++d) {
        a.nodes[d] = nodes[d].data.get();
        a.node_count[d] = nodes[d].size;
    }
    for (size_t d = 0; d < group_bases.size(); ++d) a.group_base[d] = group_bases[d].data.get();
    a.caps = caps.data.get();
    a.cap_bytes = cap_bytes;
    a.cap_count = cap_count;
    return Octree<T>(a);
}

namespace {

using detail::Builder;
using detail::Sink;
using detail::Summary;

/// Appends `src` to `dst` at `at`, then frees `src`, so each piece's memory goes as it is copied.
template <typename U> void move_into(UninitArray<U>& dst, uint64_t& at, std::vector<U>& src) {
    std::copy(src.begin(), src.end(), dst.data.get() + at);
    at += src.size();
    std::vector<U>().swap(src);
}

/// Gives freed heap pages back to the OS. The pieces' vectors are mostly below glibc's dynamic
/// mmap threshold, so they live in the worker threads' arenas, and free() alone keeps them
/// resident while the final arrays fill: that doubled the output in peak RSS (octiso-bench
/// compression, 512^3 plume: 1.26x of input + output before, see BENCHMARKS.md, compression).
void release_free_memory() { ::malloc_trim(0); }

template <typename T> OctreeData<T> build_impl(const VolumeView<T>& input, const BuildOptions& options) {
    const auto t0 = std::chrono::steady_clock::now();
    if (input.dims.x == 0 || input.dims.y == 0 || input.dims.z == 0)
        throw Error(options.source_name, "volume has a zero dimension");
    detail::PreparedVolume<T> prepared = detail::prepare_volume(input, options);
    BuildPhases phases;
    phases.prepare = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    OctreeData<T> out;
    out.dims = input.dims;
    out.dmax = dmax_for(input.dims);
    const int dmax = out.dmax;
    const Builder<T> builder(prepared.view, input.dims, dmax, options.tolerance);

    // 1. Pieces: the nodes at split depth k that the top-level descent reaches, in DFS order.
    const int k = std::min(dmax - 2, 3);
    std::vector<Coord> origins;
    auto enumerate = [&](auto&& self, int d, Coord o) -> void {
        if (builder.outside(o)) return;
        if (d == k) { origins.push_back(o); return; }
        for (int c = 0; c < 8; ++c) self(self, d + 1, Builder<T>::child_origin(o, c, builder.child_bit(d)));
    };
    enumerate(enumerate, 0, Coord{});

    auto t_phase = std::chrono::steady_clock::now();
    const auto phase_done = [&](double& phase) {
        const auto now = std::chrono::steady_clock::now();
        phase = std::chrono::duration<double>(now - t_phase).count();
        t_phase = now;
    };
    std::vector<Sink<T>> sinks;
    sinks.reserve(origins.size());
    for (size_t i = 0; i < origins.size(); ++i) sinks.emplace_back(dmax);
    std::vector<Summary<T>> roots(origins.size());
    std::atomic<uint64_t> pieces_busy_ns{0};   // each piece's own wall time (two clock reads a piece)
    tbb::parallel_for(size_t(0), origins.size(), [&](size_t i) {
        const auto started = std::chrono::steady_clock::now();
        roots[i] = builder.build(k, origins[i], sinks[i]);
        pieces_busy_ns += uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - started).count());
    });
    phase_done(phases.pieces);
    phases.pieces_busy = double(pieces_busy_ns.load()) * 1e-9;

    // 2. The top: the same descent, taking each depth-k summary from its piece.
    Sink<T> top(dmax);
    size_t next_piece = 0;
    auto descend = [&](auto&& self, int d, Coord o) -> Summary<T> {
        if (builder.outside(o)) return Builder<T>::padding();
        if (d == k) {
            return roots[next_piece++];
        }
        Summary<T> ch[8];
        for (int c = 0; c < 8; ++c) ch[c] = self(self, d + 1, Builder<T>::child_origin(o, c, builder.child_bit(d)));
        return builder.combine(d, ch, top);
    };
    if (k > 0) descend(descend, 0, Coord{});
    // The top must consume every piece in the order they were cut, or a depth-(k-1) node's
    // children would be another piece's roots.
    OCTISO_CHECK(k == 0 || next_piece == origins.size(), next_piece, " of ", origins.size(), " pieces consumed");
    phase_done(phases.top);

    // 3. Concatenate depth by depth. Depths below k come from `top` alone. The pieces of a depth
    //    are copied in parallel, in batches of 16 pieces or two per thread (whichever is more):
    //    each piece's place is a prefix sum, so the copies are independent
    //    (issue 12: serial, the copy and the trims were 0.044 s of a 1.27 s 1-thread build of
    //    plume 512^3, an Amdahl bound of 66 % at 16 threads; BENCHMARKS.md "Many-core"). Freed piece
    //    memory is handed back as the copy goes, so peak memory stays near input + output.
    const auto t_concat = std::chrono::steady_clock::now();
    double release_seconds = 0;
    const auto release = [&] {
        const auto t = std::chrono::steady_clock::now();
        release_free_memory();
        release_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
    };
    const size_t batch = std::max<size_t>(16, 2 * size_t(tbb::this_task_arena::max_concurrency()));
    uint64_t tree_bytes = 0;
    for (const auto& sk : sinks) {
        tree_bytes += sk.caps.size();
        for (const auto& v : sk.nodes) tree_bytes += v.size() * sizeof(InteriorNode<T>);
    }
    // Freed memory is handed back once a 64th of the tree (at least 1 MiB) was freed since the last
    // time, not after every batch: malloc_trim walks every arena each call. Plume 512^3, 1 and 2
    // threads, 2 interleaved rounds (octiso-convert --json phases): release 13-15 / 21-24 ms after
    // every batch against 7-9 / 11 ms, peak RSS 191.1-191.6 against 191.9-192.2 MiB (+0.3 %).
    const uint64_t release_every = std::max<uint64_t>(uint64_t(1) << 20, tree_bytes / 64);
    uint64_t pending = 0;
    // Runs copy(i) for every part index i in parallel, one batch at a time, releasing between.
    const auto in_batches = [&](size_t count, auto&& bytes_of, auto&& copy) {
        for (size_t b = 0; b < count; b += batch) {
            const size_t e = std::min(count, b + batch);
            for (size_t i = b; i < e; ++i) pending += bytes_of(i);
            tbb::parallel_for(b, e, [&](size_t i) { copy(i); });
            if (pending >= release_every) release(), pending = 0;
        }
    };
    out.nodes.resize(size_t(dmax - 1));
    out.group_bases.resize(size_t(dmax - 1));
    out.stats.nodes_per_depth.assign(size_t(dmax), 0);
    out.stats.scalar_leaves_per_depth.assign(size_t(dmax), 0);
    for (int d = 0; d <= dmax - 2; ++d) {
        std::vector<Sink<T>*> parts;
        if (d < k) parts.push_back(&top);
        else for (auto& s : sinks) parts.push_back(&s);
        std::vector<uint64_t> at(parts.size());
        uint64_t total = 0;
        for (size_t i = 0; i < parts.size(); ++i) {
            at[i] = total;
            total += parts[i]->nodes[size_t(d)].size();
            out.stats.scalar_leaves_per_depth[size_t(d)] += parts[i]->leaves[size_t(d)];
        }
        // Children at depth d+1, as they will be concatenated.
        const bool caps_below = d + 1 == dmax - 1;
        uint64_t next_total = 0;
        if (caps_below) for (auto& s : sinks) next_total += s.caps.size();
        else if (d + 1 < k) next_total = top.nodes[size_t(d + 1)].size();
        else for (auto& s : sinks) next_total += s.nodes[size_t(d + 1)].size();
        // Interior children are 32-bit node indices, caps 48-bit byte offsets (octree.h).
        if (next_total > (caps_below ? kMaxCapByteOffset : uint64_t(1) << 32))
            throw Error(options.source_name, caps_below ? "octree too large: more than 2^48 bytes of caps"
                                                        : "octree too large: more than 2^32 nodes at depth " +
                                                              std::to_string(d + 1) + " (32-bit child indices)");
        out.nodes[size_t(d)] = UninitArray<InteriorNode<T>>::make(total);
        in_batches(parts.size(), [&](size_t i) { return parts[i]->nodes[size_t(d)].size() * sizeof(InteriorNode<T>); },
                   [&](size_t i) {
            uint64_t place = at[i];
            move_into(out.nodes[size_t(d)], place, parts[i]->nodes[size_t(d)]);
        });
        out.group_bases[size_t(d)] = UninitArray<uint64_t>::make(node_groups(total));
        const uint64_t children = detail::place_children(out.nodes[size_t(d)].data.get(), total, caps_below,
                                                         out.group_bases[size_t(d)].data.get());
        OCTISO_CHECK(children == next_total, "depth ", d, ": children for ", children, " of ", next_total, " at depth ", d + 1);
        out.stats.nodes_per_depth[size_t(d)] = total;
    }
    uint64_t n_bytes = 0, n_caps = 0;
    std::vector<uint64_t> cap_at(sinks.size());
    for (size_t i = 0; i < sinks.size(); ++i) cap_at[i] = n_bytes, n_bytes += sinks[i].caps.size(), n_caps += sinks[i].cap_count;
    out.caps = UninitArray<uint8_t>::make(n_bytes + kCapReadSlack);
    in_batches(sinks.size(), [&](size_t i) { return uint64_t(sinks[i].caps.size()); }, [&](size_t i) {
        uint64_t place = cap_at[i];
        move_into(out.caps, place, sinks[i].caps);
    });
    std::fill_n(out.caps.data.get() + n_bytes, kCapReadSlack, uint8_t(0));
    sinks = {};
    release();
    out.stats.phases = phases;
    out.stats.phases.concatenate = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_concat).count() - release_seconds;
    out.stats.phases.release = release_seconds;
    out.cap_bytes = n_bytes;
    out.cap_count = n_caps;
    out.stats.nodes_per_depth[size_t(dmax - 1)] = n_caps;

    for (int d = 0; d <= dmax - 2; ++d) {
        out.stats.interior_bytes += interior_level_bytes<T>(out.nodes[size_t(d)].size);
        out.stats.minmax_bytes += out.nodes[size_t(d)].size * sizeof(ChildBounds<T>);
    }
    out.stats.cap_bytes = n_bytes;
    out.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
}

}  // namespace

template <typename T> OctreeData<T> build_octree(const VolumeView<T>& volume, const BuildOptions& options) {
    try {
        return in_shared_arena(options.threads, [&] { return build_impl(volume, options); });
    } catch (const std::bad_alloc&) {
        // Issue 18: a huge declared grid ran out of memory without naming its file.
        const Dims d = volume.dims;
        throw Error(options.source_name, "out of memory building the octree of this " + std::to_string(d.x) + "x" +
                                             std::to_string(d.y) + "x" + std::to_string(d.z) + " " +
                                             std::string(scalar_type_name(scalar_type_of<T>())) + " volume");
    }
}

#define OCTISO_INSTANTIATE(T)                                                               \
    template class OctreeData<T>;                                                           \
    template OctreeData<T> build_octree<T>(const VolumeView<T>&, const BuildOptions&);
OCTISO_FOR_EACH_SCALAR_TYPE(OCTISO_INSTANTIATE)
#undef OCTISO_INSTANTIATE

}  // namespace octiso
