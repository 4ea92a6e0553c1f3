// Building an Octree<T> bottom-up from a dense VolumeView<T> (Knoll et al. 2006, Sec. 3.1, 3.3,
// 4.1), in parallel with TBB: lossless consolidation of uniform siblings into scalar leaves,
// min/max over each child's cells including the forward layer, padding as "don't care", optional
// iso-range clamping and lossy tolerance. OctreeData<T> owns the result; view() reads it.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "octiso/octree.h"
#include "octiso/volume.h"

namespace octiso {

struct BuildOptions {
    /// --iso-range LO,HI: a voxel below LO (above HI) becomes LO (HI) wherever that changes no
    /// cell that reaches into (LO,HI), so every isosurface with LO < iso < HI stays exact.
    std::optional<std::array<double, 2>> iso_range;
    /// --tolerance EPS: siblings whose values all lie within EPS of one representative merge.
    double tolerance = 0.0;
    /// --nan-as V: NaN and +-Inf become V; without it a non-finite value is an error.
    std::optional<double> nan_as;
    int threads = 0;               ///< 0: all cores (the caller's tbb::global_control applies)
    std::string source_name;       ///< named in errors
    /// Recorded with the tree, not used by the build: the source's stored-to-real values and
    /// reversed axes (volume.h). iso_range, tolerance and nan_as above are stored values.
    ValueScale value_scale;
    uint8_t flipped_axes = 0;
};

/// Wall seconds of the in-memory build's phases (issue 12: what does not scale is visible in
/// octiso-convert --json on any machine). pieces is the parallel bulk; prepare is parallel too;
/// top is serial and small; concatenate copies the pieces' arrays into the final ones (parallel
/// over pieces in batches) and release is the malloc_trim between batches (serial).
/// pieces_busy is the thread seconds inside pieces: pieces_busy / (threads x pieces) is that
/// phase's utilisation, and its growth with the thread count is each piece costing more.
struct BuildPhases {
    double prepare = 0, pieces = 0, top = 0, concatenate = 0, release = 0;
    double pieces_busy = 0;
};

/// Counts per depth d = 0 .. dmax-1: stored nodes (interior; caps at dmax-1) and scalar leaves
/// (children of depth-d nodes that are leaves, data-covering or padding).
struct BuildStats {
    std::vector<uint64_t> nodes_per_depth;
    std::vector<uint64_t> scalar_leaves_per_depth;
    uint64_t interior_bytes = 0;   ///< all interior levels as the file holds them (records, group bases)
    uint64_t minmax_bytes = 0;     ///< the part of interior_bytes that is child bounds
    uint64_t cap_bytes = 0;        ///< packed cap records
    double seconds = 0;
    BuildPhases phases;
};

/// A fixed-size array whose elements start uninitialised, so that its pages become resident only
/// as they are written (the builder's concatenation relies on that to keep peak memory low).
template <typename U> struct UninitArray {
    std::unique_ptr<U[]> data;
    uint64_t size = 0;
    static UninitArray make(uint64_t n) { return {std::unique_ptr<U[]>(new U[n]), n}; }
};

template <typename T> class OctreeData {
public:
    Octree<T> view() const;

    Dims dims;
    int dmax = 0;
    std::vector<UninitArray<InteriorNode<T>>> nodes;   ///< [depth 0 .. dmax-2]
    std::vector<UninitArray<uint64_t>> group_bases;    ///< [depth 0 .. dmax-2], node_groups(count) each
    UninitArray<uint8_t> caps;    ///< packed cap records, then kCapReadSlack zero bytes
    uint64_t cap_bytes = 0;       ///< records only
    uint64_t cap_count = 0;
    BuildStats stats;
};

/// Builds the octree of `volume`. Throws Error(options.source_name, ...) on non-finite data
/// without nan_as, or on a tree too large for 32-bit child indices.
template <typename T> OctreeData<T> build_octree(const VolumeView<T>& volume, const BuildOptions& options);

}  // namespace octiso
