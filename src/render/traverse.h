// OctreeTracer<T, Finder>: first hit of one ray with the isosurfaces of an Octree<T> (Knoll et al.
// 2006, Sec. 4.3 and App. C), in index space on the closed data box [0, n-1]^3.
//
// Interior nodes: the ray's times at the three mid-planes decide the first child and the order
// of the rest; a child is entered only if an isovalue lies in its [min, max]. Every plane time is
// IndexRay::plane_t, the same expression the cell walk and the reference tracer use, so a ray
// splits at exactly the same t at every level and no interval is lost or doubled.
// Deviation from App. C: the first child is chosen by comparing times, not positions (no
// position/time rounding mismatch), and +-0 direction components never divide (plane_t gives +inf).
// Caps and scalar leaves: a short DDA over their cells. A scalar leaf's inner cells have all 8
// corners equal to the leaf value, so unless an isovalue equals it only the shell of cells at its
// +x/+y/+z faces (whose forward corners lie in neighbours) is walked.
// Corners: inside a cap, a forward neighbour in the same cap is a direct read (octant & dir == 0),
// otherwise neighbour finding climbs the parent trace this traversal keeps (App. B.2); each of the
// 7 forward neighbour blocks of a cap is located once per cap visit and then read directly
// (measured by `octiso-bench grid`: +3-5 % frames/s on octree data, BENCHMARKS.md, grid section).
// The corner source is a policy only for the grid benchmark's "octree over array data" variant
// (Knoll 2006 Table 3); with the default, OctreeCornerSource, the policy costs nothing.
// The recorder is a policy only for `--debug-pixel` (octiso/debug_trace.h): with the default,
// NoRecorder, every recording call sits behind `if constexpr (Recorder::kOn)` and is not compiled.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "octiso/octree.h"
#include "render/cell.h"
#include "render/cell_dda.h"
#include "render/cell_hit.h"
#include "math/ray.h"
#include "render/roots.h"
#include "util/check.h"

namespace octiso {

/// The default corner source: the octree itself (in-cap reads and neighbour finding). Any other
/// Corners type provides `void gather(Coord cell, double corner[8]) const` and replaces every
/// corner read (e.g. ArrayCorners<T> in src/reference/macrocell.h); the octree then only culls.
struct OctreeCornerSource {};

/// The default recorder: records nothing. A recording type sets kOn = true and provides the
/// const calls of PixelTraceRecorder (src/render/debug_trace.cpp): clip, enter_node, cull,
/// scalar_leaf, enter_cap, cell, root.
struct NoRecorder {
    static constexpr bool kOn = false;
};

template <typename T, class Finder, class Corners = OctreeCornerSource, class Recorder = NoRecorder>
class OctreeTracer {
    static constexpr bool kOwnCorners = std::is_same_v<Corners, OctreeCornerSource>;

public:
    OctreeTracer(const Octree<T>& tree, const Placement& placement, const double* isovalues, int iso_count,
                 const Finder& finder, const Corners& corners = Corners{}, const Recorder& recorder = Recorder{})
        : tree_(tree), scene_(tree.dims(), placement, isovalues, iso_count), finder_(finder), corners_(corners),
          recorder_(recorder) {
        OCTISO_CHECK(tree.dmax() >= 2 && tree.dmax() < kMaxDepth, "dmax ", tree.dmax());
    }

    /// First hit along the world ray; the normal is computed only if `want_normal`.
    /// Thread-safe: all per-ray state lives on the caller's stack.
    TraceHit trace(const Ray& ray_world, bool want_normal) const {
        Walk w;
        const BoxClip clip = w.start(scene_, ray_world, want_normal);
        if constexpr (Recorder::kOn) recorder_.clip(clip.t_in, clip.t_out);
        if (!clip.empty()) node(w, 0, 0, Coord{}, clip.t_in, clip.t_out);
        return w.hit;
    }

private:
    static Coord child_origin_of(const Coord& o, int c, uint32_t half) {
        return {o.x + ((c & 4) ? half : 0), o.y + ((c & 2) ? half : 0), o.z + ((c & 1) ? half : 0)};
    }

    struct Walk : RayState {
        uint32_t trace[kMaxDepth];   ///< parent trace: node index at each depth down to the current one
    };

    /// Whether the ray is on the upper side of the plane p[a] == plane at time t (the side it
    /// occupies on [t, t + dt) for small dt): decided from times, never from positions. A ray lying
    /// in the plane takes the upper side, except in the data box's top face (plane == box_hi),
    /// whose only cells lie below it (the box is closed, CONVENTIONS 2b).
    bool upper_at(const IndexRay& r, int a, double plane, double t_plane, double t) const {
        const double d = r.dir[a];
        if (d > 0) return t_plane <= t;
        if (d < 0) return t < t_plane;
        return r.origin[a] > plane || (r.origin[a] == plane && plane < scene_.box_hi[a]);
    }

