// One pixel re-traced with a record of what its ray visited, for `octiso-render --debug-pixel X,Y`
// (STYLE.md, hot loops): the same camera ray and the same OctreeTracer as a frame, with a
// recording policy that the frame's instantiation does not have (src/render/traverse.h), so
// recording costs a frame nothing. The trace is in index space; t is world distance, as in frames.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "octiso/camera.h"
#include "octiso/octree.h"
#include "octiso/render.h"
#include "octiso/volume.h"

namespace octiso {

/// One step of the traversal, in the order it happened.
struct PixelTraceEvent {
    enum class Kind {
        clip,          ///< the ray's piece [t0, t1] inside the data box (t0 > t1: it misses the box)
        node,          ///< interior node entered: depth, index, origin, side, [t0, t1)
        cull,          ///< child skipped because no isovalue lies in [lo, hi]: depth of its parent,
                       ///< index = child octant, origin, side, [t0, t1)
        scalar_leaf,   ///< uniform child walked at its shell: depth of its parent, origin, side,
                       ///< value = lo = hi; all_cells: an isovalue equals the value (every cell walked)
        cap,           ///< cap entered: depth dmax-1, index, origin, side 2, [t0, t1)
        cell,          ///< data cell tested: origin, [t0, t1) ([t0, t1] when closed_end), corner range [lo, hi]
        root,          ///< the cell just tested has the first root: t0 = t1 = t, iso_index
    };
    Kind kind = Kind::clip;
    int depth = -1;
    uint32_t index = 0;
    Coord origin{};
    uint32_t side = 0;
    double t0 = 0, t1 = 0;
    double lo = 0, hi = 0;
    bool closed_end = false;   ///< cell: closed at the data exit; scalar leaf: every cell walked
    int iso_index = -1;
};

struct PixelTrace {
    int x = 0, y = 0, width = 0, height = 0;
    std::array<double, 3> origin{}, dir{};   ///< the world ray of the pixel (unit direction)
    double t = std::numeric_limits<double>::infinity();   ///< the hit, as the frame's depth; +inf: miss
    int iso_index = -1;                                   ///< -1: miss
    std::array<double, 3> normal{};                       ///< world unit normal at the hit
    std::vector<double> isovalues;
    std::vector<PixelTraceEvent> events;

    /// One line per event, indented by depth, then the hit (or "miss"); t printed with 17 digits.
    std::string text() const;
};

/// Re-traces pixel (x, y) (x from the left, y = 0 the top row) of `camera` with the isovalues and
/// root finder of `options`, recording every event. Throws Error("--debug-pixel", ...) when the
/// pixel lies outside the image, and as render() does for invalid options or camera.
template <typename T>
PixelTrace trace_pixel(const Octree<T>& tree, const Placement& placement, const Camera& camera,
                       const RenderOptions& options, int x, int y);

}  // namespace octiso
