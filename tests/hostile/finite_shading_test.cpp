// Issue 18, class 1: finite input must give finite normals and colours. Values near +-DBL_MAX
// overflowed the gradient to inf and mixed it to NaN; the NaN colour then indexed the sRGB table
// at INT_MIN (SIGSEGV with -o, 47,415 NaN normals with --normal).
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <limits>
#include <random>

#include "hostile/hostile_util.h"
#include "octiso/image.h"
#include "octiso/oct_file.h"
#include "octiso/verify.h"
#include "render/roots.h"
#include "render/shade.h"

namespace octiso::test {
namespace {

void expect_unit_facing(const std::array<double, 3>& n, const std::array<double, 3>& dir) {
    for (double v : n) ASSERT_TRUE(std::isfinite(v)) << n[0] << "," << n[1] << "," << n[2];
    EXPECT_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1.0, 1e-12);
    EXPECT_LE(n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2], 1e-12);
}

TEST(HostileShading, WorldNormalFiniteForCornersNearDblMax) {
    const double issue[8] = {DBL_MAX, 1e308, -DBL_MAX, 0.6, -1e308, 0.6, DBL_MAX, 1e308};
    const std::array<double, 3> dir{0.6, -0.48, 0.64};
    for (double x : {0.0, 0.25, 0.5, 1.0})
        for (double y : {0.0, 0.5, 1.0})
            for (double z : {0.0, 0.7, 1.0}) expect_unit_facing(world_normal(issue, {x, y, z}, {1, 1, 1}, dir), dir);
}

TEST(HostileShading, WorldNormalFiniteForRandomExtremeCornersAndSpacings) {
    std::mt19937_64 rng(18);
    const double magnitudes[] = {DBL_MAX, 1e308, 1e300, 1.0, 1e-300, DBL_MIN, 4.9e-324, 0.0};
    const double spacings[] = {1.0, 1e300, 1e-300, DBL_MIN, 3.0};
    std::uniform_int_distribution<int> pick(0, 7), pick_s(0, 4), sign(0, 1);
    std::uniform_real_distribution<double> u(-0.01, 1.01);   // extrapolates a little, as the tracer may
    for (int trial = 0; trial < 20000; ++trial) {
        double c[8];
        for (double& v : c) v = (sign(rng) ? -1 : 1) * magnitudes[pick(rng)] * (0.5 + 0.5 * u(rng));
        const std::array<double, 3> s{spacings[pick_s(rng)], spacings[pick_s(rng)], spacings[pick_s(rng)]};
        std::array<double, 3> dir{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5 + 1e-3};
        const double len = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        for (double& d : dir) d /= len;
        expect_unit_facing(world_normal(c, {u(rng), u(rng), u(rng)}, s, dir), dir);
        if (HasFailure()) return;
    }
}

TEST(HostileShading, ZeroGradientFallsBackToMinusDir) {
    const double flat[8] = {DBL_MAX, DBL_MAX, DBL_MAX, DBL_MAX, DBL_MAX, DBL_MAX, DBL_MAX, DBL_MAX};
    const std::array<double, 3> dir{0, 0, 1};
    const auto n = world_normal(flat, {0.5, 0.5, 0.5}, {1, 1, 1}, dir);
    EXPECT_EQ(n[0], 0.0);
    EXPECT_EQ(n[1], 0.0);
    EXPECT_EQ(n[2], -1.0);
}

TEST(HostileShading, SrgbTableNeverIndexedWithNanOrInf) {
    const SrgbTable& t = SrgbTable::instance();
    EXPECT_EQ(t(std::numeric_limits<float>::quiet_NaN()), t(0.0f));
    EXPECT_EQ(t(-std::numeric_limits<float>::quiet_NaN()), t(0.0f));
    EXPECT_EQ(t(std::numeric_limits<float>::infinity()), t(1.0f));
    EXPECT_EQ(t(-std::numeric_limits<float>::infinity()), t(0.0f));
    EXPECT_EQ(t(1e30f), 255);
    EXPECT_EQ(t(-1e30f), 0);
}

/// The issue's 2x2x2 f64 volume, converted and rendered end to end: exit 0 and every pixel of
/// the normal image a finite unit vector or 0,0,0 (miss), under each root finder.
TEST(HostileShading, IssueVolumeRendersWithFiniteNormalsAndColours) {
    ScratchDir dir("octiso_hostile_shading");
    const double v[8] = {1.7976931348623157e308, 1e308, -1.7976931348623157e308, 0.6, -1e308, 0.6, DBL_MAX, 1e308};
    write_bytes(dir.file("v.raw"), v, sizeof v);
    const std::string err = dir.file("err.txt");
    RunResult r = run_capture("'" + tool("octiso-convert") + "' '" + dir.file("v.raw") + "' --dims 2,2,2 --type f64 -o '" +
                                  dir.file("v.oct") + "'", err);
    ASSERT_EQ(r.exit_status, 0) << r.err;
    ASSERT_NO_THROW(verify_octree(OctFile::open(dir.file("v.oct"))));
    for (const char* finder : {"neubauer", "schwarze", "linear", "exact"}) {
        SCOPED_TRACE(finder);
        r = run_capture("'" + tool("octiso-render") + "' '" + dir.file("v.oct") + "' --iso 0.5 --size 96x96 --root-finder " +
                            finder + " -o '" + dir.file("c.png") + "' --normal '" + dir.file("n.exr") + "' --depth '" +
                            dir.file("d.exr") + "'", err);
        ASSERT_EQ(r.signal, 0) << r.err;
        ASSERT_EQ(r.exit_status, 0) << r.err;
        const FloatImage n = read_image(dir.file("n.exr"));
        const FloatImage d = read_image(dir.file("d.exr"));
        ASSERT_EQ(n.channels, 3);
        size_t hits = 0;
        for (size_t p = 0; p < size_t(n.width) * size_t(n.height); ++p) {
            const float* q = &n.pixels[3 * p];
            ASSERT_TRUE(std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2])) << "pixel " << p;
            const float len2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2];
            if (len2 == 0) continue;
            ++hits;
            EXPECT_NEAR(len2, 1.0f, 1e-4f) << "pixel " << p;
            ASSERT_FALSE(std::isnan(d.pixels[p])) << "pixel " << p;
        }
        EXPECT_GT(hits, 0u) << "the view must show the surface";
    }
}

}  // namespace
}  // namespace octiso::test
