// First root of the cell cubic along one segment (Knoll et al. 2006, Sec. 4.4; Marmitt et al.
// 2004 as rebuilt in notes/rootfinding.md 1.2): interchangeable root-finder policies behind one
// function template, first_root<Finder>, the hit policies of CONVENTIONS 2b they all share, the
// runtime-to-template switch over them, and the world-space normal at a hit. The cubic is cell.h.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <type_traits>

#include "octiso/inline.h"
#include "octiso/root_finder.h"
#include "render/cell.h"
#include "util/isa.h"

namespace octiso {
OCTISO_ISA_BEGIN

/// first_root's "no hit": negative, never NaN.
inline constexpr double kNoHit = -1.0;
/// first_root's "a root is located, its refinement left to the caller" (only where it is given
/// a RootBracket): negative, never NaN, not kNoHit.
inline constexpr double kRootPending = -2.0;

/// A root located but not refined: the monotone piece [a, b] of the cubic with coefficients c
/// that holds it, f(a) = fa and f(b) = fb nonzero with opposite signs. Neubauer::refine on it and
/// roots_detail::into_bracket(s, a, b) give first_root's s bit for bit (pending_roots.h refines
/// four at a time).
struct RootBracket {
    double c[4];
    double a, fa, b, fb;
};

namespace roots_detail {

template <typename R> inline int sign(R v) { return (v > 0) - (v < 0); }

/// Roots of a*s^2 + b*s + c strictly inside (0,1), ascending; the stable form q = -(b + sign(b)
/// sqrt(disc))/2, roots q/a and c/q, so neither cancels; a == 0 falls back to the line.
template <typename R> inline int quadratic_roots_in_unit(R a, R b, R c, R out[2]) {
    R r[2];
    int n = 0;
    if (a == 0) {
        if (b != 0) r[n++] = -c / b;
    } else {
        const R disc = b * b - R(4) * a * c;
        if (disc >= 0) {
            const R q = R(-0.5) * (b + std::copysign(std::sqrt(disc), b));
            if (q != 0) {
                r[n++] = q / a;
                r[n++] = c / q;
            } else {
                r[n++] = R(0);   // b == 0 and c == 0: double root at 0
            }
        }
    }
    int m = 0;
    for (int i = 0; i < n; ++i)
        if (r[i] > 0 && r[i] < 1) out[m++] = r[i];
    if (m == 2 && out[1] < out[0]) std::swap(out[0], out[1]);
    return m;
}

/// The stationary points of the cubic inside (0,1): roots of f' = 3 c3 s^2 + 2 c2 s + c1.
template <typename R> inline int extrema_stable(const CellCubic<R>& f, R out[2]) {
    return quadratic_roots_in_unit(R(3) * f.c[3], R(2) * f.c[2], f.c[1], out);
}

/// The cubic's Bernstein coefficients on [0, 1]: f(s) = sum b_i C(3,i) s^i (1-s)^(3-i), so on
/// [0, 1] f lies between the least and the largest of them.
template <typename R> inline std::array<R, 4> bernstein_on_unit(const CellCubic<R>& f) {
    const R c0 = f.c[0], c1 = f.c[1], c2 = f.c[2], c3 = f.c[3];
    return {c0, c0 + c1 / R(3), c0 + (R(2) * c1 + c2) / R(3), ((c0 + c1) + c2) + c3};
}

/// Whether the walk (marmitt_walk) would find no root on [0, 1] whatever the finder: true only
/// where the Bernstein coefficients all exceed, with one sign, a margin far above the rounding of
/// any evaluation the walk makes, and f_out (evaluated apart, from the corners) is non-zero with
/// that sign. Then f(e) at every stationary point a finder returns keeps the sign of f_in, so the
/// walk would end in kNoHit: the same result without the stationary points (a square root,
/// divisions) and their evaluations.
/// Margin: the hull and Horner's f(e) on [0, 1] each round by under 8u (|c0| + .. + |c3|),
/// u = 2^-53 for double (less for long double); 2^-40 of that sum is over 100 times more.
/// Most cells whose corner range holds the isovalue are not hit (ch2better 100.5: 118 k of 166 k
/// per 512^2 frame, counted once, no JSON), and this is their common case (BENCHMARKS.md, packets).
template <typename R> inline bool keeps_one_sign(const CellCubic<R>& f) {
    const auto [b0, b1, b2, b3] = bernstein_on_unit(f);
    const R margin = R(0x1p-40) * (std::fabs(f.c[0]) + std::fabs(f.c[1]) + std::fabs(f.c[2]) + std::fabs(f.c[3]));
    const R lo = std::min(std::min(b0, b1), std::min(b2, b3)), hi = std::max(std::max(b0, b1), std::max(b2, b3));
    if (lo > margin) return f.f_out > 0;
    if (hi < -margin) return f.f_out < 0;
    return false;
}

/// s of a root inside the bracket [a, b] where f(b) != 0: the true root is < b, so a value that
/// rounded up to b (or beyond) is pulled just below it; the half-open rule stays exact.
inline double into_bracket(double s, double a, double b) {
    if (!(s < b)) s = std::nextafter(b, -1.0);
    if (!(s >= a)) s = a;
    return s;
}

}  // namespace roots_detail

/// Marmitt split + Illinois-modified regula falsi (the default; notes 1.2, "Marmitt + Illinois").
/// `iterations` refinement steps, then one final interpolation (Neubauer et al. 2002).
struct Neubauer {
    static constexpr const char* name = "neubauer";
    using Real = double;
    int iterations = 5;

