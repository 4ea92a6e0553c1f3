// The OpenVDB peer of `octiso-bench peers`: (1) the volume as a sparse float grid (copyFromDense,
// tolerance 0) and its memUsage, and (2) the level-set path a user needs for an arbitrary scalar
// isosurface (shift by -iso, scale to |grad| ~ 1, GRID_LEVEL_SET; notes/peers.md 1.3) traced with
// LevelSetRayIntersector over the same rays as octiso. Compiled against OpenVDB only where CMake
// found it (OCTISO_HAVE_OPENVDB); otherwise vdb_available() is false and nothing runs.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "octiso/reader.h"
#include "octiso/render.h"

namespace octiso::bench {

bool vdb_available();

struct VdbPeerResult {
    bool ran = false;
    std::string skipped;                   ///< why not, when !ran
    // The volume as an OpenVDB float grid, lossless.
    double dense_seconds = 0;              ///< copyFromDense (from the float copy)
    uint64_t dense_bytes = 0;              ///< Grid::memUsage()
    uint64_t dense_leaves = 0, dense_active_voxels = 0;
    // The level-set grid g = scale * (iso - f) for LevelSetRayIntersector.
    double to_float_seconds = 0;           ///< the volume converted to a dense float array
    double levelset_seconds = 0;           ///< max cell range + shift/scale + copyFromDense + intersector set-up
    uint64_t levelset_bytes = 0;           ///< Grid::memUsage()
    double scale = 0, background = 0;      ///< the chosen s and background
    double first_render_seconds = 0;       ///< wall time of the first frame
    Frame frame;                           ///< depth + normals facing the ray (the first frame)
    /// Renders the frame again (the level set stays alive while this result lives) and returns the
    /// tile-loop seconds; the caller interleaves these repeats with the other methods.
    std::function<double(Frame* out)> render;
    /// to-float + level-set preprocessing + one render: what an isovalue change costs.
    double time_to_first_image() const { return to_float_seconds + levelset_seconds + first_render_seconds; }
};

/// Runs both OpenVDB measurements for isovalue `iso` with `camera` (one frame; more through `render`). Never throws for a volume
/// OpenVDB cannot take (anisotropic spacing, iso outside the data): it says so in `skipped`.
VdbPeerResult run_vdb_peer(const LoadedVolume& volume, double iso, const Camera& camera);

}  // namespace octiso::bench