    // Node origins travel by reference: a Coord passed by value is assembled with 32-bit stores
    // and reloaded as a 64-bit register pair, a store-forwarding stall that cost 18 % of node()
    // (perf annotate, plume 256^3 at 1024^2).
    bool node(Walk& w, int d, uint32_t index, const Coord& o, double t0, double t1) const {
        OCTISO_DCHECK(d >= 0 && d <= tree_.dmax() - 2, "interior depth ", d, ", dmax ", tree_.dmax());
        OCTISO_DCHECK(index < tree_.node_count(d), "node ", index, " of ", tree_.node_count(d), " at depth ", d);
        w.trace[d] = index;
        const InteriorNode<T>& n = tree_.node(d, index);
        const uint32_t half = tree_.child_bit(d);
        if constexpr (Recorder::kOn) recorder_.enter_node(d, index, o, 2 * half, t0, t1);
        const uint32_t origin[3] = {o.x, o.y, o.z};
        double tm[3];
        int c = 0;
        for (int a = 0; a < 3; ++a) {
            const double mid = double(origin[a] + half);
            tm[a] = w.ray.plane_t(a, mid);
            if (upper_at(w.ray, a, mid, tm[a], t0)) c |= 4 >> a;
        }
        // Axes in the order the ray crosses their mid-planes (a 3-element sorting network).
        int order[3] = {0, 1, 2};
        if (tm[order[1]] < tm[order[0]]) std::swap(order[0], order[1]);
        if (tm[order[2]] < tm[order[1]]) std::swap(order[1], order[2]);
        if (tm[order[1]] < tm[order[0]]) std::swap(order[0], order[1]);

        double t_cur = t0;
        for (int i = 0; i <= 3; ++i) {
            double t_next = t1;
            if (i < 3 && tm[order[i]] > t0 && tm[order[i]] < t1) t_next = tm[order[i]];
            else if (i < 3) continue;   // this axis is not crossed inside [t0, t1)
            if constexpr (Recorder::kOn)
                if (t_next > t_cur && !n.may_contain_any(c, scene_.isovalues, scene_.iso_count))
                    recorder_.cull(d, c, child_origin_of(o, c, half), half, double(n.min[c]), double(n.max[c]), t_cur,
                                   t_next);
            if (t_next > t_cur && n.may_contain_any(c, scene_.isovalues, scene_.iso_count)) {
                const Coord co{o.x + ((c & 4) ? half : 0), o.y + ((c & 2) ? half : 0), o.z + ((c & 1) ? half : 0)};
                bool hit;
                if (n.is_scalar_leaf(c)) hit = scalar_leaf(w, d, co, half, n.scalar[c], t_cur, t_next);
                else if (d == tree_.dmax() - 2) hit = cap(w, n.child_index(c), co, t_cur, t_next);
                else hit = node(w, d + 1, n.child_index(c), co, t_cur, t_next);
                if (hit) return true;
            }
            if (i == 3) break;
            t_cur = std::max(t_cur, t_next);
            c ^= 4 >> order[i];
        }
        return false;
    }

    bool cap(Walk& w, uint32_t cap_index, const Coord& co, double t0, double t1) const {
        OCTISO_DCHECK(cap_index < tree_.cap_count(), "cap ", cap_index, " of ", tree_.cap_count());
        if constexpr (Recorder::kOn) recorder_.enter_cap(tree_.dmax() - 1, cap_index, co, t0, t1);
        w.trace[tree_.dmax() - 1] = cap_index;
        const Cap<T>& cap = tree_.cap(cap_index);
        // The forward neighbour blocks (2x2x2 at co + 2 * (r>>2&1, r>>1&1, r&1), r = 1..7) are each a
        // cap or lie inside one scalar leaf: located once per cap visit by neighbour finding, on
        // first use, and then read directly for every corner and cell that falls in them.
        LeafRef<T> block[8];
        unsigned located = 0;
        return walk_cells(w, co, 2, t0, t1, [&](Coord v, double corner[8]) {
            if constexpr (!kOwnCorners) {
                corners_.gather(v, corner);
                return;
            }
            const int oct = int(((v.x - co.x) << 2) | ((v.y - co.y) << 1) | (v.z - co.z));
            for (int k = 0; k < 8; ++k) {
                const int dir = ((k & 1) << 2) | (k & 2) | ((k >> 2) & 1);   // corner i+2j+4k -> octant bits
                const int r = oct & dir;                                         // which block holds the corner
                if (r == 0) {
                    corner[k] = double(cap.voxel[oct | dir]);
                    continue;
                }
                if (!((located >> r) & 1u)) {
                    const Coord b{co.x + ((r & 4) ? 2u : 0u), co.y + ((r & 2) ? 2u : 0u), co.z + ((r & 1) ? 2u : 0u)};
                    block[r] = tree_.neighbour_locate(co, b, tree_.dmax() - 1, w.trace);
                    located |= 1u << r;
                }
                corner[k] = block[r].in_cap ? double(tree_.cap(block[r].index).voxel[(oct | dir) & ~r])
                                            : double(block[r].value);
            }
        });
    }