    int extrema(const CellCubic<double>& f, double out[2]) const { return roots_detail::extrema_stable(f, out); }

    /// Precondition: fa, fb nonzero with opposite signs, a < b, f monotone on [a, b].
    double refine(const CellCubic<double>& f, double a, double fa, double b, double fb) const {
        int kept = 0;   // +1: a was kept last step, -1: b was kept
        for (int it = 0; it < iterations; ++it) {
            double s = a + (b - a) * (fa / (fa - fb));   // fa/(fa-fb) in [0,1]: no cancellation
            s = std::clamp(s, a, b);
            const double fs = f(s);
            if (fs == 0) return s;
            if (roots_detail::sign(fs) == roots_detail::sign(fa)) {
                a = s, fa = fs;
                if (kept == -1) fb *= 0.5;   // Illinois: b stayed twice, so pull its weight down
                kept = -1;
            } else {
                b = s, fb = fs;
                if (kept == +1) fa *= 0.5;
                kept = +1;
            }
            if (!(a < b)) break;
        }
        return a + (b - a) * (fa / (fa - fb));
    }
};

/// Analytic (Schwarze 1990 / Parker et al. 1998): Cardano or the trigonometric form in double.
/// Deviation: the classic solver decides hit/miss from the analytic roots alone, which flips under
/// rounding at near-double roots and at the segment ends; here the hit decision comes from the same
/// extremum walk as Neubauer and only the root VALUE is analytic (the real root nearest the
/// monotone bracket, polished by up to 4 Newton steps kept inside it). Guards are relative to the
/// scale-normalised coefficients (max |c| in [1/2,1)), not Manta's absolute 1e-7.
struct Schwarze {
    static constexpr const char* name = "schwarze";
    using Real = double;
    int iterations = 0;   // unused; keeps the policies constructible the same way
    // |c3| (then |c2|) below kRelGuard: drop the degree. The dropped term moves f by at most kRelGuard
    // on [0,1] and the polish removes that; keeping a tinier c3 puts a root near -c2/c3 and the trig
    // form then loses ~sqrt(u)/|c3| in the small roots (acos near +-1), more than the polish can fix.
    static constexpr double kRelGuard = 1e-6;
    static constexpr int kPolishSteps = 4;

    int extrema(const CellCubic<double>& f, double out[2]) const { return roots_detail::extrema_stable(f, out); }

    double refine(const CellCubic<double>& f, double a, double fa, double b, double fb) const {
        double roots[3];
        const int n = analytic_roots(f, roots);
        double best = a + (b - a) * (fa / (fa - fb));   // fallback: one regula falsi step
        double best_dist = std::numeric_limits<double>::infinity();
        for (int i = 0; i < n; ++i) {
            const double dist = roots[i] < a ? a - roots[i] : (roots[i] > b ? roots[i] - b : 0.0);
            if (dist < best_dist) best_dist = dist, best = roots[i];
        }
        double s = std::clamp(best, a, b);
        for (int it = 0; it < kPolishSteps; ++it) {   // Newton polish on the full cubic
            const double d = f.derivative(s);
            if (d == 0) break;
            const double next = s - f(s) / d;
            if (!(next >= a && next <= b) || next == s) break;
            s = next;
        }
        return s;
    }

