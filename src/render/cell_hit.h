// The cell test every cell-walking tracer shares (the octree traversal and the macrocell grid):
// cull by the range of the 8 corners, build the cell-local segment from the integer cell index
// plus a double offset (notes/rootfinding.md E11), take the first root over all isovalues, and
// the normal at it. The hit policies themselves live in roots.h (first_root).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "octiso/octree.h"
#include "render/ray.h"
#include "render/roots.h"

namespace octiso {

struct TraceHit {
    double t = std::numeric_limits<double>::infinity();   ///< world distance; +inf: miss
    std::array<double, 3> normal{0, 0, 0};
    int iso_index = -1;
    bool is_hit() const { return iso_index >= 0; }
};

/// A coordinate that rounding left a hair off a cell face is put exactly on it, so that two
/// cells sharing that face evaluate bitwise the same value there (cell.h) and the half-open
/// rule reports a root on the face exactly once.
inline double snap_to_face(double p) {
    constexpr double kEps = 1e-12;
    if (std::fabs(p) < kEps) return 0.0;
    if (std::fabs(p - 1.0) < kEps) return 1.0;
    return p;
}

/// What a cell test needs besides the cell: the isovalues, the index-space ray, and for normals
/// the spacing and the world direction.
struct CellQuery {
    const double* isovalues;
    int iso_count;
    const IndexRay* ray;
    const std::array<double, 3>* spacing;
    const std::array<double, 3>* world_dir;
    bool want_normal;
};

/// Tests cell v (lower corner, index space) with corners `corner` (order i + 2j + 4k) on the ray
/// piece [t_in, t_out) ([t_in, t_out] when closed_end). On a hit fills `hit` and returns true.
template <class Finder>
inline bool intersect_cell(const Finder& finder, const CellQuery& q, const Coord& v, const double corner[8], double t_in,
                           double t_out, bool closed_end, TraceHit& hit) {
    double lo = corner[0], hi = corner[0];
    for (int k = 1; k < 8; ++k) lo = std::min(lo, corner[k]), hi = std::max(hi, corner[k]);
    bool any = false;   // a NaN corner fails every comparison, so such a cell is never tested
    for (int i = 0; i < q.iso_count; ++i) any |= lo <= q.isovalues[i] && q.isovalues[i] <= hi;
    if (!any) return false;
    const IndexRay& r = *q.ray;
    const std::array<double, 3> o_cell{r.origin[0] - double(v.x), r.origin[1] - double(v.y), r.origin[2] - double(v.z)};
    std::array<double, 3> p_in, p_out;
    for (int a = 0; a < 3; ++a) {
        p_in[a] = snap_to_face(o_cell[a] + t_in * r.dir[a]);
        p_out[a] = snap_to_face(o_cell[a] + t_out * r.dir[a]);
    }
    double best_s = 2.0;
    int best = -1;
    for (int i = 0; i < q.iso_count; ++i) {
        if (!(lo <= q.isovalues[i] && q.isovalues[i] <= hi)) continue;
        const double s = first_root(finder, corner, q.isovalues[i], p_in, p_out, closed_end);
        if (s >= 0 && s < best_s) best_s = s, best = i;
    }
    if (best < 0) return false;
    hit.t = t_in + best_s * (t_out - t_in);
    hit.iso_index = best;
    if (q.want_normal) {
        std::array<double, 3> p_hit;
        for (int a = 0; a < 3; ++a) p_hit[a] = p_in[a] + best_s * (p_out[a] - p_in[a]);
        hit.normal = world_normal(corner, p_hit, *q.spacing, *q.world_dir);
    }
    return true;
}

}  // namespace octiso
