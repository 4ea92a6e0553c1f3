// The cell test every cell-walking tracer shares (the octree traversal and the macrocell grid):
// cull by the range of the 8 corners, build the cell-local segment from the integer cell index
// plus a double offset (notes/rootfinding.md E11), take the first root over all isovalues, and
// the normal at it. The hit policies themselves live in roots.h (first_root).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

#include "octiso/inline.h"
#include "octiso/octree.h"
#include "math/hit.h"
#include "math/ray.h"
#include "octiso/limits.h"
#include "render/roots.h"
#include "util/check.h"
#include "util/isa.h"

namespace octiso {
OCTISO_ISA_BEGIN

/// A coordinate that rounding left a hair off a cell face is put exactly on it, so that two
/// cells sharing that face evaluate bitwise the same value there (cell.h) and the half-open
/// rule reports a root on the face exactly once.
/// Written as selects, not early returns: one coordinate of every entry and exit point lies on a
/// face, which axis varies from cell to cell, and the branches it took were mispredicted:
/// 0.970-0.983 x the frame time (min of 7 pairs, medians 0.971-0.999; build_ab_snap_selects.json).
inline double snap_to_face(double p) {
    constexpr double kEps = 1e-12;
    double snapped = std::fabs(p - 1.0) < kEps ? 1.0 : p;
    snapped = std::fabs(p) < kEps ? 0.0 : snapped;
    return snapped;
}

/// What every cell-walking tracer fixes once per render: the isovalues, the placement, and the
/// closed data box [0, n-1]^3 that rays are clipped to (CONVENTIONS 1: only cells inside exist).
struct CellWalkScene {
    double isovalues[kMaxIsovalues] = {};
    int iso_count = 0;
    Placement placement;
    std::array<double, 3> box_hi{};
    bool has_cells = false;   ///< false when an extent is 1: no cell exists, nothing is ever hit

    CellWalkScene(Dims dims, const Placement& p, const double* isos, int count) : iso_count(count), placement(p) {
        // The fixed isovalue array is what every per-cell loop runs over; more would overrun it.
        OCTISO_CHECK(count >= 0 && count <= kMaxIsovalues, count, " isovalues, at most ", kMaxIsovalues);
        for (int i = 0; i < count; ++i) isovalues[i] = isos[i];
        box_hi = {double(dims.x) - 1, double(dims.y) - 1, double(dims.z) - 1};
        has_cells = dims.x >= 2 && dims.y >= 2 && dims.z >= 2;
    }
    bool any_iso_in(double lo, double hi) const {
        for (int i = 0; i < iso_count; ++i)
            if (lo <= isovalues[i] && isovalues[i] <= hi) return true;
        return false;
    }
};

/// A first hit whose cell, isovalue and root bracket are decided, its root not yet refined
/// (nearest_root with kDefer): what the rest of nearest_root needs, kept until finish_hit.
struct PendingHit {
    RootBracket bracket;
    double t_in, t_out;
    std::array<double, 3> p_in, p_out, cell_spacing;
    double corner[8];
};

/// Per-ray state of a cell walk: the index-space ray, where it leaves the data, and the hit so far.
struct RayState {
    IndexRay ray;
    std::array<double, 3> world_dir{};
    double t_exit = 0;
    bool want_normal = false;
    /// hit.iso_index is set, hit.t and hit.normal wait for finish_hit (pending_roots.h).
    bool pending = false;
    TraceHit hit;
    PendingHit later;

