// The start of a packet's lanes in the AVX2 kernel, four lanes per instruction: each lane's index
// ray (index_from_world, IndexRay::set_direction) and its piece inside the data box
// (clip_to_box on the ray's own [t_min, t_max]). The same IEEE operations lane by lane as
// RayState::start (divisions, the slab times as products with the reciprocal, std::max/std::min
// as the selects they compile to, no FMA: -ffp-contract=off), so the same numbers bit for bit;
// the branches of the scalar clip (non-finite input, a zero direction component, an empty piece)
// become masks. Why: with no surface in view (ch2better @129.99, 512^2) a frame still cost 12-13
// ms of its 46 at @100.5, and perf put three quarters of trace_packet's own samples in the lanes'
// starts (nine divisions and a dozen branches per ray); the A/B is in BENCHMARKS.md (packet
// section, eleventh session).
#pragma once

#if defined(__AVX2__)

#include <limits>

#include "math/ray.h"
#include "render/cell_hit.h"
#include "render/simd4.h"
#include "util/isa.h"

namespace octiso {
OCTISO_ISA_BEGIN

/// Four lanes' starts by axis: lane j of a group at [a][j].
struct LaneStarts4 {
    V4d origin[3], dir[3], inv_dir[3];
    V4d t_in, t_out;   ///< the box clip; an empty one is (+inf, -inf), BoxClip's default
    V4m given;         ///< -1 where the lane has a ray (k < count, valid[k] != 0)
    V4m live;          ///< -1 where the lane has a ray and its piece is not empty
};

/// Lanes k0 .. k0+3 of `rays` (count rays in all, valid[k] == 0 or k >= count: no ray, an empty
/// piece and a zero index ray, as a lane never started). In a volume without cells
/// (!scene.has_cells) every piece is empty, as RayState::start returns it.
OCTISO_ALWAYS_INLINE void start_four_lanes(const CellWalkScene& scene, const Ray* rays, int k0, int count, const int* valid,
                                           LaneStarts4& out) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    static const Ray kNoRay{};
    const Ray* r[4];
    V4m given{};
    for (int j = 0; j < 4; ++j) {
        const int k = k0 + j;
        const bool on = k < count && (!valid || valid[k]);
        r[j] = on ? &rays[k] : &kNoRay;
        given[j] = on ? -1 : 0;
    }
    const auto lanes = [&](auto field) { return V4d{field(*r[0]), field(*r[1]), field(*r[2]), field(*r[3])}; };
    const V4d zero{}, inf4{inf, inf, inf, inf};
    const auto finite = [](V4d x) { return (x - x) == V4d{}; };   // false for +-inf and NaN

    // index_from_world and set_direction.
    for (int a = 0; a < 3; ++a) {
        const double s = scene.placement.spacing[a], o = scene.placement.origin[a];
        const V4d ow = lanes([a](const Ray& ray) { return ray.origin[a]; });
        const V4d dw = lanes([a](const Ray& ray) { return ray.dir[a]; });
        const V4d so{s, s, s, s}, oo{o, o, o, o};
        out.origin[a] = (ow - oo) / so;
        const V4d d = dw / so;
        const V4d one{1.0, 1.0, 1.0, 1.0};
        const V4d inv = d == zero ? zero : one / d;
        const V4m flush = ~finite(inv);   // a reciprocal that overflows: the axis counts as parallel
        out.dir[a] = flush ? zero : d;
        out.inv_dir[a] = flush ? zero : inv;
    }

    // clip_to_box(ray, box_hi, ray_world).
    const V4d t_min = lanes([](const Ray& ray) { return ray.t_min; });
    const V4d t_max = lanes([](const Ray& ray) { return ray.t_max; });
    V4m live = given & (t_min <= t_max);
    if (!scene.has_cells) live = V4m{};
    V4d t_in = t_min, t_out = inf4;
    for (int a = 0; a < 3; ++a) {
        const double hi = scene.box_hi[a];
        if (!(hi >= 0)) live = V4m{};
        const V4d o = out.origin[a], d = out.dir[a], inv = out.inv_dir[a];
        const V4d hi4{hi, hi, hi, hi};
        live &= finite(o) & finite(d);
        const V4m parallel = d == zero;
        live &= ~(parallel & ((o < zero) | (o > hi4)));
        const V4m up = d > zero;
        const V4d t_lo = ((up ? zero : hi4) - o) * inv;
        const V4d t_hi = ((up ? hi4 : zero) - o) * inv;
        t_in = (~parallel & (t_in < t_lo)) ? t_lo : t_in;     // std::max(t_in, t_lo)
        t_out = (~parallel & (t_hi < t_out)) ? t_hi : t_out;  // std::min(t_out, t_hi)
    }
    live &= finite(t_in) & finite(t_out) & (t_in <= t_out);
    t_out = t_max < t_out ? t_max : t_out;
    live &= t_in <= t_out;
    out.t_in = live ? t_in : inf4;
    out.t_out = live ? t_out : -inf4;
    out.given = given;
    out.live = live;
    for (int a = 0; a < 3; ++a) {   // a lane never started keeps a zero index ray
        out.origin[a] = given ? out.origin[a] : zero;
        out.dir[a] = given ? out.dir[a] : zero;
        out.inv_dir[a] = given ? out.inv_dir[a] : zero;
    }
}

OCTISO_ISA_END
}  // namespace octiso

#endif
