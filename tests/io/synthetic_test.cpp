// Synthetic generators (src/volume/synthetic.cpp) against independent definitions: the sphere's
// distance, the Marschner-Lobb formula, the Menger sponge's solid count (20^L of 27^L cells);
// statistical shape of noise, plume and mixing (uniform 2x2x2 blocks, ambient values); name
// parsing; and determinism across thread counts and repeated runs.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <cmath>
#include <numbers>
#include <set>

#include "octiso/error.h"
#include "octiso/synthetic.h"

namespace octiso::test {
namespace {

template <typename T> double uniform_block_fraction(const std::vector<T>& v, Dims d) {
    uint64_t uniform = 0, total = 0;
    for (uint32_t z = 0; z + 1 < d.z; z += 2)
        for (uint32_t y = 0; y + 1 < d.y; y += 2)
            for (uint32_t x = 0; x + 1 < d.x; x += 2) {
                const T s = v[x + uint64_t(d.x) * (y + uint64_t(d.y) * z)];
                bool same = true;
                for (int c = 0; c < 8; ++c)
                    same &= v[(x + (c & 1)) + uint64_t(d.x) * ((y + ((c >> 1) & 1)) + uint64_t(d.y) * (z + (c >> 2)))] == s;
                uniform += same;
                ++total;
            }
    return double(uniform) / double(total);
}

TEST(Synthetic, ParsesNamesAndSizes) {
    SyntheticSpec s = parse_synthetic("sphere:16");
    EXPECT_EQ(s.name, "sphere");
    EXPECT_EQ(s.dims, (Dims{16, 16, 16}));
    EXPECT_EQ(s.steps, 1u);
    s = parse_synthetic("sierpinski:27,9,3");
    EXPECT_EQ(s.name, "sponge");
    EXPECT_EQ(s.dims, (Dims{27, 9, 3}));
    s = parse_synthetic("plume-series:32,5");
    EXPECT_EQ(s.dims, (Dims{32, 32, 32}));
    EXPECT_EQ(s.steps, 5u);
    s = parse_synthetic("plume-series:8,9,10,2");
    EXPECT_EQ(s.dims, (Dims{8, 9, 10}));
    EXPECT_EQ(s.steps, 2u);
    for (const char* bad : {"sphere", "sphere:", "sphere:0", "sphere:4,4", "sphere:4,4,4,4", "teapot:8", "sphere:x",
                            "plume-series:8", "sphere:2000000000"})
        EXPECT_THROW(parse_synthetic(bad), Error) << bad;
    EXPECT_EQ(synthetic_names().size(), 8u);
}

TEST(Synthetic, CtHeadHasAirTissueBoneAndNoise) {
    const Dims d{64, 64, 32};
    EXPECT_EQ(synthetic_default_type("ct-head"), ScalarType::i16);
    const std::vector<int16_t> v = generate_synthetic<int16_t>("ct-head", d);
    EXPECT_EQ(v, generate_synthetic<int16_t>("ct-head", d)) << "deterministic";
    auto at = [&](uint32_t x, uint32_t y, uint32_t z) { return double(v[x + d.x * (y + uint64_t(d.y) * z)]); };
    EXPECT_NEAR(at(0, 0, 0), -1000, 18.01) << "air, noise within +-18 HU";
    EXPECT_NEAR(at(32, 32, 16), 37.5, 26) << "brain";
    // Along +x from the centre: brain, then the skull (dense bone), then skin, then air.
    double peak = -2000;
    for (uint32_t x = 32; x < 64; ++x) peak = std::max(peak, at(x, 32, 16));
    EXPECT_GT(peak, 700) << "bone (the shell is under 2 voxels thick at this size, so partial volume lowers it)";
    // Noise: neighbours in the air differ (a real scan never merges).
    int differ = 0;
    for (uint32_t x = 0; x + 1 < 8; ++x) differ += at(x, 0, 0) != at(x + 1, 0, 0);
    EXPECT_GE(differ, 5);
}

TEST(Synthetic, SphereIsTheDistanceFromTheCentre) {
    const Dims d{9, 6, 5};
    const std::vector<float> f = generate_synthetic<float>("sphere", d);
    const std::vector<uint8_t> u = generate_synthetic<uint8_t>("sphere", d);
    for (uint32_t z = 0; z < d.z; ++z)
        for (uint32_t y = 0; y < d.y; ++y)
            for (uint32_t x = 0; x < d.x; ++x) {
                const double r = std::hypot(x - 4.0, y - 2.5, z - 2.0);
                const uint64_t i = x + 9u * (y + 6u * z);
                ASSERT_NEAR(f[i], r, 1e-5);
                ASSERT_EQ(u[i], uint8_t(std::lround(r)));
            }
}

TEST(Synthetic, MarschnerLobbMatchesItsDefinition) {
    const Dims d{17, 17, 17};
    const std::vector<double> v = generate_synthetic<double>("marschner-lobb", d);
    const double pi = std::numbers::pi, alpha = 0.25, fm = 6;
    for (uint32_t k = 0; k < d.z; ++k)
        for (uint32_t j = 0; j < d.y; ++j)
            for (uint32_t i = 0; i < d.x; ++i) {
                const double x = -1 + i / 8.0, y = -1 + j / 8.0, z = -1 + k / 8.0;
                const double pr = std::cos(2 * pi * fm * std::cos(pi * std::sqrt(x * x + y * y) / 2));
                const double expected = (1 - std::sin(pi * z / 2) + alpha * (1 + pr)) / (2 * (1 + alpha));
                ASSERT_NEAR(v[i + 17u * (j + 17u * k)], expected, 1e-12);
            }
    // integer types use the 0..255 scale
    const std::vector<uint8_t> u = generate_synthetic<uint8_t>("marschner-lobb", d);
    for (size_t i = 0; i < u.size(); ++i) ASSERT_EQ(u[i], uint8_t(std::lround(v[i] * 255))) << i;
}

TEST(Synthetic, SpongeHasTwentyOfTwentySevenCellsPerLevel) {
    for (const uint32_t n : {9u, 27u, 81u}) {
        const std::vector<uint8_t> v = generate_synthetic<uint8_t>("sponge", {n, n, n});
        uint64_t solid = 0;
        for (uint8_t s : v) {
            ASSERT_TRUE(s == 0 || s == 255);
            solid += s == 255;
        }
        const uint64_t levels = n == 9 ? 2 : n == 27 ? 3 : 4;
        EXPECT_EQ(solid, uint64_t(std::pow(20.0, double(levels)))) << n;
        EXPECT_EQ(v[0], 255);                                        // a corner is solid
        EXPECT_EQ(v[n / 2 + uint64_t(n) * (n / 2 + uint64_t(n) * (n / 2))], 0);   // the centre is a hole
    }
}

TEST(Synthetic, NoiseLeavesNothingUniform) {
    const Dims d{48, 48, 48};
    const std::vector<uint8_t> v = generate_synthetic<uint8_t>("noise", d);
    EXPECT_LT(uniform_block_fraction(v, d), 0.01);
    const std::set<uint8_t> distinct(v.begin(), v.end());
    EXPECT_GT(distinct.size(), 150u);
}

TEST(Synthetic, PlumeLooksLikeSimulationOutput) {
    for (const uint32_t n : {64u, 96u}) {
        const Dims d{n, n, n};
        const std::vector<uint8_t> v = generate_synthetic<uint8_t>("plume", d);
        const double f = uniform_block_fraction(v, d);
        EXPECT_GE(f, 0.40) << n;
        EXPECT_LE(f, 0.80) << n;
        // ambient air everywhere along the bottom edges, hot core above the nozzle
        EXPECT_EQ(v[0], 0);
        EXPECT_EQ(v[n - 1], 0);
        EXPECT_EQ(v[n / 2 + uint64_t(n) * (n / 2 + uint64_t(n) * 2)], 255);
        const std::set<uint8_t> distinct(v.begin(), v.end());
        EXPECT_GT(distinct.size(), 100u) << "the interface should carry many levels";
    }
}

TEST(Synthetic, MixingLayerSeparatesTwoFluids) {
    for (const uint32_t n : {64u, 96u}) {
        const Dims d{n, n, n};
        const std::vector<uint8_t> v = generate_synthetic<uint8_t>("mixing", d);
        const double f = uniform_block_fraction(v, d);
        EXPECT_GE(f, 0.40) << n;
        EXPECT_LE(f, 0.80) << n;
        const uint64_t plane = uint64_t(n) * n;
        for (uint64_t i = 0; i < plane; ++i) {
            ASSERT_EQ(v[i], 255) << "bottom plane is heavy fluid";
            ASSERT_EQ(v[(n - 1) * plane + i], 0) << "top plane is light fluid";
        }
        // the mid plane is mixed: both fluids and intermediate values
        const std::set<uint8_t> mid(v.begin() + (n / 2) * plane, v.begin() + (n / 2 + 1) * plane);
        EXPECT_GT(mid.size(), 50u);
    }
}

TEST(Synthetic, TypesShareOneScale) {
    const Dims d{24, 24, 24};
    const std::vector<uint8_t> u8 = generate_synthetic<uint8_t>("plume", d);
    const std::vector<uint16_t> u16 = generate_synthetic<uint16_t>("plume", d);
    const std::vector<float> f32 = generate_synthetic<float>("plume", d);
    const std::vector<int8_t> i8 = generate_synthetic<int8_t>("sponge", d);
    for (size_t i = 0; i < u8.size(); ++i) {
        ASSERT_EQ(u16[i], u8[i]);
        ASSERT_EQ(f32[i], float(u8[i]));   // quantized on every type
    }
    for (int8_t s : i8) ASSERT_TRUE(s == 0 || s == 127);   // 255 clamps into i8
}

TEST(Synthetic, DeterministicAcrossThreadCounts) {
    const Dims d{40, 33, 29};
    for (const char* name : {"plume", "mixing", "noise", "marschner-lobb"}) {
        std::vector<float> one, all;
        {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
            one = generate_synthetic<float>(name, d);
        }
        all = generate_synthetic<float>(name, d);
        EXPECT_TRUE(one == all) << name;
        EXPECT_TRUE(generate_synthetic<float>(name, d) == all) << name;
    }
}

TEST(Synthetic, PlumeSeriesStepsEvolve) {
    const Dims d{48, 48, 48};
    const std::vector<uint8_t> plume = generate_synthetic<uint8_t>("plume", d);
    const std::vector<uint8_t> s0 = generate_synthetic<uint8_t>("plume-series", d, 0);
    const std::vector<uint8_t> s1 = generate_synthetic<uint8_t>("plume-series", d, 1);
    const std::vector<uint8_t> s5 = generate_synthetic<uint8_t>("plume-series", d, 5);
    EXPECT_TRUE(s0 == plume);
    uint64_t diff1 = 0, diff5 = 0;
    for (size_t i = 0; i < s0.size(); ++i) {
        diff1 += s0[i] != s1[i];
        diff5 += s0[i] != s5[i];
    }
    EXPECT_GT(diff1, 0u);
    EXPECT_GT(diff5, diff1) << "steps further apart differ more";
    const double f0 = uniform_block_fraction(s0, d), f5 = uniform_block_fraction(s5, d);
    EXPECT_NEAR(f0, f5, 0.1);
}

TEST(Synthetic, StepsComeAsLoadedVolumes) {
    const Dims d{10, 12, 14};
    const LoadedVolume v = synthetic_step("plume-series", d, 3, ScalarType::u16);
    EXPECT_EQ(v.type(), ScalarType::u16);
    EXPECT_EQ(v.dims(), d);
    EXPECT_EQ(v.format(), VolumeFormat::synthetic);
    const std::vector<uint16_t> ref = generate_synthetic<uint16_t>("plume-series", d, 3);
    const VolumeView<uint16_t> view = v.view<uint16_t>();
    for (uint64_t i = 0; i < d.voxels(); ++i) ASSERT_EQ(view.load(i), ref[i]);
    EXPECT_EQ(make_synthetic(parse_synthetic("sphere:4")).type(), ScalarType::f32);
    EXPECT_EQ(synthetic_default_type("mixing"), ScalarType::u8);
    EXPECT_THROW(synthetic_step("teapot", d, 0), Error);
}

}  // namespace
}  // namespace octiso::test
