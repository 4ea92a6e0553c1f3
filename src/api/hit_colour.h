// What colour a hit has, shared by the deferred shading of shading.cpp and the ray-traced look
// of look.cpp: the isovalue a hit shows, read back from the field at its hit point (a depth and a
// normal AOV do not say which surface they are), and that isovalue's albedo.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "math/ray.h"
#include "math/vec.h"
#include "octiso/clip_cap.h"
#include "octiso/octree.h"
#include "octiso/shading.h"
#include "render/clip.h"
#include "render/shade.h"

namespace octiso {

/// The trilinear interpolant at world point `p` (CONVENTIONS 1), clamped into the data's cells.
template <typename T> inline double field_at(const Octree<T>& tree, const Placement& placement, const Vec3& p) {
    const uint32_t n[3] = {tree.dims().x, tree.dims().y, tree.dims().z};
    uint32_t lo[3], hi[3];
    double f[3];
    for (int a = 0; a < 3; ++a) {
        const double q = (p[a] - placement.origin[a]) / placement.spacing[a];
        const double top = double(n[a] > 1 ? n[a] - 2 : 0);
        const double cell = std::isfinite(q) ? std::clamp(std::floor(q), 0.0, top) : 0.0;
        lo[a] = uint32_t(cell);
        hi[a] = n[a] > 1 ? lo[a] + 1 : lo[a];
        f[a] = n[a] > 1 && std::isfinite(q) ? std::clamp(q - cell, 0.0, 1.0) : 0.0;
    }
    double v = 0;
    for (int c = 0; c < 8; ++c) {
        const Coord at{(c & 4) ? hi[0] : lo[0], (c & 2) ? hi[1] : lo[1], (c & 1) ? hi[2] : lo[2]};
        const double w = ((c & 4) ? f[0] : 1 - f[0]) * ((c & 2) ? f[1] : 1 - f[1]) * ((c & 1) ? f[2] : 1 - f[2]);
        v += w * double(tree.point_locate(at));
    }
    return v;
}

/// Index of the isovalue nearest to v.
inline int nearest_isovalue(double v, const std::vector<double>& isovalues) {
    int best = 0;
    for (int i = 1; i < int(isovalues.size()); ++i)
        if (std::fabs(v - isovalues[size_t(i)]) < std::fabs(v - isovalues[size_t(best)])) best = i;
    return best;
}

/// The isovalue a hit at depth `t` (the AOV's float) along the primary `ray` (unclipped) shows: the
/// nearest to the field there; on a cap of `cap` (the ray enters through a plane at that very t,
/// clip_cap.h) the innermost isovalue whose inside holds the point, as cap_clip_planes chose it.
template <typename T>
inline int shown_isovalue(const Octree<T>& tree, const Placement& placement, const std::vector<double>& isovalues, const Ray& ray,
                          float t, const ClipCap* cap) {
    if (isovalues.size() < 2) return 0;
    const Vec3 p{ray.origin[0] + double(t) * ray.dir[0], ray.origin[1] + double(t) * ray.dir[1], ray.origin[2] + double(t) * ray.dir[2]};
    const double v = field_at(tree, placement, p);
    if (cap) {
        const ClipEntry entry = clip_entry(cap->planes, ray);
        if (entry.plane >= 0 && float(entry.t) == t)
            if (const int inner = cap_isovalue(v, isovalues, cap->inside_above); inner >= 0) return inner;
    }
    return nearest_isovalue(v, isovalues);
}

/// The linear albedo of isovalue `iso`: the caller's colour where given, else the palette's.
inline const float* albedo_of(const Shading& shading, int iso) {
    return size_t(iso) < shading.colours.size() && shading.colours[size_t(iso)] ? shading.colours[size_t(iso)]->data()
                                                                                : kAlbedo[iso % kMaxIsovalues];
}

}  // namespace octiso
