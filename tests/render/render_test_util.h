// Shared by the renderer tests (octree and macrocell grid): synthetic fields in [0, 120] that every
// scalar type holds, a look-at camera, and agreement with the dense exact-root reference measured
// with the library's CONVENTIONS 4 metrics (render_reference + compare_frames).
#pragma once

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "octiso/render.h"
#include "octree/octree_test_util.h"
#include "reference/reference_render.h"

namespace octiso::test {

enum class Field { Sphere, MarschnerLobb, Noise, Sierpinski, Torus };

/// Fields with values in [0, 120] (so every type, i8 included, holds them), rounded for integer types.
template <typename T> inline DenseVolume<T> make_field(Field field, Dims dims, uint32_t seed = 1) {
    DenseVolume<T> v{dims, std::vector<T>(dims.voxels())};
    std::mt19937 rng(seed);
    std::vector<double> lattice(512);
    for (double& x : lattice) x = std::uniform_real_distribution<double>(0, 255)(rng);
    for (uint32_t z = 0; z < dims.z; ++z)
        for (uint32_t y = 0; y < dims.y; ++y)
            for (uint32_t x = 0; x < dims.x; ++x) {
                const double u = (x + 0.5) / dims.x * 2 - 1, w = (y + 0.5) / dims.y * 2 - 1, q = (z + 0.5) / dims.z * 2 - 1;
                double f = 0;
                switch (field) {
                    case Field::Sphere: f = 255 * (1 - std::sqrt(u * u + w * w + q * q) / std::sqrt(3.0)); break;
                    case Field::MarschnerLobb: {
                        const double r = std::sqrt(u * u + w * w);
                        const double rho = std::cos(2 * M_PI * 6 * std::cos(M_PI * r / 2));
                        f = 255 * (1 - std::sin(M_PI * q / 2) + 0.25 * (1 + rho)) / (2 * 1.25);
                        break;
                    }
                    case Field::Noise: f = lattice[(x * 73856093u ^ y * 19349663u ^ z * 83492791u) % 512]; break;
                    case Field::Sierpinski: {
                        uint32_t a = x, b = y, c = z;
                        bool hole = false;
                        while (a || b || c) {
                            hole |= ((a % 3 == 1) + (b % 3 == 1) + (c % 3 == 1)) >= 2;
                            a /= 3, b /= 3, c /= 3;
                        }
                        f = hole ? 0 : 255;
                        break;
                    }
                    case Field::Torus: {
                        const double ring = std::sqrt(u * u + w * w) - 0.55;
                        f = 255 * std::clamp(1 - std::sqrt(ring * ring + q * q) / 0.6, 0.0, 1.0);
                        break;
                    }
                }
                f *= 120.0 / 255.0;
                if constexpr (!std::is_floating_point_v<T>) f = std::round(f);
                v.values[x + uint64_t(dims.x) * (y + uint64_t(dims.y) * z)] = T(f);
            }
    return v;
}

inline Camera look_at(std::array<double, 3> eye, std::array<double, 3> look, std::array<double, 3> up, double fov, int size) {
    Camera c;
    c.eye = eye, c.look = look, c.up = up, c.fov_deg = fov, c.width = c.height = size;
    return c;
}

/// The traversal kernels this CPU runs: the portable one, and AVX2 where the CPU has it.
inline std::vector<Isa> kernel_isas() {
    std::vector<Isa> isas{Isa::baseline};
    if (cpu_has_avx2()) isas.push_back(Isa::avx2);
    return isas;
}

/// `frame` (depth needed) against the exact reference of the dense volume at `iso`.
template <typename T>
ImageError error_against_reference(const Frame& frame, const VolumeView<T>& dense, const Placement& placement,
                                   const Camera& camera, double iso) {
    const Frame ref = render_reference(dense, placement, camera, {iso});
    return compare_frames(frame, ref, std::min({placement.spacing[0], placement.spacing[1], placement.spacing[2]}));
}

/// What the default root finder (Neubauer, 5 Illinois steps) achieves, measured over all 230
/// agreement frames of the render and macrocell suites (1600 to 3136 pixels each): at most 4 pixels
/// of a frame have depth off by more than 1e-3 voxel, the worst 0.0172 voxel (noise 37x30x33 u8,
/// OctreeOverArrayData). They are the finder's: the same frames rendered with RootFinder::exact
/// have none (RenderAgreementFields checks that on its cases).
struct DepthBar {
    uint64_t max_above_1e3 = 4;    ///< pixels with depth error > 1e-3 voxel
    double max_voxels = 0.018;     ///< the largest depth error
};
inline constexpr DepthBar kExactFinderBar{0, 1e-3};

/// The renderer tests' bar, which is what the renderer achieves, not a tolerance it may use up:
/// the same hit mask as the exact reference (the reference marks no pixel as ambiguous, so every
/// mismatch counts), the depth bar above, and a view that actually shows the surface.
inline void expect_agreement(const ImageError& e, const std::string& what, DepthBar bar = {}) {
    SCOPED_TRACE(what);
    EXPECT_EQ(e.mask_mismatch, 0u) << e.mask_mismatch << " of " << e.pixels << " pixels differ";
    EXPECT_LE(e.depth_above_1e3, bar.max_above_1e3) << "pixels with depth error > 1e-3 voxel (p99 " << e.depth_p99 << ")";
    EXPECT_LE(e.depth_max, bar.max_voxels) << "largest depth error in voxels";
    EXPECT_GT(e.both_hit, 0u) << "the view must actually show the surface";
}

}  // namespace octiso::test
