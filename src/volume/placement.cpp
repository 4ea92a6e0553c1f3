// check_placement(): the one test of spacing and origin, made by the readers (conversion), the
// .oct writer and the .oct loader, so extreme placements are refused naming the file instead of
// surfacing later as a complaint about --up or --look (issue 18).
#include <cmath>
#include <cstdio>
#include <string>

#include "octiso/error.h"
#include "octiso/volume.h"

namespace octiso {

namespace {
std::string g(double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.17g", v);
    return b;
}
std::string triple(const std::array<double, 3>& v) { return g(v[0]) + "," + g(v[1]) + "," + g(v[2]); }
}  // namespace

void check_placement(const Placement& p, Dims dims, const std::string& subject, const std::string& hint) {
    const uint32_t n[3] = {dims.x, dims.y, dims.z};
    for (int a = 0; a < 3; ++a) {
        const double s = p.spacing[size_t(a)];
        if (!std::isfinite(s) || !(s > 0))
            throw Error(subject, "spacing must be finite and positive (found " + triple(p.spacing) + ")" + hint);
        if (!(s >= kMinSpacing && s <= kMaxSpacing))
            throw Error(subject, "spacing " + triple(p.spacing) + " is outside [" + g(kMinSpacing) + ", " + g(kMaxSpacing) +
                                     "]" + hint);
    }
    for (int a = 0; a < 3; ++a) {
        const double o = p.origin[size_t(a)];
        if (!std::isfinite(o)) throw Error(subject, "origin must be finite (found " + triple(p.origin) + ")" + hint);
        const double hi = o + double(n[a] > 0 ? n[a] - 1 : 0) * p.spacing[size_t(a)];
        const double extent = std::fmax(std::fabs(o), std::fabs(hi));
        if (!(extent <= kMaxWorldCoordinate))
            throw Error(subject, "the world box (origin " + triple(p.origin) + ", spacing " + triple(p.spacing) +
                                     ") reaches beyond +-" + g(kMaxWorldCoordinate) + hint);
        if (p.spacing[size_t(a)] < std::ldexp(extent, -40))
            throw Error(subject, "spacing " + g(p.spacing[size_t(a)]) + " along " + std::string(1, "xyz"[a]) +
                                     " is too small to resolve voxels at origin " + g(o) + hint);
    }
}

}  // namespace octiso
