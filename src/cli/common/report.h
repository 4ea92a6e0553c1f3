// What the tools' text reports share: numbers printed as people write them ({fmt}'s shortest form
// that reads back to the same double, never "-500.000000"), and the world box of a placed grid.
#pragma once

#include <algorithm>
#include <array>
#include <string>

#include <fmt/format.h>

#include "octiso/volume.h"

namespace octiso::cli {

/// The shortest decimal text that parses back to `v` exactly ("0.5", "-500", "1e-07").
inline std::string number(double v) { return fmt::format("{}", v); }

/// "X, Y, Z" with number() for each component.
inline std::string numbers(const std::array<double, 3>& v) { return number(v[0]) + ", " + number(v[1]) + ", " + number(v[2]); }

/// The world box spanned by the voxel positions (CONVENTIONS 1: voxel i at origin + i * spacing),
/// lowest and highest corner, and its centre (what the default cameras look at).
struct WorldBox {
    std::array<double, 3> lo, hi, centre;
};
inline WorldBox world_box(Dims dims, const Placement& p) {
    WorldBox b;
    const uint32_t n[3] = {dims.x, dims.y, dims.z};
    for (int a = 0; a < 3; ++a) {
        const double end = p.origin[a] + double(n[a] > 0 ? n[a] - 1 : 0) * p.spacing[a];
        b.lo[a] = std::min(p.origin[a], end);
        b.hi[a] = std::max(p.origin[a], end);
        b.centre[a] = 0.5 * (b.lo[a] + b.hi[a]);
    }
    return b;
}

}  // namespace octiso::cli
