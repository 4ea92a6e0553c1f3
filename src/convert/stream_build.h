// The out-of-core build of one step (issue 13): the bottom-up build of build.cpp, cut into pieces
// of S^3 voxels (subtrees at depth dmax - log2 S) that are built a slab of S layers at a time from
// a VolumeStream, their finished node arrays appended per depth to SpillFiles, and the sections
// streamed into OctWriter at the end in the file's node order with the child indices offset.
// The bytes written equal those of the in-memory build (tests/convert/stream_build_test.cpp):
// per depth, nodes sit in depth-first order whatever the cut, and each node depends only on the
// voxels of its cube plus the halo below.
//
// Halo per slab: one layer above (the forward layer of min/max and of the caps' neighbourhood);
// with --iso-range one more above and one below, because clamping a voxel needs the flags of its
// 3x3x3 neighbourhood. x and y are never cut: a slab spans whole layers, the order of the file.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "io/volume_stream.h"
#include "octiso/build.h"
#include "octiso/oct_file.h"
#include "octiso/volume.h"

namespace octiso::convert_detail {

/// The cut and the memory it is expected to need (bytes).
struct StreamPlan {
    uint32_t piece_side = 0;   ///< S: a power of two, 4 <= S <= 2^dmax
    uint64_t slab_bytes = 0;   ///< one slab: layers + halo, conditioning copies, the pieces' arrays
    uint64_t fixed_bytes = 0;  ///< per-piece index (counts, root summaries, order) and one staging chunk
    uint64_t spill_memory = 0; ///< what the spill files may keep in memory before going to disk
};

/// The largest side S up to 64 whose slab needs at most half of `budget` (the rest may hold
/// spilled arrays), else 4. `forced_side` (tests: every seam crossed) overrides the choice.
/// Throws Error(subject, "out of memory: ...") (bad input) when a slab of side 4 (or the forced
/// side) does not fit, naming the need and the budget, before any work is done.
StreamPlan plan_stream(Dims dims, ScalarType type, const BuildOptions& options, uint64_t budget, uint32_t forced_side,
                       const std::string& subject);

/// What one streamed step gave.
struct StreamStepResult {
    StepSizes sizes;
    double build_seconds = 0;   ///< reading, conditioning, building and writing: the whole step
    uint64_t spilled_bytes = 0; ///< node bytes that went to temporary files
    /// Its phases (issue 12): the slabs (read, conditioned and built into pieces, interleaved),
    /// the top above the pieces, and the sections streamed into the writer.
    double slabs_seconds = 0, top_seconds = 0, sections_seconds = 0;
};

/// Builds the step `stream` holds (its cursor at layer 0) under `plan` and writes its sections
/// into `writer` (begin_section .. end_section, depths 0 .. dmax-1). Temporaries are named after
/// `output`. `on_layers(read)` is called after each slab with the layers read so far. Throws
/// Error(options.source_name, ...) as build_octree() does (non-finite data, too many nodes).
StreamStepResult stream_build_step(VolumeStream& stream, const BuildOptions& options, const StreamPlan& plan,
                                   OctWriter& writer, const std::string& output,
                                   const std::function<void(uint32_t)>& on_layers = {});

}  // namespace octiso::convert_detail