    bool scalar_leaf(Walk& w, int holder_depth, const Coord& co, uint32_t side, T value, double t0, double t1) const {
        const double v = double(value);
        auto gather = [&](Coord p, double corner[8]) {
            if constexpr (!kOwnCorners) {
                corners_.gather(p, corner);
                return;
            }
            const uint32_t ex = co.x + side, ey = co.y + side, ez = co.z + side;
            for (int k = 0; k < 8; ++k) {
                const Coord dest{p.x + (k & 1), p.y + ((k >> 1) & 1), p.z + ((k >> 2) & 1)};
                corner[k] = (dest.x < ex && dest.y < ey && dest.z < ez)
                                ? v
                                : double(tree_.neighbour_find(p, dest, holder_depth, w.trace));
            }
        };
        bool iso_equals_value = false;
        for (int i = 0; i < scene_.iso_count; ++i) iso_equals_value |= scene_.isovalues[i] == v;
        if constexpr (Recorder::kOn) recorder_.scalar_leaf(holder_depth, co, side, v, t0, t1, iso_equals_value);
        if (iso_equals_value) return walk_cells(w, co, side, t0, t1, gather);

        // Skip the inner cells [co, co + side - 1)^3: constant, never crossed by another iso.
        double ti0 = t0, ti1 = t1;
        const uint32_t lo[3] = {co.x, co.y, co.z};
        for (int a = 0; a < 3; ++a) {
            const double p0 = double(lo[a]), p1 = double(lo[a] + side - 1);
            const double d = w.ray.dir[a];
            if (d == 0) {
                if (w.ray.origin[a] < p0 || w.ray.origin[a] >= p1) ti1 = ti0 - 1;   // never inside
                continue;
            }
            const double ta = w.ray.plane_t(a, d > 0 ? p0 : p1), tb = w.ray.plane_t(a, d > 0 ? p1 : p0);
            ti0 = std::max(ti0, ta);
            ti1 = std::min(ti1, tb);
        }
        if (!(ti0 < ti1)) return walk_cells(w, co, side, t0, t1, gather);
        if (ti0 > t0 && walk_cells(w, co, side, t0, ti0, gather)) return true;
        return ti1 < t1 && walk_cells(w, co, side, ti1, t1, gather);
    }

    /// The cells of the box [lo, lo + side)^3 that the ray crosses on [t0, t1), in order, by the
    /// one cell DDA (cell_dda.h). Each data cell gets the half-open piece [t_in, t_out) (closed at
    /// the data exit); `gather` fills its 8 corners. Cells of the box beyond the data (padding)
    /// are stepped over. Returns true at the first hit.
    template <class Gather>
    bool walk_cells(Walk& w, const Coord& lo, uint32_t side, double t0, double t1, Gather&& gather) const {
        const Dims dims = tree_.dims();
        const int64_t last_cell[3] = {int64_t(dims.x) - 2, int64_t(dims.y) - 2, int64_t(dims.z) - 2};
        const DdaBox box{{lo.x, lo.y, lo.z},
                         {int64_t(lo.x) + side, int64_t(lo.y) + side, int64_t(lo.z) + side},
                         {last_cell[0], last_cell[1], last_cell[2]},
                         scene_.box_hi};
        return walk_units(w.ray, UnitCells{}, box, t0, t1, w.t_exit,
                          [&](const int64_t cell[3], double t_in, double t_out, bool closed_end) {
                              if (cell[0] > last_cell[0] || cell[1] > last_cell[1] || cell[2] > last_cell[2])
                                  return false;
                              OCTISO_DCHECK(cell[0] >= 0 && cell[1] >= 0 && cell[2] >= 0, "cell below the data box");
                              const Coord v{uint32_t(cell[0]), uint32_t(cell[1]), uint32_t(cell[2])};
                              double corner[8];
                              gather(v, corner);
                              return test_cell(w, v, corner, t_in, t_out, closed_end);
                          });
    }

    bool test_cell(Walk& w, Coord v, const double corner[8], double t_in, double t_out, bool closed_end) const {
        if constexpr (Recorder::kOn) {
            double lo = corner[0], hi = corner[0];
            for (int k = 1; k < 8; ++k) lo = std::min(lo, corner[k]), hi = std::max(hi, corner[k]);
            recorder_.cell(v, t_in, t_out, closed_end, lo, hi);
            const bool hit = intersect_cell(finder_, scene_, w, v, corner, t_in, t_out, closed_end);
            if (hit) recorder_.root(w.hit.t, w.hit.iso_index);
            return hit;
        }
        return intersect_cell(finder_, scene_, w, v, corner, t_in, t_out, closed_end);
    }

    const Octree<T> tree_;   // a view: cheap to copy, and no dangling reference to a temporary
    const CellWalkScene scene_;
    const Finder finder_;
    [[no_unique_address]] const Corners corners_;
    [[no_unique_address]] const Recorder recorder_;
};

}  // namespace octiso
