// Tests for src/render/pending_roots.h and the deferral it finishes (nearest_root<Finder, true>,
// first_root with a RootBracket): a root left pending and refined later is the root refined at
// once, bit for bit, on its own, through nearest_root's hit (t and normal), and four at a time in
// the AVX2 register (neubauer_refine4), including the refinement's two early exits.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "octiso/render.h"
#include "render/cell_hit.h"
#include "render/pending_roots.h"
#include "render/roots.h"
#include "test_util/skip.h"

namespace octiso {
namespace isa_avx2::test {   // pending_roots_avx2.cpp, compiled for AVX2
void refine4_for_test(int iterations, const double in[8][4], double out[4]);
void normal4_for_test(const double in[17][4], double out[3][4], long long ok[4]);
}
namespace {

using P3 = std::array<double, 3>;

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// A random cell segment whose isovalue lies inside the corners' range.
struct Cell {
    double corner[8];
    double iso;
    P3 p_in, p_out;
};
Cell random_cell(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u01(0, 1), usym(-1, 1);
    Cell g;
    double lo = 1e300, hi = -1e300;
    for (double& c : g.corner) c = usym(rng), lo = std::min(lo, c), hi = std::max(hi, c);
    g.iso = lo + (hi - lo) * u01(rng);
    for (int a = 0; a < 3; ++a) g.p_in[a] = u01(rng), g.p_out[a] = u01(rng);
    return g;
}

TEST(PendingRoots, FirstRootLeftPendingRefinesToTheRootFoundAtOnce) {
    std::mt19937_64 rng(20261206);
    int pending = 0, at_once = 0;
    for (int n = 0; n < 20000; ++n) {
        const Cell g = random_cell(rng);
        for (bool closed : {false, true}) {
            const double now = first_root(Neubauer{}, g.corner, g.iso, g.p_in, g.p_out, closed);
            RootBracket later{};
            const double s = first_root(Neubauer{}, g.corner, g.iso, g.p_in, g.p_out, closed, &later);
            if (s != kRootPending) {
                ASSERT_TRUE(same_bits(s, now)) << "case " << n << ": " << s << " against " << now;
                ++at_once;
                continue;
            }
            ++pending;
            ASSERT_GE(now, 0) << "a pending root is a hit, case " << n;
            CellCubic<double> f{};
            std::copy(later.c, later.c + 4, f.c);
            const double refined = roots_detail::into_bracket(Neubauer{}.refine(f, later.a, later.fa, later.b, later.fb), later.a, later.b);
            ASSERT_TRUE(same_bits(refined, now)) << "case " << n << ": " << refined << " against " << now;
        }
    }
    EXPECT_GT(pending, 1000);   // neither branch is vacuous
    EXPECT_GT(at_once, 1000);
}

TEST(PendingRoots, DeferredHitFinishesToTheImmediateHit) {
    std::mt19937_64 rng(7);
    int deferred = 0;
    for (int n = 0; n < 5000; ++n) {
        const Cell g = random_cell(rng);
        const double iso[1] = {g.iso};
        Placement placement;
        placement.spacing = {0.5, 1.0, 2.0};
        const CellWalkScene scene(Dims{4, 4, 4}, placement, iso, 1);
        RayState now, later;
        for (RayState* w : {&now, &later}) w->want_normal = true, w->world_dir = {0.6, 0.0, 0.8};
        double lo, hi;
        corner_range(g.corner, lo, hi);
        const bool hit_now = nearest_root<Neubauer, false>(Neubauer{}, scene, now, g.corner, lo, hi, g.p_in, g.p_out, 1.0, 2.5,
                                                           false, placement.spacing);
        const bool hit_later = nearest_root<Neubauer, true>(Neubauer{}, scene, later, g.corner, lo, hi, g.p_in, g.p_out, 1.0,
                                                            2.5, false, placement.spacing);
        ASSERT_EQ(hit_now, hit_later) << "case " << n;
        ASSERT_FALSE(now.pending);
        if (later.pending) {
            ++deferred;
            EXPECT_EQ(later.hit.iso_index, 0);
            finish_hit(Neubauer{}, later);
            EXPECT_FALSE(later.pending);
        }
        ASSERT_TRUE(same_bits(now.hit.t, later.hit.t)) << "case " << n;
        ASSERT_EQ(now.hit.iso_index, later.hit.iso_index) << "case " << n;
        for (int a = 0; a < 3; ++a) ASSERT_TRUE(same_bits(now.hit.normal[a], later.hit.normal[a])) << "case " << n;
    }
    EXPECT_GT(deferred, 500);
}

TEST(PendingRoots, FourAtATimeInAvx2EqualsTheScalarRefinementLaneByLane) {
    if (!cpu_has_avx2()) {
        OCTISO_SKIP("this CPU has no AVX2: the four-lane refinement only runs in the AVX2 kernel");
    }
    std::vector<RootBracket> brackets;
    std::mt19937_64 rng(11);
    while (brackets.size() < 4000) {   // brackets the traversal leaves pending
        const Cell g = random_cell(rng);
        RootBracket r{};
        if (first_root(Neubauer{}, g.corner, g.iso, g.p_in, g.p_out, false, &r) == kRootPending) brackets.push_back(r);
    }
    // The early exits. f(s) = s - 1/2 from [0, 1] and s - 1/4 from [0, 3/4]: the first
    // interpolation lands on the root exactly (fs == 0). f(s) = s - 1/2 with fb = 1e-300 given at
    // b = 1/4 (refine uses the values it is given): the first step lands on b, f there has the
    // sign of fa, so a becomes b and the bracket collapses (!(a < b)); the loop without that exit
    // returns the same b, so this case guards the masks' handling of it, not its necessity.
    brackets.push_back({{-0.5, 1, 0, 0}, 0, -0.5, 1, 0.5});
    brackets.push_back({{-0.25, 1, 0, 0}, 0, -0.25, 0.75, 0.5});
    brackets.push_back({{-0.5, 1, 0, 0}, 0, -0.5, 0.25, 1e-300});
    // A cubic decreasing on [0.2, 0.9], given fa = 0.31 and fb = -0.2 (f's own values there are
    // 0.311 and -0.106; refine uses what it is given): its steps keep each end twice, so Illinois
    // halves fb at step 2 and fa at steps 4, 7 and 8 (a scalar trace of Neubauer::refine).
    brackets.push_back({{0.5, -1, 0.25, 0.125}, 0.2, 0.31, 0.9, -0.2});
    int exact_exits = 0;
    for (int iterations : {0, 1, 2, 5, 9}) {
        const Neubauer finder{iterations};
        for (size_t i = 0; i < brackets.size(); i += 3) {   // overlapping groups: every lane position
            double in[8][4], out[4];
            for (int l = 0; l < 4; ++l) {
                const RootBracket& r = brackets[(i + l) % brackets.size()];
                const double part[8] = {r.c[0], r.c[1], r.c[2], r.c[3], r.a, r.fa, r.b, r.fb};
                for (int j = 0; j < 8; ++j) in[j][l] = part[j];
            }
            isa_avx2::test::refine4_for_test(iterations, in, out);
            for (int l = 0; l < 4; ++l) {
                const RootBracket& r = brackets[(i + l) % brackets.size()];
                CellCubic<double> f{};
                std::copy(r.c, r.c + 4, f.c);
                const double scalar = finder.refine(f, r.a, r.fa, r.b, r.fb);
                ASSERT_TRUE(same_bits(out[l], scalar))
                    << "bracket " << (i + l) % brackets.size() << ", " << iterations << " steps: " << out[l] << " against " << scalar;
                exact_exits += iterations > 0 && f(scalar) == 0;
            }
        }
    }
    EXPECT_GT(exact_exits, 0);   // the fs == 0 exit was taken
}

/// One hit for the four-lane normal: its cell-local point, corners, spacing and ray direction.
struct NormalCase {
    double p[3], corner[8], spacing[3], dir[3];
};

TEST(PendingRoots, NormalsFourAtATimeInAvx2EqualWorldNormalOrDeferToIt) {
    if (!cpu_has_avx2()) {
        OCTISO_SKIP("this CPU has no AVX2: the four-lane normals only run in the AVX2 kernel");
    }
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u01(0, 1), usym(-1, 1);
    std::vector<NormalCase> cases;
    for (int n = 0; n < 4000; ++n) {
        NormalCase h;
        const double scale = std::ldexp(1.0, int(usym(rng) * 60));   // corner magnitudes 2^-60 .. 2^60
        for (double& c : h.corner) c = usym(rng) * scale;
        for (int a = 0; a < 3; ++a) h.p[a] = u01(rng), h.spacing[a] = 0.25 + u01(rng), h.dir[a] = usym(rng);
        cases.push_back(h);
    }
    // world_normal's other paths: a constant cell (zero gradient), corners at the top of the range
    // (the scale leaves the multiply), a subnormal maximum, a NaN and an infinite corner.
    const double special[5] = {0.0, 1e308, 4e-320, std::nan(""), std::numeric_limits<double>::infinity()};
    for (double v : special) {
        NormalCase h = cases[0];
        for (double& c : h.corner) c = v == 0.0 ? 3.0 : v;
        if (v != 0.0) h.corner[0] = v * 0.5, h.corner[7] = -v;
        cases.push_back(h);
    }
    int vector_lanes = 0, scalar_lanes = 0;
    for (size_t i = 0; i < cases.size(); ++i) {
        double in[17][4], out[3][4];
        long long ok[4];
        for (int l = 0; l < 4; ++l) {
            const NormalCase& h = cases[(i + l) % cases.size()];
            for (int a = 0; a < 3; ++a) in[a][l] = h.p[a], in[11 + a][l] = h.spacing[a], in[14 + a][l] = h.dir[a];
            for (int j = 0; j < 8; ++j) in[3 + j][l] = h.corner[j];
        }
        isa_avx2::test::normal4_for_test(in, out, ok);
        for (int l = 0; l < 4; ++l) {
            const NormalCase& h = cases[(i + l) % cases.size()];
            const P3 scalar = world_normal(h.corner, {h.p[0], h.p[1], h.p[2]}, {h.spacing[0], h.spacing[1], h.spacing[2]},
                                           {h.dir[0], h.dir[1], h.dir[2]});
            if (!ok[l]) {
                scalar_lanes += l == 0;
                continue;
            }
            vector_lanes += l == 0;
            for (int a = 0; a < 3; ++a)
                ASSERT_TRUE(same_bits(out[a][l], scalar[a])) << "case " << (i + l) % cases.size() << ", axis " << a;
        }
    }
    EXPECT_GT(vector_lanes, 3900);   // the common path is the vector one
    EXPECT_GE(scalar_lanes, 4);      // zero gradient, subnormal, NaN and infinite corners go to world_normal
}

}  // namespace
}  // namespace octiso
