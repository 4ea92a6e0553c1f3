// The one cell DDA (Amanatides & Woo 1987) every cell-walking tracer steps with: the octree's cap
// and scalar-leaf walks (traverse.h, unit cells) and every level of the macrocell grid
// (macrocell.h, units of B^l cells). It owns the first unit from t0, with the rounding of
// p(t0) settled against the same plane times the stepping uses, and the stepping itself; what a
// visited unit means (a cell to solve, a macrocell to cull or enter) is the caller's `visit`.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "math/ray.h"
#include "util/isa.h"

namespace octiso {
OCTISO_ISA_BEGIN

/// Unit cells: unit i spans the index planes [i, i + 1]. No multiply or divide in the loop.
struct UnitCells {
    double plane(int64_t i) const { return double(i); }
    int64_t unit_of(double p) const { return int64_t(std::floor(p)); }
};

/// Units of `u` cells (a macrocell level, u = B^l): unit i spans the planes [i u, (i + 1) u].
/// With u == 1 every plane and unit equals UnitCells' bit for bit (x * 1.0 and x / 1.0 are exact).
struct ScaledCells {
    double u = 1;
    double plane(int64_t i) const { return double(i) * u; }
    int64_t unit_of(double p) const { return int64_t(std::floor(p / u)); }
};

/// The box of units a walk may visit, [lo, hi) per axis (hi exclusive, lo < hi), and where a ray
/// lying in the data's top face is put: a ray with dir[a] == 0 and p[a] == box_hi[a] lies on the
/// upper plane of the last data unit, top_unit[a] (the data box is closed, CONVENTIONS 2b), not in
/// the unit above it.
struct DdaBox {
    int64_t lo[3], hi[3];
    int64_t top_unit[3];
    std::array<double, 3> box_hi;
};

/// Walks the units of `box` that `r` crosses on [t0, t1), in order. Each is handed to
/// `visit(const int64_t unit[3], double t_in, double t_out, bool closed_end) -> bool` with its
/// piece [t_in, t_out) of the ray, or [t_in, t_out] when closed_end (t_out == t_exit, the data
/// exit: the last unit owns it). Empty pieces are skipped unless closed_end. Returns true as soon
/// as a visit does (a hit), false when the ray leaves the box or reaches t1.
/// Every face time is IndexRay::plane_t of units.plane(i), the expression the octree traversal
/// and the reference use, so units abut exactly and no piece of the ray is lost or doubled.
template <class Units, class Visit>
inline bool walk_units(const IndexRay& r, const Units& units, const DdaBox& box, double t0, double t1, double t_exit,
                       Visit&& visit) {
    int64_t unit[3];
    for (int a = 0; a < 3; ++a) {
        const double p = r.origin[a] + t0 * r.dir[a];
        int64_t i = units.unit_of(p);
        if (r.dir[a] == 0 && p == box.box_hi[a]) i = box.top_unit[a];   // lying in the top face
        const int64_t b0 = box.lo[a], b1 = box.hi[a] - 1;
        i = std::clamp(i, b0, b1);
        // Settle rounding of p at a unit face with the same plane times the stepping uses.
        if (r.dir[a] > 0) {
            if (i < b1 && r.plane_t(a, units.plane(i + 1)) <= t0) ++i;
            else if (i > b0 && r.plane_t(a, units.plane(i)) > t0) --i;
        } else if (r.dir[a] < 0) {   // unit i holds [plane_t(i+1), plane_t(i))
            if (i > b0 && r.plane_t(a, units.plane(i)) <= t0) --i;
            else if (i < b1 && r.plane_t(a, units.plane(i + 1)) > t0) ++i;
        }
        unit[a] = i;
    }
    double t_cur = t0;
    for (;;) {
        double t_face[3];
        for (int a = 0; a < 3; ++a)
            t_face[a] = r.dir[a] > 0 ? r.plane_t(a, units.plane(unit[a] + 1))
                      : r.dir[a] < 0 ? r.plane_t(a, units.plane(unit[a]))
                                     : std::numeric_limits<double>::infinity();
        int axis = 0;
        if (t_face[1] < t_face[axis]) axis = 1;
        if (t_face[2] < t_face[axis]) axis = 2;
        const double t_out = std::min(t_face[axis], t1);
        const bool closed_end = t_out == t_exit;
        if ((t_out > t_cur || closed_end) && visit(unit, t_cur, t_out, closed_end)) return true;
        if (t_face[axis] >= t1) return false;
        t_cur = std::max(t_cur, t_face[axis]);
        unit[axis] += r.dir[axis] > 0 ? 1 : -1;
        if (unit[axis] < box.lo[axis] || unit[axis] >= box.hi[axis]) return false;
    }
}

OCTISO_ISA_END
}  // namespace octiso
