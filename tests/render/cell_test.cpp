// Tests for src/render/cell.h: the cubic along a segment against direct trilinear evaluation, its
// power-of-two normalisation, bitwise agreement of neighbouring cells on a shared face, and the
// gradient against central differences.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <random>

#include "render/cell.h"

namespace octiso {
namespace {

using P3 = std::array<double, 3>;

TEST(CellCubic, CoefficientsMatchDirectTrilinearEvaluation) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u01(0, 1), usym(-1, 1);
    for (int n = 0; n < 20000; ++n) {
        double c[8];
        const double scale = std::ldexp(1.0, int(usym(rng) * 200));
        for (double& v : c) v = usym(rng) * scale;
        const double iso = usym(rng) * scale;
        P3 p_in, p_out;
        for (int a = 0; a < 3; ++a) p_in[a] = u01(rng), p_out[a] = u01(rng);
        const CellCubic<double> f = make_cell_cubic<double>(c, iso, p_in, p_out);
        double big = std::fabs(f.f_out);
        for (double k : f.c) big = std::fmax(big, std::fabs(k));
        ASSERT_GE(big, 0.5);
        ASSERT_LT(big, 1.0);
        ASSERT_EQ(f.f_in, f.c[0]);
        for (double s : {0.0, 0.25, 0.5, 0.7731, 1.0}) {
            P3 p;
            for (int a = 0; a < 3; ++a) p[a] = p_in[a] + s * (p_out[a] - p_in[a]);
            const double direct = trilinear(c, p) - iso;
            EXPECT_NEAR(std::ldexp(f(s), f.scale_exp), direct, 1e-13 * scale) << n << " s " << s;
        }
        const double out = trilinear(c, p_out) - iso;
        EXPECT_EQ(f.f_out > 0, out > 0);
        EXPECT_EQ(f.f_out < 0, out < 0);
    }
}

TEST(CellCubic, LongDoubleAgreesWithDouble) {
    std::mt19937_64 rng(8);
    std::uniform_real_distribution<double> u01(0, 1), usym(-1, 1);
    for (int n = 0; n < 2000; ++n) {
        double c[8];
        for (double& v : c) v = usym(rng);
        P3 p_in, p_out;
        for (int a = 0; a < 3; ++a) p_in[a] = u01(rng), p_out[a] = u01(rng);
        const auto fd = make_cell_cubic<double>(c, 0.1, p_in, p_out);
        const auto fl = make_cell_cubic<long double>(c, 0.1, p_in, p_out);
        ASSERT_EQ(fd.scale_exp, fl.scale_exp);   // the same power of two unless at a binade edge
        for (int i = 0; i < 4; ++i) EXPECT_NEAR(fd.c[i], double(fl.c[i]), 1e-14);
    }
}

/// IntegerCorners (values of an integer type, the isovalue inside their range) skips the scaling
/// of step 1 and the normalisation of step 3: the normalised cubic times 2^scale_exp exactly,
/// every coefficient, in double and long double.
template <typename R> void expect_integer_corners_unscaled_bit_for_bit(uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u01(0, 1);
    for (int n = 0; n < 20000; ++n) {
        const double top = n % 3 == 0 ? 255.0 : n % 3 == 1 ? 65535.0 : 4294967295.0;
        const double offset = n % 2 ? 0.0 : -std::floor(top / 2) - 1;   // signed types too
        double c[8], lo = 1e300, hi = -1e300;
        for (double& v : c) v = std::floor(u01(rng) * top) + offset, lo = std::min(lo, v), hi = std::max(hi, v);
        const double iso = n % 5 == 0 ? c[n % 8] : lo + (hi - lo) * u01(rng);
        P3 p_in, p_out;
        for (int a = 0; a < 3; ++a) p_in[a] = u01(rng), p_out[a] = u01(rng);
        if (n % 7 == 0) p_out[n % 3] = p_in[n % 3];
        const CellCubic<R> scaled = make_cell_cubic<R>(c, iso, p_in, p_out, AnyCorners{});
        const CellCubic<R> unscaled = make_cell_cubic<R>(c, iso, p_in, p_out, IntegerCorners{});
        // Equal values of equal sign (long double's padding bytes are not its value).
        auto same = [](R a, R b) { return a == b && std::signbit(a) == std::signbit(b); };
        const auto normalised = [&](R v) { return std::ldexp(v, -scaled.scale_exp); };
        ASSERT_EQ(unscaled.scale_exp, 0) << n;
        for (int i = 0; i < 4; ++i) ASSERT_TRUE(same(scaled.c[i], normalised(unscaled.c[i]))) << n << " c" << i;
        ASSERT_TRUE(same(scaled.f_out, normalised(unscaled.f_out))) << n;
        ASSERT_TRUE(same(scaled.f_in, normalised(unscaled.f_in))) << n;
    }
}

TEST(CellCubic, IntegerCornersAreTheNormalisedCubicTimesAPowerOfTwo) {
    expect_integer_corners_unscaled_bit_for_bit<double>(11);
    expect_integer_corners_unscaled_bit_for_bit<long double>(12);
}

TEST(CellCubic, ConstantCellEqualToIsoIsIdenticallyZeroAtAnyScale) {
    for (double v : {0.0, 0.3, -7.5e300, 1e-310, 255.0}) {
        double c[8];
        for (double& x : c) x = v;
        const auto f = make_cell_cubic<double>(c, v, {0.1, 0.2, 0.3}, {0.9, 0.4, 0.7});
        EXPECT_TRUE(f.is_identically_zero()) << v;
    }
    double c[8] = {1e308, -1e308, 1e308, -1e308, 1e308, -1e308, 1e308, -1e308};
    const auto f = make_cell_cubic<double>(c, -1e308, {0, 0, 0}, {1, 1, 1});   // no overflow
    for (double k : f.c) EXPECT_TRUE(std::isfinite(k));
    EXPECT_TRUE(std::isfinite(f.f_out));
}

TEST(CellCubic, NeighbouringCellsAgreeBitwiseOnSharedFaces) {
    // A 3x3x3 lattice of random values; cells (0,0,0) and its +x, +y, +z neighbours.
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<double> u01(0, 1), usym(-1, 1);
    double v[3][3][3];
    for (auto& a : v)
        for (auto& b : a)
            for (double& x : b) x = usym(rng) * 1000;
    auto corners = [&](int x0, int y0, int z0, double c[8]) {
        for (int k = 0; k < 2; ++k)
            for (int j = 0; j < 2; ++j)
                for (int i = 0; i < 2; ++i) c[i + 2 * j + 4 * k] = v[x0 + i][y0 + j][z0 + k];
    };
    double a[8], bx[8], by[8], bz[8];
    corners(0, 0, 0, a), corners(1, 0, 0, bx), corners(0, 1, 0, by), corners(0, 0, 1, bz);
    for (int n = 0; n < 1000; ++n) {
        const double p = u01(rng), q = u01(rng);
        EXPECT_EQ(trilinear(a, {1, p, q}), trilinear(bx, {0, p, q}));
        EXPECT_EQ(trilinear(a, {p, 1, q}), trilinear(by, {p, 0, q}));
        EXPECT_EQ(trilinear(a, {p, q, 1}), trilinear(bz, {p, q, 0}));
    }
}

TEST(CellGradient, MatchesCentralDifferences) {
    std::mt19937_64 rng(10);
    std::uniform_real_distribution<double> u01(0, 1), usym(-1, 1);
    for (int n = 0; n < 1000; ++n) {
        double c[8];
        for (double& x : c) x = usym(rng);
        const P3 p{u01(rng), u01(rng), u01(rng)};
        const P3 g = gradient(c, p);
        for (int a = 0; a < 3; ++a) {
            P3 lo = p, hi = p;
            const double h = 1e-5;
            lo[a] -= h, hi[a] += h;
            // The interpolant is linear along each axis, so the central difference is exact up to rounding.
            EXPECT_NEAR(g[a], (trilinear(c, hi) - trilinear(c, lo)) / (2 * h), 1e-9);
        }
    }
}

}  // namespace
}  // namespace octiso
