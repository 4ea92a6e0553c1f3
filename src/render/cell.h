// The math of one trilinear cell (Knoll et al. 2006, Sec. 4.4; notes/rootfinding.md 1.1): the
// interpolant, its gradient, and the cubic f(p_in + s*(p_out - p_in)) - iso on the segment s in
// [0,1], scale-normalised by a power of two. Header-only, no allocation; the root finders that
// consume the cubic live in roots.h, the world-space normal there too.
//
// Corner order: corner[i + 2*j + 4*k], i,j,k in {0,1} along x,y,z (x fastest, like the volume).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include "util/isa.h"

namespace octiso {
OCTISO_ISA_BEGIN

/// a at t = 0, b at t = 1, written so that both ends are exact (a*1 + b*0 == a): two cells that
/// share a face then compute bitwise the same value on it, which the half-open rule relies on.
template <typename R> inline R cell_lerp(R a, R b, R t) { return a * (R(1) - t) + b * t; }

/// Trilinear interpolant of the 8 corners at p_cell (cell-local, [0,1]^3; extrapolates outside).
template <typename R> inline R trilinear(const R c[8], R x, R y, R z) {
    const R y0 = cell_lerp(cell_lerp(c[0], c[1], x), cell_lerp(c[2], c[3], x), y);
    const R y1 = cell_lerp(cell_lerp(c[4], c[5], x), cell_lerp(c[6], c[7], x), y);
    return cell_lerp(y0, y1, z);
}
inline double trilinear(const double c[8], const std::array<double, 3>& p_cell) {
    return trilinear<double>(c, p_cell[0], p_cell[1], p_cell[2]);
}

/// Gradient of the trilinear interpolant at p_cell, in value per cell-local unit (per index step).
inline std::array<double, 3> gradient(const double c[8], const std::array<double, 3>& p_cell) {
    const double x = p_cell[0], y = p_cell[1], z = p_cell[2];
    const double dx = cell_lerp(cell_lerp(c[1] - c[0], c[3] - c[2], y), cell_lerp(c[5] - c[4], c[7] - c[6], y), z);
    const double dy = cell_lerp(cell_lerp(c[2] - c[0], c[3] - c[1], x), cell_lerp(c[6] - c[4], c[7] - c[5], x), z);
    const double dz = cell_lerp(cell_lerp(c[4] - c[0], c[5] - c[1], x), cell_lerp(c[6] - c[2], c[7] - c[3], x), y);
    return {dx, dy, dz};
}

/// x * 2^e, exactly as std::ldexp rounds it, but as one multiplication by an exact power of two
/// when that factor is a normal number (the hot case: ldexp is a library call). Both round only
/// where the result leaves the normal range, and then identically.
template <typename R> inline R scale_by_power_of_two(R x, int e) {
    if (e > -1000 && e < 1000) {
        // Build 2^e from its bit pattern: exact, no call.
        const uint64_t bits = uint64_t(e + 1023) << 52;
        double factor;
        std::memcpy(&factor, &bits, sizeof factor);
        return x * R(factor);
    }
    return std::ldexp(x, e);
}

/// The exponent std::frexp would return for x > 0 (x = f * 2^e, f in [1/2, 1)), read from the bits
/// when x is a normal double (frexp is a library call in the hot path), else frexp itself.
template <typename R> inline int frexp_exponent(R x) {
    if constexpr (std::is_same_v<R, double>) {
        uint64_t bits;
        std::memcpy(&bits, &x, sizeof bits);
        const int biased = int((bits >> 52) & 0x7ff);
        if (biased != 0 && biased != 0x7ff) return biased - 1022;
    }
    int e = 0;
    std::frexp(x, &e);
    return e;
}

/// What a caller knows of a cell's corners and isovalue beyond "finite" (make_cell_cubic,
/// first_root): AnyCorners, any finite doubles; IntegerCorners, values of an integer scalar type
/// (|c| <= 2^32, never NaN or infinite) and an isovalue inside their range, as the octree
/// traversal of an integer file hands them over (nearest_root tests the range first).
struct AnyCorners {};
struct IntegerCorners {};
/// What every cell-walking tracer over a volume of scalar type T knows of its corners.
template <typename T> using CornerKindOf = std::conditional_t<std::is_integral_v<T>, IntegerCorners, AnyCorners>;

/// f(s) = c[0] + c[1] s + c[2] s^2 + c[3] s^3 = (trilinear(p_in + s (p_out - p_in)) - iso) * 2^-scale_exp.
/// Invariants: f_in == c[0] (direct trilinear at p_in) and f_out is the direct trilinear value at
/// p_out under the same scaling, so the endpoint signs agree with the neighbouring cells (their
/// shared face values are bitwise equal) even where Horner at s = 1 would round the other way.
/// max(|c[i]|, |f_out|) is in [1/2, 1) unless everything is 0 (f identically iso on the segment),
/// except for IntegerCorners (make_cell_cubic): there scale_exp is 0 and nothing is normalised.
/// Every finder is homogeneous in the coefficients (its guards relative, its steps ratios, sign
/// tests and halvings), so a power of two more or less changes no root it returns.
template <typename R> struct CellCubic {
    R c[4];
    R f_in, f_out;
    int scale_exp;

    R operator()(R s) const { return ((c[3] * s + c[2]) * s + c[1]) * s + c[0]; }
    R derivative(R s) const { return (R(3) * c[3] * s + R(2) * c[2]) * s + c[1]; }
    bool is_identically_zero() const { return c[0] == 0 && c[1] == 0 && c[2] == 0 && c[3] == 0 && f_out == 0; }
};

/// The cubic of the segment p_in -> p_out (cell-local) for the corners `corner` and `iso`, in
/// arithmetic R (double for the fast finders, long double for the reference). Preconditions: all
/// inputs finite. Never overflows: corners and iso are first scaled by 2^-e with 2^e > max(|corner|,
/// |iso|) (exact: a power of two), so c - iso == 0 exactly where corner == iso, whatever the scale.
/// IntegerCorners (their magnitudes at most 2^32, nothing to overflow) skips that scaling and
/// the normalisation of step 3 (scale_exp 0): the scaled cubic times a power of two, exactly,
/// because multiplying by a power of two commutes with the rounding of every +, - and * below as
/// long as no value leaves the normal range. Only a value that the scaling (by at most 2^-33)
/// would push below 2^-1022 could differ, the unscaled one being the more exact; the traversal's
/// segment ends are 0, 1 or at least 1e-12 from a face (snap_to_face), so its smallest non-zero
/// intermediate is far above that, and the coefficients stay below 2^40, far from overflow in
/// the finders' squares. Every root the same bit for bit (CellCubic above). Step 1 without its 9
/// magnitudes, exponent and 9 products: 0.947-0.981 x the trace at the minimum on the real scans,
/// 0.962 / 0.969 on plume / mixing 256^3 (11 pairs, build_ab_integer_corners.json); step 3
/// without its 5 magnitudes, exponent and 5 products, on top of that: 0.935-0.980 x
/// (9 pairs, build_ab_integer_corners_unnormalised.json); both against neither in one run,
/// 0.84-0.95 x (11 pairs, build_ab_integer_corners_both_steps.json).
template <typename R, class CornerKind = AnyCorners>
inline CellCubic<R> make_cell_cubic(const double corner[8], double iso, const std::array<double, 3>& p_in,
                                    const std::array<double, 3>& p_out, CornerKind = {}) {
    constexpr bool kUnscaled = std::is_same_v<CornerKind, IntegerCorners>;
    // 1. g = (corner - iso) * 2^-e, in [-2, 2] (e = 0 for IntegerCorners: |g| <= 2^33).
    int e = 0;
    R g[8];
    if constexpr (kUnscaled) {
        for (int i = 0; i < 8; ++i) g[i] = R(corner[i]) - R(iso);
    } else {
        double m = std::fabs(iso);
        // std::max, not std::fmax: the inputs are finite (precondition), where both agree, and fmax is
        // a library call at x86-64-v2 (perf: fmax@plt + __fmax were 1.5 % of a frame on ch2better).
        for (int i = 0; i < 8; ++i) m = std::max(m, std::fabs(corner[i]));
        if (m > 0) e = frexp_exponent(m);
        const R iso_scaled = R(scale_by_power_of_two(iso, -e));
        for (int i = 0; i < 8; ++i) g[i] = R(scale_by_power_of_two(corner[i], -e)) - iso_scaled;
    }

    // 2. Monomial coefficients of the interpolant (notes 1.1) and of its restriction to the segment.
    const R k1 = g[1] - g[0], k2 = g[2] - g[0], k3 = g[4] - g[0];
    const R k4 = g[3] - g[1] - g[2] + g[0];   // xy
    const R k5 = g[6] - g[2] - g[4] + g[0];   // yz
    const R k6 = g[5] - g[1] - g[4] + g[0];   // xz
    const R k7 = g[7] - g[3] - g[5] - g[6] + g[1] + g[2] + g[4] - g[0];
    const R ox = R(p_in[0]), oy = R(p_in[1]), oz = R(p_in[2]);
    const R dx = R(p_out[0]) - ox, dy = R(p_out[1]) - oy, dz = R(p_out[2]) - oz;

    CellCubic<R> f;
    f.c[0] = trilinear<R>(g, ox, oy, oz);
    f.c[1] = k1 * dx + k2 * dy + k3 * dz + k4 * (ox * dy + oy * dx) + k5 * (oy * dz + oz * dy) +
             k6 * (ox * dz + oz * dx) + k7 * (ox * oy * dz + ox * oz * dy + oy * oz * dx);
    f.c[2] = k4 * dx * dy + k5 * dy * dz + k6 * dx * dz + k7 * (ox * dy * dz + oy * dx * dz + oz * dx * dy);
    f.c[3] = k7 * dx * dy * dz;
    f.f_out = trilinear<R>(g, R(p_out[0]), R(p_out[1]), R(p_out[2]));

    // 3. Normalise so the largest magnitude lies in [1/2, 1): exact, signs and zeros preserved
    //    (e2 = 0 for IntegerCorners: the step changes no root).
    int e2 = 0;
    if constexpr (!kUnscaled) {
        R big = std::fabs(f.f_out);
        for (int i = 0; i < 4; ++i) big = std::max(big, std::fabs(f.c[i]));
        if (big > 0) e2 = frexp_exponent(big);
        for (int i = 0; i < 4; ++i) f.c[i] = scale_by_power_of_two(f.c[i], -e2);
        f.f_out = scale_by_power_of_two(f.f_out, -e2);
    }
    f.f_in = f.c[0];
    f.scale_exp = e + e2;
    return f;
}

OCTISO_ISA_END
}  // namespace octiso
