// The refinement nearest_root<Finder, kDefer> leaves for later (cell_hit.h): one ray's (finish_hit)
// or a packet's lanes', four at a time in one AVX2 register (finish_hits). Why: the refinement is a
// chain of dependent divisions and Horner steps with a branch per step that the predictor cannot
// learn; four chains side by side in SIMD hide its latency and lose the branches. Each lane's
// arithmetic is the scalar one (the same operations in the same order, no FMA: simd4.h), so the
// hits are Neubauer::refine's bit for bit.
#pragma once

#include <algorithm>
#include <bit>
#include <type_traits>

#include "render/cell_hit.h"
#include "render/roots.h"
#include "render/simd4.h"

#if defined(__AVX2__)
#include <immintrin.h>   // _mm256_sqrt_pd
#endif
#include "util/isa.h"

namespace octiso {
OCTISO_ISA_BEGIN

/// nearest_root's tail for a deferred hit, given the refined root s of its bracket.
OCTISO_ALWAYS_INLINE void finish_hit_at(RayState& w, double refined) {
    const PendingHit& h = w.later;
    const double s = roots_detail::into_bracket(refined, h.bracket.a, h.bracket.b);
    set_hit_at(w, s, h.corner, h.p_in, h.p_out, h.t_in, h.t_out, h.cell_spacing);
    w.pending = false;
}

/// The hit of a ray whose root nearest_root<Finder, true> left pending (w.pending).
/// Only Neubauer defers (nearest_root), so only its w.pending is ever set.
template <class Finder> inline void finish_hit(const Finder& finder, RayState& w) {
    if constexpr (std::is_same_v<Finder, Neubauer>) {
        const RootBracket& b = w.later.bracket;
        CellCubic<double> f{};
        std::copy(b.c, b.c + 4, f.c);
        finish_hit_at(w, finder.refine(f, b.a, b.fa, b.b, b.fb));
    }
}

#if defined(__AVX2__)
/// Neubauer::refine on four brackets at once: lane by lane its steps, its Illinois halvings and its
/// two early exits (a root hit exactly, a collapsed bracket), as masks.
inline V4d neubauer_refine4(int iterations, const V4d c[4], V4d a, V4d fa, V4d b, V4d fb) {
    const V4d zero{0, 0, 0, 0}, half{0.5, 0.5, 0.5, 0.5};
    const V4l kept_a{1, 1, 1, 1}, kept_b{-1, -1, -1, -1};
    V4l kept{0, 0, 0, 0};   // as Neubauer::refine's `kept`: +1 a was kept last step, -1 b was
    V4l live{-1, -1, -1, -1}, exact{0, 0, 0, 0};
    V4d exact_s = zero;
    for (int it = 0; it < iterations; ++it) {
        V4d s = a + (b - a) * (fa / (fa - fb));
        s = V4l(s < a) ? a : (V4l(b < s) ? b : s);   // std::clamp(s, a, b)
        const V4d fs = ((c[3] * s + c[2]) * s + c[1]) * s + c[0];
        const V4l root = V4l(fs == zero) & live;
        exact_s = root ? s : exact_s;
        exact |= root;
        live &= ~root;
        // sign(fs) == sign(fa), the signs compared, never multiplied.
        const V4l same = ~(V4l(fs > zero) ^ V4l(fa > zero)) & ~(V4l(fs < zero) ^ V4l(fa < zero));
        const V4l to_a = same & live, to_b = ~same & live;
        fb = (to_a & V4l(kept == kept_b)) ? fb * half : fb;
        fa = (to_b & V4l(kept == kept_a)) ? fa * half : fa;
        a = to_a ? s : a, fa = to_a ? fs : fa;
        b = to_b ? s : b, fb = to_b ? fs : fb;
        kept = to_a ? kept_b : (to_b ? kept_a : kept);
        live &= V4l(a < b);
        if (!(live[0] | live[1] | live[2] | live[3])) break;
    }
    const V4d last = a + (b - a) * (fa / (fa - fb));
    return exact ? exact_s : last;
}

/// world_normal (roots.h) for four hits at once, step by step its arithmetic: corners c[8], the
/// cell-local points p[3], the spacings and world directions by axis. Returns the lanes whose
/// normal is in n[3]: those on world_normal's common path. The others (a zero, huge or
/// non-finite gradient or corner scale, a subnormal corner maximum) need world_normal itself.
inline V4l world_normal4(const V4d c[8], const V4d p[3], const V4d spacing[3], const V4d dir[3], V4d n[3]) {
    using V4u = unsigned long long __attribute__((vector_size(32)));
    const V4d zero{0, 0, 0, 0};
    const V4l magnitude{0x7fffffffffffffffLL, 0x7fffffffffffffffLL, 0x7fffffffffffffffLL, 0x7fffffffffffffffLL};
    const auto abs4 = [&](V4d x) OCTISO_LAMBDA_INLINE { return V4d(V4l(x) & magnitude); };
    const auto exponent_field = [](V4d x) OCTISO_LAMBDA_INLINE { return V4l((V4u(x) >> 52) & 0x7ff); };
    const auto lerp = [](V4d a, V4d b, V4d t) OCTISO_LAMBDA_INLINE { return a * (1.0 - t) + b * t; };   // cell_lerp
    // 1. The corners scaled by 2^(-e-2), e the exponent of their largest magnitude (frexp).
    V4d big_c = zero;
    for (int i = 0; i < 8; ++i) {
        const V4d x = abs4(c[i]);
        big_c = V4l(big_c < x) ? x : big_c;   // std::max(big_c, x)
    }
    const V4l biased = exponent_field(big_c);
    // Finite, > 0, a normal number (frexp_exponent from the bits) and -e-2 inside the range
    // scale_by_power_of_two multiplies in: e = biased - 1022, -e-2 > -1000.
    V4l ok = V4l(big_c > zero) & V4l(biased != 0) & V4l(biased < 2020);
    const V4d factor = V4d(V4u(2043 - biased) << 52);   // 2^(-e-2): its exponent field -e-2+1023
    V4d s[8];
    for (int i = 0; i < 8; ++i) s[i] = c[i] * factor;
    // 2. gradient() (cell.h) at p.
    const V4d x = p[0], y = p[1], z = p[2];
    const V4d g[3] = {lerp(lerp(s[1] - s[0], s[3] - s[2], y), lerp(s[5] - s[4], s[7] - s[6], y), z),
                      lerp(lerp(s[2] - s[0], s[3] - s[1], x), lerp(s[6] - s[4], s[7] - s[5], x), z),
                      lerp(lerp(s[4] - s[0], s[5] - s[1], x), lerp(s[6] - s[2], s[7] - s[3], x), y)};
    // 3. Per world unit, up to 1/s_min; scaled by the largest component, normalised, facing the ray.
    const V4d s12 = V4l(spacing[2] < spacing[1]) ? spacing[2] : spacing[1];   // fmin of positive spacings
    const V4d s_min = V4l(s12 < spacing[0]) ? s12 : spacing[0];
    V4d big = zero;
    for (int a = 0; a < 3; ++a) {
        n[a] = g[a] * (s_min / spacing[a]);
        ok &= V4l(exponent_field(n[a]) != 0x7ff);   // finite
        const V4d m = abs4(n[a]);
        big = V4l(big < m) ? m : big;
    }
    ok &= V4l(big > zero);
    for (int a = 0; a < 3; ++a) n[a] = n[a] / big;
    const V4d len = V4d(_mm256_sqrt_pd(__m256d(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])));
    const V4d dot = n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2];
    const V4d flip = V4l(dot > zero) ? V4d{-1, -1, -1, -1} : V4d{1, 1, 1, 1};
    const V4d scale = flip / len;
    for (int a = 0; a < 3; ++a) {
        n[a] = n[a] * scale;
        ok &= V4l(exponent_field(n[a]) != 0x7ff);
    }
    return ok;
}
#endif