    /// All real roots of the scale-normalised cubic (any order), up to 3.
    static int analytic_roots(const CellCubic<double>& f, double out[3]) {
        const double c0 = f.c[0], c1 = f.c[1], c2 = f.c[2], c3 = f.c[3];
        double big = std::fmax(std::fmax(std::fabs(c0), std::fabs(c1)), std::fmax(std::fabs(c2), std::fabs(c3)));
        if (big == 0) return 0;
        if (std::fabs(c3) <= kRelGuard * big) {
            if (std::fabs(c2) <= kRelGuard * big) {
                if (c1 == 0) return 0;
                out[0] = -c0 / c1;
                return 1;
            }
            const double disc = c1 * c1 - 4 * c2 * c0;
            if (disc < 0) {
                out[0] = -c1 / (2 * c2);   // the vertex: nearest real point of the complex pair
                return 1;
            }
            const double q = -0.5 * (c1 + std::copysign(std::sqrt(disc), c1));
            if (q == 0) {
                out[0] = 0;
                return 1;
            }
            out[0] = q / c2, out[1] = c0 / q;
            return 2;
        }
        // Monic s^3 + A s^2 + B s + C; depressed by s = x - A/3.
        const double A = c2 / c3, B = c1 / c3, C = c0 / c3;
        const double Q = (A * A - 3 * B) / 9;
        const double Rr = (2 * A * A * A - 9 * A * B + 27 * C) / 54;
        const double Q3 = Q * Q * Q;
        const double shift = A / 3;
        if (Q > 0 && Rr * Rr < Q3) {   // three real roots: trigonometric form
            const double theta = std::acos(std::clamp(Rr / std::sqrt(Q3), -1.0, 1.0));
            const double m = -2 * std::sqrt(Q);
            const double two_pi = 6.283185307179586476925;
            out[0] = m * std::cos(theta / 3) - shift;
            out[1] = m * std::cos((theta + two_pi) / 3) - shift;
            out[2] = m * std::cos((theta - two_pi) / 3) - shift;
            return 3;
        }
        // One real root (Cardano); the real part of the complex pair is a second candidate, which
        // is the double root when the discriminant vanished under rounding.
        const double u = -std::copysign(std::cbrt(std::fabs(Rr) + std::sqrt(std::fmax(Rr * Rr - Q3, 0.0))), Rr);
        const double v = u != 0 ? Q / u : 0.0;
        out[0] = (u + v) - shift;
        out[1] = -0.5 * (u + v) - shift;
        return 2;
    }
};

/// Endpoint sign test and one interpolation. By design it misses every cell where the segment
/// crosses an even number of times (double crossings, touches: E1-E3, E14), as in notes 1.2.
struct Linear {
    static constexpr const char* name = "linear";
    using Real = double;
    int iterations = 0;   // unused

    int extrema(const CellCubic<double>&, double[2]) const { return 0; }
    double refine(const CellCubic<double>&, double a, double fa, double b, double fb) const {
        return a + (b - a) * (fa / (fa - fb));
    }
};

/// The reference: long double throughout (cubic built in long double from the double corners),
/// stationary points isolated by the zero of f'' and refined by bisection on f' (so a touch at a
/// dyadic point such as s = 1/2 is found exactly), then bisection to the last bit (<= 200 steps)
/// per bracket. Slow; for tests and the brute-force reference tracer.
struct Exact {
    static constexpr const char* name = "exact";
    using Real = long double;
    int iterations = 200;

    int extrema(const CellCubic<long double>& f, long double out[2]) const {
        using L = long double;
        // f' is monotone on each side of the zero of f'' = 6 c3 s + 2 c2.
        L split[4] = {0, 0, 0, 1};
        int n = 1;
        if (f.c[3] != 0) {
            const L inflection = -f.c[2] / (L(3) * f.c[3]);
            if (inflection > 0 && inflection < 1) split[n++] = inflection;
        }
        split[n++] = 1;
        int m = 0;
        for (int i = 0; i + 1 < n; ++i) {
            L a = split[i], b = split[i + 1];
            L da = f.derivative(a), db = f.derivative(b);
            if (i > 0 && da == 0) {   // stationary exactly at the split point
                out[m++] = a;
                continue;
            }
            if (da == 0 || db == 0 || roots_detail::sign(da) == roots_detail::sign(db)) continue;
            for (int it = 0; it < iterations; ++it) {
                const L mid = a + (b - a) / 2;
                if (!(mid > a && mid < b)) break;
                const L dm = f.derivative(mid);
                if (dm == 0) { a = b = mid; break; }
                if (roots_detail::sign(dm) == roots_detail::sign(da)) a = mid, da = dm; else b = mid;
            }
            // The endpoint nearer the true zero of f' (both are within one ulp).
            out[m++] = std::fabs(f.derivative(a)) <= std::fabs(f.derivative(b)) ? a : b;
        }
        int k = 0;
        for (int i = 0; i < m; ++i)
            if (out[i] > 0 && out[i] < 1 && (k == 0 || out[i] > out[k - 1])) out[k++] = out[i];
        return k;
    }