    /// Starts `ray_world` in `scene`: returns the piece of its interval [t_min, t_max] inside the
    /// data box, empty on a miss.
    BoxClip start(const CellWalkScene& scene, const Ray& ray_world, bool normal) {
        world_dir = ray_world.dir;
        want_normal = normal;
        if (!scene.has_cells) return {};
        ray = index_from_world(ray_world, scene.placement);
        const BoxClip clip = clip_to_box(ray, scene.box_hi, ray_world);
        t_exit = clip.t_out;
        return clip;
    }
};

/// The ray's t at s of its piece [t_in, t_out), and the cell-local point at s of the segment
/// p_in -> p_out: a hit's place, here and in finish_hits (pending_roots.h), the same arithmetic.
OCTISO_ALWAYS_INLINE double piece_t(double t_in, double t_out, double s) { return t_in + s * (t_out - t_in); }
OCTISO_ALWAYS_INLINE std::array<double, 3> segment_point(const std::array<double, 3>& p_in,
                                                         const std::array<double, 3>& p_out, double s) {
    return {p_in[0] + s * (p_out[0] - p_in[0]), p_in[1] + s * (p_out[1] - p_in[1]), p_in[2] + s * (p_out[2] - p_in[2])};
}

/// The hit at s of the segment p_in -> p_out (the ray piece [t_in, t_out)): its t and, if wanted,
/// its normal (gradient per world unit through `cell_spacing`).
OCTISO_ALWAYS_INLINE void set_hit_at(RayState& w, double s, const double corner[8], const std::array<double, 3>& p_in,
                                     const std::array<double, 3>& p_out, double t_in, double t_out,
                                     const std::array<double, 3>& cell_spacing) {
    w.hit.t = piece_t(t_in, t_out, s);
    if (w.want_normal) w.hit.normal = world_normal(corner, segment_point(p_in, p_out, s), cell_spacing, w.world_dir);
}

/// The nearest root of the isovalues inside [lo, hi] (the corners' range) on the cell-local
/// segment p_in -> p_out, which is the ray piece [t_in, t_out): fills `w.hit` (the normal's
/// gradient per world unit through `cell_spacing`) and returns true, or false with no root.
/// kDefer (Neubauer, one isovalue): a root that needs refining is a hit all the same (its s lies
/// in its bracket, inside [0, 1)), so its refinement, t and normal can wait: `w.later` keeps what
/// they need, w.pending is set, and finish_hit (pending_roots.h) later gives the same hit bit
/// for bit. A packet then refines its lanes' roots four at a time.
/// CornerKind: IntegerCorners where the corners are values of an integer scalar type (cell.h).
template <class Finder, bool kDefer = false, class CornerKind = AnyCorners>
inline bool nearest_root(const Finder& finder, const CellWalkScene& scene, RayState& w, const double corner[8], double lo, double hi,
                         const std::array<double, 3>& p_in, const std::array<double, 3>& p_out, double t_in, double t_out,
                         bool closed_end, const std::array<double, 3>& cell_spacing) {
    // With several isovalues the nearest root needs every root refined, so only one defers.
    constexpr bool kMayDefer = kDefer && std::is_same_v<Finder, Neubauer>;
    RootBracket* later = nullptr;
    if constexpr (kMayDefer)
        if (scene.iso_count == 1) later = &w.later.bracket;
    double best_s = 2.0;
    int best = -1;
    for (int i = 0; i < scene.iso_count; ++i) {
        const double iso = scene.isovalues[i];
        if (!(lo <= iso && iso <= hi)) continue;
        const double s = first_root(finder, corner, iso, p_in, p_out, closed_end, later, CornerKind{});
        // Only with `later`: the one isovalue's root, refined by finish_hit(s) (pending_roots.h).
        // The other instantiations never see kRootPending and compile the test away.
        if (kMayDefer && s == kRootPending) {
            w.pending = true;
            w.hit.iso_index = i;
            PendingHit& h = w.later;
            h.t_in = t_in, h.t_out = t_out, h.p_in = p_in, h.p_out = p_out, h.cell_spacing = cell_spacing;
            std::memcpy(h.corner, corner, sizeof h.corner);
            return true;
        }
        if (s >= 0 && s < best_s) best_s = s, best = i;
    }
    if (best < 0) return false;
    w.hit.iso_index = best;
    set_hit_at(w, best_s, corner, p_in, p_out, t_in, t_out, cell_spacing);
    return true;
}

/// The range [lo, hi] of a cell's 8 corners: the cull every cell test starts with.
OCTISO_ALWAYS_INLINE void corner_range(const double corner[8], double& lo, double& hi) {
    lo = corner[0], hi = corner[0];
    for (int k = 1; k < 8; ++k) lo = std::min(lo, corner[k]), hi = std::max(hi, corner[k]);
}

/// intersect_cell after its cull, for a caller that has the corners' range [lo, hi] already (a
/// packet's cell, culled once for all its lanes): the same root, bit for bit.
template <class Finder, bool kDefer = false, class CornerKind = AnyCorners>
OCTISO_ALWAYS_INLINE bool intersect_cell_in_range(const Finder& finder, const CellWalkScene& scene, RayState& w, const Coord& v,
                                                  const double corner[8], double lo, double hi, double t_in, double t_out,
                                                  bool closed_end) {
    OCTISO_DCHECK(double(v.x) + 1 <= scene.box_hi[0] && double(v.y) + 1 <= scene.box_hi[1] &&
                      double(v.z) + 1 <= scene.box_hi[2],
                  "cell (", v.x, ",", v.y, ",", v.z, ") outside the data box");
    const IndexRay& r = w.ray;
    const std::array<double, 3> o_cell{r.origin[0] - double(v.x), r.origin[1] - double(v.y), r.origin[2] - double(v.z)};
    std::array<double, 3> p_in, p_out;
    for (int a = 0; a < 3; ++a) {
        p_in[a] = snap_to_face(o_cell[a] + t_in * r.dir[a]);
        p_out[a] = snap_to_face(o_cell[a] + t_out * r.dir[a]);
    }
    return nearest_root<Finder, kDefer, CornerKind>(finder, scene, w, corner, lo, hi, p_in, p_out, t_in, t_out,
                                                    closed_end, scene.placement.spacing);
}

/// Tests cell v (lower corner, index space) with corners `corner` (order i + 2j + 4k) on the ray
/// piece [t_in, t_out) ([t_in, t_out] when closed_end). On a hit fills `w.hit` and returns true.
template <class Finder, bool kDefer = false, class CornerKind = AnyCorners>
inline bool intersect_cell(const Finder& finder, const CellWalkScene& scene, RayState& w, const Coord& v,
                           const double corner[8], double t_in, double t_out, bool closed_end) {
    double lo, hi;
    corner_range(corner, lo, hi);
    if (!scene.any_iso_in(lo, hi)) return false;   // a NaN corner fails every comparison
    return intersect_cell_in_range<Finder, kDefer, CornerKind>(finder, scene, w, v, corner, lo, hi, t_in, t_out,
                                                               closed_end);
}

/// Level of detail (lod.h): intersect_cell on the coarse cell with lower corner v and sides
/// `extent` (the lattice unit, cut to the data's last voxel on the upper border), corners at its
/// 8 vertices. The segment is mapped into the unit cube by dividing by the extent, and the
/// normal's gradient is per world unit through spacing x extent. A separate function so that the
/// exact path keeps its arithmetic bit for bit.
template <class Finder, bool kDefer = false, class CornerKind = AnyCorners>
inline bool intersect_coarse_cell(const Finder& finder, const CellWalkScene& scene, RayState& w, const Coord& v,
                                  const uint32_t extent[3], const double corner[8], double t_in, double t_out,
                                  bool closed_end) {
    double lo, hi;
    corner_range(corner, lo, hi);
    if (!scene.any_iso_in(lo, hi)) return false;
    const IndexRay& r = w.ray;
    const double base[3] = {double(v.x), double(v.y), double(v.z)};
    std::array<double, 3> p_in, p_out, cell_spacing;
    for (int a = 0; a < 3; ++a) {
        const double e = double(extent[a]);
        const double o = r.origin[a] - base[a];
        p_in[a] = snap_to_face((o + t_in * r.dir[a]) / e);
        p_out[a] = snap_to_face((o + t_out * r.dir[a]) / e);
        cell_spacing[a] = scene.placement.spacing[a] * e;
    }
    return nearest_root<Finder, kDefer, CornerKind>(finder, scene, w, corner, lo, hi, p_in, p_out, t_in, t_out,
                                                    closed_end, cell_spacing);
}

OCTISO_ISA_END
}  // namespace octiso