/// finish_hit for every lane in `lanes` of lane[] (each with w.pending set): Neubauer's
/// refinements four at a time in the AVX2 kernel, one by one otherwise.
template <class Finder, class Lane> inline void finish_hits(const Finder& finder, Lane* lane, unsigned lanes) {
#if defined(__AVX2__)
    if constexpr (std::is_same_v<Finder, Neubauer>) {
        while (std::popcount(lanes) >= 2) {
            int k[4] = {};
            int n = 0;
            for (; n < 4 && lanes; ++n) k[n] = std::countr_zero(lanes), lanes &= lanes - 1;
            for (int i = n; i < 4; ++i) k[i] = k[0];   // a short group repeats its first lane
            double by_part[8][4];   // c0..c3, a, fa, b, fb of the four lanes
            for (int i = 0; i < 4; ++i) {
                const RootBracket& r = lane[k[i]].later.bracket;
                const double part[8] = {r.c[0], r.c[1], r.c[2], r.c[3], r.a, r.fa, r.b, r.fb};
                for (int j = 0; j < 8; ++j) by_part[j][i] = part[j];
            }
            V4d v[8];
            for (int j = 0; j < 8; ++j) load4(v[j], by_part[j]);
            const V4d refined = neubauer_refine4(finder.iterations, v, v[4], v[5], v[6], v[7]);
            // nearest_root's tail (set_hit_at) with the normals four at a time where all four want
            // one; world_normal itself for a lane off world_normal4's common path.
            double by_axis[17][4];   // the hits' points, their corners, spacings, world directions
            bool normals = true;
            for (int i = 0; i < 4; ++i) {
                RayState& w = lane[k[i]];
                const PendingHit& h = w.later;
                const double s = roots_detail::into_bracket(refined[i], h.bracket.a, h.bracket.b);
                w.hit.t = piece_t(h.t_in, h.t_out, s);
                normals &= w.want_normal;
                const std::array<double, 3> p = segment_point(h.p_in, h.p_out, s);
                for (int a = 0; a < 3; ++a) {
                    by_axis[a][i] = p[a];
                    by_axis[11 + a][i] = h.cell_spacing[a];
                    by_axis[14 + a][i] = w.world_dir[a];
                }
                for (int j = 0; j < 8; ++j) by_axis[3 + j][i] = h.corner[j];
            }
            V4d normal[3] = {};
            V4l ok{0, 0, 0, 0};
            if (normals) {
                V4d in[17];
                for (int j = 0; j < 17; ++j) load4(in[j], by_axis[j]);
                ok = world_normal4(in + 3, in, in + 11, in + 14, normal);
            }
            for (int i = 0; i < 4; ++i) {
                RayState& w = lane[k[i]];
                w.pending = false;
                if (!w.want_normal) continue;
                w.hit.normal = ok[i] ? std::array<double, 3>{normal[0][i], normal[1][i], normal[2][i]}
                                     : world_normal(w.later.corner, {by_axis[0][i], by_axis[1][i], by_axis[2][i]},
                                                    w.later.cell_spacing, w.world_dir);
            }
        }
    }
#endif
    for (unsigned m = lanes; m; m &= m - 1) finish_hit(finder, lane[std::countr_zero(m)]);
}

OCTISO_ISA_END
}  // namespace octiso
