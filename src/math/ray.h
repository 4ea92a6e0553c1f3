// Rays in world and index space and their clip to the data box, shared by the octree renderer
// and the brute-force reference tracer so both see exactly the same interval [t_in, t_out].
// Index space: voxel (i,j,k) at (i,j,k); the index ray keeps the world parameter t (the direction
// is divided by the spacing and NOT renormalised), so t is world distance along the unit ray.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "octiso/volume.h"
#include "util/isa.h"

namespace octiso {

/// World-space ray: origin and unit direction (CONVENTIONS 2). Components may be +-0.
/// [t_min, t_max] is the piece of the ray a tracer may hit (world distance, closed); the default
/// [0, +inf] is a primary ray as CONVENTIONS 2b defines it. Secondary rays start at t_min > 0
/// (render/secondary.h) and clip planes narrow the interval before traversal (render/clip.h);
/// t_min > t_max is an empty ray, never hit.
struct Ray {
    std::array<double, 3> origin{};
    std::array<double, 3> dir{};
    double t_min = 0.0;
    double t_max = std::numeric_limits<double>::infinity();
};

/// The same ray in index space: p_index(t) = origin + t * dir, t the world distance.
struct IndexRay {
    std::array<double, 3> origin{};
    std::array<double, 3> dir{};
    std::array<double, 3> inv_dir{};   ///< 1/dir, 0 where dir is +-0 (never used there)

    /// t at which the ray crosses the plane p[axis] == plane; +inf ("never") when dir[axis] is
    /// +0 or -0, so no 0 * inf or 0/0 ever reaches a caller. A multiplication by the reciprocal,
    /// not a division: every tracer calls this one function, so all agree on each boundary t.
    OCTISO_ALWAYS_INLINE double plane_t(int axis, double plane) const {
        if (dir[axis] == 0) return std::numeric_limits<double>::infinity();
        return (plane - origin[axis]) * inv_dir[axis];
    }

    OCTISO_ALWAYS_INLINE static IndexRay make(const std::array<double, 3>& o, const std::array<double, 3>& d) {
        IndexRay r;
        r.origin = o;
        r.set_direction(d);
        return r;
    }
    /// A component whose reciprocal overflows (|d| < 2^-1024, subnormal) is flushed to +0: such a
    /// ray needs t > 1e300 to cross one cell, so it is parallel to that axis for every purpose, and
    /// flushing keeps 0 * inf (a NaN) out of plane_t.
    OCTISO_ALWAYS_INLINE void set_direction(const std::array<double, 3>& d) {
        dir = d;
        for (int a = 0; a < 3; ++a) {
            inv_dir[a] = d[a] == 0 ? 0.0 : 1.0 / d[a];
            if (!std::isfinite(inv_dir[a])) dir[a] = 0.0, inv_dir[a] = 0.0;
        }
    }
};

OCTISO_ALWAYS_INLINE IndexRay index_from_world(const Ray& ray_world, const Placement& placement) {
    IndexRay r;
    std::array<double, 3> d;
    for (int a = 0; a < 3; ++a) {
        r.origin[a] = (ray_world.origin[a] - placement.origin[a]) / placement.spacing[a];
        d[a] = ray_world.dir[a] / placement.spacing[a];
    }
    r.set_direction(d);
    return r;
}

/// The part [t_in, t_out] of the ray with t >= t_min inside the closed box [0, box_hi] (per axis).
/// empty() when the ray misses it, any input is non-finite or the direction is zero. A ray that only touches the box
/// (edge, corner, or lying in a face) gets t_in == t_out or a segment in the face: closed box.
/// For each axis, the slab crossing times are exactly IndexRay::plane_t(axis, 0 or box_hi), the
/// same expression a DDA uses for its cell faces, so callers can recognise face crossings by ==.
struct BoxClip {
    double t_in = std::numeric_limits<double>::infinity();
    double t_out = -std::numeric_limits<double>::infinity();
    OCTISO_ALWAYS_INLINE bool empty() const { return !(t_in <= t_out); }
};

OCTISO_ALWAYS_INLINE BoxClip clip_to_box(const IndexRay& ray, const std::array<double, 3>& box_hi, double t_min = 0.0) {
    BoxClip clip;
    double t_in = t_min, t_out = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        const double o = ray.origin[a], d = ray.dir[a];
        if (!std::isfinite(o) || !std::isfinite(d) || !(box_hi[a] >= 0)) return clip;
        if (d == 0) {   // parallel to the slab: inside it for all t, or never
            if (o < 0 || o > box_hi[a]) return clip;
            continue;
        }
        const double t_lo = ray.plane_t(a, d > 0 ? 0.0 : box_hi[a]);
        const double t_hi = ray.plane_t(a, d > 0 ? box_hi[a] : 0.0);
        // Never NaN here (o and d are finite, plane_t of them is finite or never called with
        // d == 0), where std::max/min equal fmax/fmin without their library calls.
        t_in = std::max(t_in, t_lo);
        t_out = std::min(t_out, t_hi);
    }
    if (!std::isfinite(t_in) || !std::isfinite(t_out) || !(t_in <= t_out)) return clip;   // dir == 0: no ray
    clip.t_in = t_in, clip.t_out = t_out;
    return clip;
}

/// clip_to_box on the ray's own interval [ray_world.t_min, ray_world.t_max] (math/ray.h, Ray).
/// For the default interval it is clip_to_box(ray, box_hi) bit for bit: t_min 0 is the old lower
/// bound and min(t_out, +inf) == t_out. A t_max inside the box ends the piece there, and that end
/// is closed like the data exit (the cell holding it owns t_max, CONVENTIONS 2b).
OCTISO_ALWAYS_INLINE BoxClip clip_to_box(const IndexRay& ray, const std::array<double, 3>& box_hi, const Ray& ray_world) {
    if (!(ray_world.t_min <= ray_world.t_max)) return {};   // empty, or NaN bounds
    BoxClip clip = clip_to_box(ray, box_hi, ray_world.t_min);
    if (clip.empty()) return clip;
    if (ray_world.t_max < clip.t_out) clip.t_out = ray_world.t_max;
    if (!(clip.t_in <= clip.t_out)) return {};
    return clip;
}

}  // namespace octiso