    long double refine(const CellCubic<long double>& f, long double a, long double fa, long double b,
                       long double fb) const {
        for (int it = 0; it < iterations; ++it) {
            const long double mid = a + (b - a) / 2;
            if (!(mid > a && mid < b)) break;
            const long double fm = f(mid);
            if (fm == 0) return mid;
            if (roots_detail::sign(fm) == roots_detail::sign(fa)) a = mid, fa = fm; else b = mid, fb = fm;
        }
        return std::fabs(fa) <= std::fabs(fb) ? a : b;
    }
};

/// Marmitt's walk over the monotone pieces between stationary points of a built cubic `f`
/// (f_in != 0, a segment of non-zero length): the first piece with a sign change holds exactly one
/// root, the first root. Signs are compared, never multiplied (E12). first_root without its
/// early exit (roots_detail::keeps_one_sign), which a test holds to the same results.
/// With `later` (Neubauer only), a root that needs refining is not refined: its bracket goes to
/// *later and the walk returns kRootPending.
template <class Finder>
inline double marmitt_walk(const Finder& finder, const CellCubic<typename Finder::Real>& f, bool closed_end,
                           RootBracket* later = nullptr) {
    using R = typename Finder::Real;
    using roots_detail::sign;
    const auto refined = [&](R a, R fa, R b, R fb) OCTISO_LAMBDA_INLINE {
        if constexpr (std::is_same_v<Finder, Neubauer>) {
            if (later) {
                *later = {{f.c[0], f.c[1], f.c[2], f.c[3]}, a, fa, b, fb};
                return kRootPending;
            }
        }
        return roots_detail::into_bracket(double(finder.refine(f, a, fa, b, fb)), double(a), double(b));
    };
    R ext[2];
    const int n = finder.extrema(f, ext);
    R a = 0, fa = f.f_in;
    for (int i = 0; i < n; ++i) {
        const R e = ext[i], fe = f(e);
        if (fe == 0) return roots_detail::into_bracket(double(e), 0.0, 1.0);
        if (sign(fe) != sign(fa)) return refined(a, fa, e, fe);
        a = e, fa = fe;
    }
    if (f.f_out == 0) return closed_end ? 1.0 : kNoHit;
    if (sign(f.f_out) != sign(fa)) return refined(a, fa, R(1), f.f_out);
    return kNoHit;
}

/// First root s in [0,1) (in [0,1] when closed_end) of trilinear(p_in + s (p_out - p_in)) - iso,
/// where p_in, p_out are cell-local; kNoHit if none. Never NaN. The hit policies (CONVENTIONS 2b),
/// the same for every Finder (Linear misses even crossings by design):
///   - any non-finite corner, iso or endpoint: no hit (the caller continues behind the cell);
///   - a zero-length segment (p_in == p_out: the ray grazes an edge or corner) is the empty [0,0)
///     unless closed_end, then the point s = 0 if f == iso exactly there; so among the cells that
///     share that edge only the one that owns the half-open piece starting there reports it;
///   - f == iso exactly at p_in (includes a cell identically iso along the segment): s = 0;
///   - a stationary point e where f(e) == iso exactly is a hit (tangential touch), a near touch
///     that does not reach iso is not;
///   - a root exactly at s = 1 (f_out == 0) belongs to the next cell unless closed_end.
/// Pure function of its arguments; thread-safe.
/// With `later` (Neubauer only): kRootPending where the root needs refining, its bracket in *later.
/// IntegerCorners (cell.h): the caller vouches for corners of an integer type and an iso inside
/// their range, and the cubic skips its scaling and normalisation; the same root bit for bit.
template <class Finder, class CornerKind = AnyCorners>
inline double first_root(const Finder& finder, const double corner[8], double iso, const std::array<double, 3>& p_in,
                         const std::array<double, 3>& p_out, bool closed_end, RootBracket* later = nullptr,
                         CornerKind kind = {}) {
    using R = typename Finder::Real;
    bool finite = true;
    if constexpr (!std::is_same_v<CornerKind, IntegerCorners>) {
        finite = std::isfinite(iso);
        for (int i = 0; i < 8; ++i) finite &= std::isfinite(corner[i]);
    }
    for (int a = 0; a < 3; ++a) finite &= std::isfinite(p_in[a]) && std::isfinite(p_out[a]);
    if (!finite) return kNoHit;

    const CellCubic<R> f = make_cell_cubic<R>(corner, iso, p_in, p_out, kind);
    if (p_in == p_out) return closed_end && f.f_in == 0 ? 0.0 : kNoHit;
    if (f.f_in == 0) return 0.0;
    // 0.94-0.96 x the frame time (min of 5 interleaved pairs; build_ab_bernstein_exit.json).
    if (roots_detail::keeps_one_sign(f)) return kNoHit;
    return marmitt_walk(finder, f, closed_end, later);
}

/// Calls f(finder) with a value of the policy type for `kind`, once, outside the hot loop, so
/// the caller's loop is instantiated (and inlined) per policy. `iterations` configures Neubauer's
/// refinement steps (< 0 keeps the default); the other policies ignore it (Exact always bisects
/// to the last bit).
template <class F> decltype(auto) dispatch_root_finder(RootFinder kind, int iterations, F&& f) {
    switch (kind) {
        case RootFinder::neubauer: {
            Neubauer p;
            if (iterations >= 0) p.iterations = iterations;
            return f(p);
        }
        case RootFinder::schwarze: return f(Schwarze{});
        case RootFinder::linear: return f(Linear{});
        case RootFinder::exact: break;
    }
    return f(Exact{});
}

/// World-space unit normal of the isosurface at p_cell: the gradient of the trilinear interpolant
/// (per index step) divided by the spacing per axis, normalised, and flipped to face the ray
/// (dot(n, ray_dir) <= 0). A zero or non-finite gradient gives -ray_dir (CONVENTIONS 2b).
/// Finite for every finite input: the corners are scaled by a power of two before they are
/// differenced (values near +-DBL_MAX would otherwise overflow to inf and mix to NaN, issue 18),
/// and the spacing enters as the ratio smallest/own (<= 1), never as a division that overflows.
inline std::array<double, 3> world_normal(const double c[8], const std::array<double, 3>& p_cell,
                                          const std::array<double, 3>& spacing, const std::array<double, 3>& ray_dir) {
    const std::array<double, 3> fallback{-ray_dir[0], -ray_dir[1], -ray_dir[2]};
    // 1. Scale the corners so that |c| <= 2^-2: differences stay <= 2^-1 and the lerps below
    //    (weights in [0,1], slightly outside for an extrapolated p_cell) cannot overflow.
    double big_c = 0;
    // std::max ignores a NaN second argument exactly as fmax does here (big_c starts at 0 and
    // never becomes NaN), without fmax's library call.
    for (int i = 0; i < 8; ++i) big_c = std::max(big_c, std::fabs(c[i]));
    if (!std::isfinite(big_c) || !(big_c > 0)) return fallback;
    const int e = frexp_exponent(big_c);   // big_c < 2^e
    double cs[8];
    for (int i = 0; i < 8; ++i) cs[i] = scale_by_power_of_two(c[i], -e - 2);   // == std::ldexp, without the call
    const std::array<double, 3> g = gradient(cs, p_cell);
    // 2. Per world unit: g_a / s_a, up to the common factor 1/s_min, which the normalisation drops.
    const double s_min = std::fmin(spacing[0], std::fmin(spacing[1], spacing[2]));
    std::array<double, 3> n{g[0] * (s_min / spacing[0]), g[1] * (s_min / spacing[1]), g[2] * (s_min / spacing[2])};
    for (double v : n)
        if (!std::isfinite(v)) return fallback;   // fmax below would hide a NaN component
    // 3. Scale by the largest component, so tiny values do not underflow in the squares.
    const double big = std::max({std::fabs(n[0]), std::fabs(n[1]), std::fabs(n[2])});   // finite: checked above
    if (!(big > 0)) return fallback;
    for (double& v : n) v /= big;
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const double flip = (n[0] * ray_dir[0] + n[1] * ray_dir[1] + n[2] * ray_dir[2]) > 0 ? -1.0 : 1.0;
    for (double& v : n) v *= flip / len;
    for (double v : n)
        if (!std::isfinite(v)) return fallback;
    return n;
}

OCTISO_ISA_END
}  // namespace octiso
