// Clip planes (issue 17 item 7, `--clip`): the interval [t_min, t_max] of a world ray cut to the
// half-spaces n . p <= d before traversal, so a cut-open volume is traced by the unchanged exact
// tracer (math/ray.h, Ray) and the reference sees the same interval. The Renderer clips primary
// rays, the secondary rays (render/secondary.h) are clipped the same way: what is cut away
// neither shows nor casts a shadow. Pure arithmetic, no allocation.
#pragma once

#include <algorithm>
#include <limits>
#include <span>

#include "math/ray.h"
#include "math/vec.h"
#include "octiso/render.h"

namespace octiso {

/// Narrows `ray.t_min`/`ray.t_max` (world distance along the unit direction) to the points
/// p(t) = origin + t dir with n . p(t) <= d for every plane: the kept set is closed, so a point on
/// a plane stays. A ray parallel to a plane (n . dir == 0, +-0 included) keeps all of it or none.
/// An emptied interval is left with t_min > t_max (a miss for every tracer).
inline void clip_ray(std::span<const ClipPlane> planes, Ray& ray) {
    for (const ClipPlane& c : planes) {
        const double s0 = vec_dot(c.normal, ray.origin) - c.d;   // > 0: the origin is cut away
        const double s1 = vec_dot(c.normal, ray.dir);
        if (s1 == 0) {
            if (s0 > 0) ray.t_min = std::numeric_limits<double>::infinity(), ray.t_max = -std::numeric_limits<double>::infinity();
            continue;
        }
        const double t = -s0 / s1;   // where the ray crosses the plane
        if (s1 > 0) ray.t_max = std::min(ray.t_max, t);   // leaving the kept side
        else ray.t_min = std::max(ray.t_min, t);          // entering it
    }
}

/// Where a ray enters the kept set through one of the planes (--clip-cap, api/clip_cap.cpp):
/// `t` is the t_min clip_ray() leaves and `plane` the index of the plane that set it, or -1 when no
/// plane did (the ray starts on the kept side of every entering plane) or the kept interval is
/// empty. The same arithmetic as clip_ray, so `t` is its t_min bit for bit.
struct ClipEntry {
    double t = 0;
    int plane = -1;
};

inline ClipEntry clip_entry(std::span<const ClipPlane> planes, const Ray& ray) {
    ClipEntry e{ray.t_min, -1};
    double t_max = ray.t_max;
    for (size_t i = 0; i < planes.size(); ++i) {
        const ClipPlane& c = planes[i];
        const double s0 = vec_dot(c.normal, ray.origin) - c.d;
        const double s1 = vec_dot(c.normal, ray.dir);
        if (s1 == 0) {
            if (s0 > 0) return {std::numeric_limits<double>::infinity(), -1};
            continue;
        }
        const double t = -s0 / s1;
        if (s1 > 0) t_max = std::min(t_max, t);
        else if (t > e.t) e = {t, int(i)};   // std::max in clip_ray: a tie keeps the earlier plane's t, the same value
    }
    if (!(e.t <= t_max)) e.plane = -1;
    return e;
}

}  // namespace octiso
