// Tests for src/reference/brute_force.h and src/render/ray.h on analytic fields (no octree):
// planes sampled in all scalar types under anisotropic placement, signed-zero axis rays, rays at
// lattice vertices (E9), eyes inside the data, non-finite voxels, 1-wide volumes, far-out cell
// indices (E11), and a curved field against an independent fine march.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "reference/brute_force.h"

namespace octiso {
namespace {

using P3 = std::array<double, 3>;
const double kInf = std::numeric_limits<double>::infinity();

/// A dense x-fastest volume owning its values, with a view.
template <typename T> struct Dense {
    Dims dims;
    std::vector<T> values;
    template <class Fn> Dense(Dims d, Fn fn) : dims(d), values(size_t(d.voxels())) {
        for (uint32_t z = 0; z < d.z; ++z)
            for (uint32_t y = 0; y < d.y; ++y)
                for (uint32_t x = 0; x < d.x; ++x) values[x + size_t(d.x) * (y + size_t(d.y) * z)] = T(fn(x, y, z));
    }
    VolumeView<T> view() const { return {reinterpret_cast<const std::byte*>(values.data()), dims, false}; }
};

P3 normalized(P3 v) {
    const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    return {v[0] / n, v[1] / n, v[2] / n};
}
double dot(P3 a, P3 b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/// Exact first hit of a ray with the plane {sum_a w_a * p_index_a == iso} restricted to the data
/// box, t >= 0; +inf on a miss. `margin` > 0 returns NaN when the answer is within margin (index
/// units) of the box surface, where the data's closed/half-open edges decide.
double plane_hit(const P3& w, double iso, const Ray& ray, const Placement& pl, Dims dims, double margin) {
    const IndexRay r = index_from_world(ray, pl);
    const double f0 = dot(w, r.origin), df = dot(w, r.dir);
    if (df == 0) return kInf;
    const double t = (iso - f0) / df;
    if (t < 0) return kInf;
    const double hi[3] = {double(dims.x - 1), double(dims.y - 1), double(dims.z - 1)};
    bool inside = true, near = false;
    for (int a = 0; a < 3; ++a) {
        const double p = r.origin[a] + t * r.dir[a];
        inside &= p >= 0 && p <= hi[a];
        near |= std::fabs(p) < margin || std::fabs(p - hi[a]) < margin;
    }
    if (near) return std::numeric_limits<double>::quiet_NaN();
    return inside ? t : kInf;
}

template <typename T> class BruteForceTyped : public ::testing::Test {};
using ScalarTypes = ::testing::Types<uint8_t, int8_t, uint16_t, int16_t, uint32_t, int32_t, float, double>;
TYPED_TEST_SUITE(BruteForceTyped, ScalarTypes);

TYPED_TEST(BruteForceTyped, PlanesUnderAnisotropicPlacementHitExactly) {
    using T = TypeParam;
    const Dims dims{6, 5, 4};
    const P3 w{1, 2, 3};   // x + 2y + 3z in index space: <= 22, fits every type; exact in trilinear
    const Dense<T> vol(dims, [&](uint32_t x, uint32_t y, uint32_t z) { return w[0] * x + w[1] * y + w[2] * z; });
    Placement pl;
    pl.spacing = {0.5, 2.0, 1.25};
    pl.origin = {-1.0, 3.0, 0.5};
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> u(-1, 1);
    const P3 centre{pl.origin[0] + 2.5 * 0.5, pl.origin[1] + 2 * 2.0, pl.origin[2] + 1.5 * 1.25};
    int hits = 0;
    for (int n = 0; n < 3000; ++n) {
        const double iso = 0.37 + 20 * (0.5 + 0.5 * u(rng));
        Ray ray;
        const double reach = n % 3 == 0 ? 2.0 : 12.0;   // a third of the eyes start inside the data
        for (int a = 0; a < 3; ++a) ray.origin[a] = centre[a] + reach * u(rng);
        const P3 target{centre[0] + 1.5 * u(rng), centre[1] + 5 * u(rng), centre[2] + 2.5 * u(rng)};
        ray.dir = n % 5 == 0 ? normalized({u(rng), u(rng), u(rng)})
                             : normalized({target[0] - ray.origin[0], target[1] - ray.origin[1], target[2] - ray.origin[2]});
        const double t_exact = plane_hit(w, iso, ray, pl, dims, 1e-9);
        if (std::isnan(t_exact)) continue;
        const RefHit hit = trace_reference(vol.view(), pl, ray, iso);
        ASSERT_EQ(hit.is_hit(), t_exact < kInf) << "ray " << n << " iso " << iso;
        if (!hit.is_hit()) continue;
        ++hits;
        EXPECT_NEAR(hit.t, t_exact, 1e-11 * (1 + t_exact)) << n;
        const P3 n_exact = normalized({w[0] / pl.spacing[0], w[1] / pl.spacing[1], w[2] / pl.spacing[2]});
        const double sign = dot(n_exact, ray.dir) > 0 ? -1 : 1;
        for (int a = 0; a < 3; ++a) EXPECT_NEAR(hit.normal[a], sign * n_exact[a], 1e-12) << n;
    }
    EXPECT_GT(hits, 400);
}

TEST(BruteForce, OtherRootFindersAgreeOnPlanes) {
    const Dims dims{7, 6, 5};
    const Dense<float> vol(dims, [](uint32_t x, uint32_t y, uint32_t z) { return 0.5f * x - 1.0f * y + 2.0f * z; });
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int n = 0; n < 500; ++n) {
        Ray ray;
        ray.origin = {3 + 8 * u(rng), 2.5 + 8 * u(rng), 2 + 8 * u(rng)};
        ray.dir = normalized({u(rng), u(rng), u(rng)});
        const RefHit ref = trace_reference(vol.view(), Placement{}, ray, 1.3);
        const RefHit a = trace_reference(vol.view(), Placement{}, ray, 1.3, Neubauer{});
        const RefHit b = trace_reference(vol.view(), Placement{}, ray, 1.3, Schwarze{});
        const RefHit c = trace_reference(vol.view(), Placement{}, ray, 1.3, Linear{});
        for (const RefHit* h : {&a, &b, &c}) {
            ASSERT_EQ(h->is_hit(), ref.is_hit()) << n;
            if (ref.is_hit()) {
                EXPECT_NEAR(h->t, ref.t, 1e-12 * (1 + ref.t)) << n;
            }
        }
    }
}

TEST(BruteForce, AxisAlignedRaysWithSignedZeroComponents) {
    const Dims dims{8, 6, 5};
    const P3 w{1, 2, 3};
    const Dense<double> vol(dims, [&](uint32_t x, uint32_t y, uint32_t z) { return w[0] * x + w[1] * y + w[2] * z; });
    const double z0 = 0.0;
    int tested = 0;
    for (double y : {0.0, 0.5, 1.0, 2.25, 5.0}) {        // 0, 1 and 5: on cell faces and the box face
        for (double zz : {0.0, 1.0, 1.75, 4.0}) {
            for (const P3 dir : {P3{1, z0, z0}, P3{1, -z0, z0}, P3{1, z0, -z0}, P3{1, -z0, -z0}, P3{-1, z0, -z0},
                                 P3{-1, -z0, z0}}) {
                for (double x0 : {-3.0, 0.0, 2.0, 3.5, 7.0, 10.0}) {
                    const double iso = 3.3 + 2 * y + 3 * zz;   // the plane x == 3.3 on this line
                    Ray ray;
                    ray.origin = {x0, y, zz};
                    ray.dir = dir;
                    const RefHit hit = trace_reference(vol.view(), Placement{}, ray, iso);
                    const double t_exact = (3.3 - x0) / dir[0];
                    if (t_exact >= 0) {
                        ASSERT_TRUE(hit.is_hit()) << x0 << " " << y << " " << zz << " dir " << dir[0];
                        EXPECT_NEAR(hit.t, t_exact, 1e-14);
                        for (double v : hit.normal) EXPECT_FALSE(std::isnan(v));
                        EXPECT_NEAR(hit.normal[0], -dir[0] * 1 / std::sqrt(14.0), 1e-15);
                    } else {
                        EXPECT_FALSE(hit.is_hit());
                    }
                    ++tested;
                }
            }
        }
    }
    EXPECT_EQ(tested, 5 * 4 * 6 * 6);
    // Along the y and z axes too, rays lying in cell faces (x integer) and on box edges.
    for (double x : {0.0, 3.0, 7.0}) {
        for (const P3 dir : {P3{z0, 1, -z0}, P3{-z0, -1, z0}, P3{z0, -z0, 1}, P3{-z0, z0, -1}}) {
            Ray ray;
            ray.origin = {x, dir[1] != 0 ? (dir[1] > 0 ? -2.0 : 8.0) : 1.0, dir[2] != 0 ? (dir[2] > 0 ? -2.0 : 7.0) : 1.0};
            ray.dir = dir;
            const double iso = dir[1] != 0 ? x + 2 * 2.5 + 3 * 1.0 : x + 2 * 1.0 + 3 * 2.5;   // at y or z == 2.5
            const RefHit hit = trace_reference(vol.view(), Placement{}, ray, iso);
            ASSERT_TRUE(hit.is_hit()) << x;
            const double t_exact = dir[1] != 0 ? std::fabs(2.5 - ray.origin[1]) : std::fabs(2.5 - ray.origin[2]);
            EXPECT_NEAR(hit.t, t_exact, 1e-14) << x;
        }
    }
}

TEST(BruteForce, RaysAtLatticeVerticesAlwaysHit) {
    // E9, lattice version: x + 2y + 3z == iso passes exactly through lattice vertices, where up to
    // 8 cells meet and the DDA sees the three face crossings at t values that differ by rounding.
    // Vertices strictly inside the data (on the data's outer surface the exact hit is the last point
    // of the ray inside the data, a tie that rounding may put outside).
    const Dims dims{6, 6, 6};
    const Dense<int16_t> vol(dims, [](uint32_t x, uint32_t y, uint32_t z) { return x + 2 * y + 3 * z; });
    std::mt19937_64 rng(99);
    std::uniform_real_distribution<double> u(-1, 1);
    const P3 vertices[] = {{1, 2, 1}, {3, 1, 1}, {2, 3, 2}, {4, 4, 1}};   // iso = 8, 8, 14, 15
    for (int n = 0; n < 4000; ++n) {
        const P3 v = vertices[n % 4];
        P3 eye;
        if (n % 2) {
            for (int a = 0; a < 3; ++a) eye[a] = v[a] + 6 * u(rng);   // general directions
        } else {
            // Axis-parallel and in-face approaches: move the eye along one or two axes only.
            eye = v;
            const int axis = n / 2 % 3;
            eye[axis] += (n / 6 % 2 ? 4.0 : -4.0);
            if (n / 12 % 2) eye[(axis + 1) % 3] += 2.0;
        }
        Ray ray;
        ray.origin = eye;
        const P3 to{v[0] - eye[0], v[1] - eye[1], v[2] - eye[2]};
        const double dist = std::sqrt(dot(to, to));
        ray.dir = normalized(to);
        const double df = ray.dir[0] + 2 * ray.dir[1] + 3 * ray.dir[2];
        if (std::fabs(df) < 1e-3) continue;   // (nearly) inside the plane
        const double iso = v[0] + 2 * v[1] + 3 * v[2];
        const double f_eye = eye[0] + 2 * eye[1] + 3 * eye[2];
        const double t_plane = (iso - f_eye) / df;   // the plane is met once, at the vertex
        const RefHit hit = trace_reference(vol.view(), Placement{}, ray, iso);
        ASSERT_TRUE(hit.is_hit()) << "crack at vertex (" << v[0] << "," << v[1] << "," << v[2] << ") from (" << eye[0]
                                  << "," << eye[1] << "," << eye[2] << ")";
        EXPECT_NEAR(hit.t, t_plane, 1e-12 * (1 + dist));
    }
}

TEST(BruteForce, EyeInsideTheDataSeesTheFirstCrossing) {
    const Dims dims{9, 9, 9};
    const Dense<double> vol(dims, [](uint32_t x, uint32_t, uint32_t) { return double(x); });
    Ray ray;
    ray.origin = {4.25, 4, 4.5};   // f = 4.25 at the eye
    ray.dir = {-1, 0, 0};
    EXPECT_NEAR(trace_reference(vol.view(), Placement{}, ray, 2.0).t, 2.25, 1e-15);
    EXPECT_FALSE(trace_reference(vol.view(), Placement{}, ray, 6.0).is_hit());   // behind the eye
    ray.dir = {1, 0, 0};
    EXPECT_NEAR(trace_reference(vol.view(), Placement{}, ray, 6.0).t, 1.75, 1e-15);
    ray.origin = {4, 4, 4};   // eye exactly on a lattice vertex where f == iso: hit at t = 0
    EXPECT_EQ(trace_reference(vol.view(), Placement{}, ray, 4.0).t, 0.0);
    ray.dir = {-1, 0, 0};
    EXPECT_EQ(trace_reference(vol.view(), Placement{}, ray, 4.0).t, 0.0);
    // Eye on the box face, looking in and looking along the face.
    ray.origin = {0, 3.5, 2};
    ray.dir = {1, 0, 0};
    EXPECT_NEAR(trace_reference(vol.view(), Placement{}, ray, 2.5).t, 2.5, 1e-15);
    ray.dir = normalized({0, 1, 1});
    EXPECT_FALSE(trace_reference(vol.view(), Placement{}, ray, 2.5).is_hit());
    EXPECT_EQ(trace_reference(vol.view(), Placement{}, ray, 0.0).t, 0.0);
    // A ray leaving through the far face: the last cell owns its closed end.
    ray.origin = {7.5, 1, 1};
    ray.dir = {1, 0, 0};
    EXPECT_NEAR(trace_reference(vol.view(), Placement{}, ray, 8.0).t, 0.5, 1e-15);
    ray.origin = {-2, 8, 8};   // the top edge of the box, touching only
    EXPECT_NEAR(trace_reference(vol.view(), Placement{}, ray, 8.0).t, 10.0, 1e-15);
    ray.origin = {9.5, 8, 8};
    ray.dir = normalized({-1, 1, 0});   // misses the box: only the region y > 8
    EXPECT_FALSE(trace_reference(vol.view(), Placement{}, ray, 8.0).is_hit());
}

TEST(BruteForce, NonFiniteVoxelsSkipTheirCellsAndTheRayContinues) {
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    const double line[6] = {0, 1, 2, 3, 2, 5};   // iso 2.5 crossed at x = 2.5 and x = 3.5
    for (double bad : {nan, inf, -inf}) {
        const Dense<double> vol({6, 3, 3}, [&](uint32_t x, uint32_t y, uint32_t z) {
            return x == 2 && y == 1 && z == 1 ? bad : line[x];
        });
        Ray ray;
        ray.origin = {-1, 1, 1};   // along the voxel row through the bad voxel
        ray.dir = {1, 0, 0};
        const RefHit hit = trace_reference(vol.view(), Placement{}, ray, 2.5);
        ASSERT_TRUE(hit.is_hit());
        EXPECT_NEAR(hit.t, 4.5, 1e-15);   // x = 3.5: the cells touching the bad voxel were skipped
        for (double v : hit.normal) EXPECT_TRUE(std::isfinite(v));
        ray.origin = {-1, 0.5, 0.5};
        EXPECT_NEAR(trace_reference(vol.view(), Placement{}, ray, 2.5).t, 4.5, 1e-15);
    }
    const Dense<float> fl({4, 2, 2}, [](uint32_t x, uint32_t, uint32_t) {
        return x == 1 ? std::numeric_limits<float>::quiet_NaN() : float(x);
    });
    Ray ray;
    ray.origin = {-1, 0.5, 0.5};
    ray.dir = {1, 0, 0};
    EXPECT_NEAR(trace_reference(fl.view(), Placement{}, ray, 2.5).t, 3.5, 1e-15);
}

TEST(BruteForce, OneWideVolumesHaveNoCells) {
    for (const Dims d : {Dims{1, 5, 5}, Dims{5, 1, 5}, Dims{5, 5, 1}, Dims{1, 1, 1}}) {
        const Dense<uint8_t> vol(d, [](uint32_t x, uint32_t y, uint32_t z) { return uint8_t(x + y + z); });
        Ray ray;
        ray.origin = {-3, 0.0, 0.0};
        ray.dir = normalized({1, 0.3, 0.2});
        for (double iso : {0.0, 0.5, 1.0, 2.0}) EXPECT_FALSE(trace_reference(vol.view(), Placement{}, ray, iso).is_hit());
    }
}

TEST(BruteForce, DegenerateRaysNeverHitAndNeverLoop) {
    const Dense<double> vol({4, 4, 4}, [](uint32_t x, uint32_t, uint32_t) { return double(x); });
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (const Ray& ray : {Ray{{1, 1, 1}, {0, 0, 0}}, Ray{{nan, 1, 1}, {1, 0, 0}}, Ray{{1, 1, 1}, {nan, 0, 0}},
                           Ray{{kInf, 1, 1}, {-1, 0, 0}}}) {
        EXPECT_FALSE(trace_reference(vol.view(), Placement{}, ray, 1.5).is_hit());
    }
}

TEST(BruteForce, FarCellIndicesKeepLocalPrecision) {
    // E11: the same local set-up at cell indices 2^10 .. 2^20 (values alternate 0,1 along x).
    for (int e : {10, 16, 20}) {
        const uint32_t base = 1u << e;
        const Dense<uint8_t> vol({base + 2, 2, 2}, [](uint32_t x, uint32_t, uint32_t) { return uint8_t(x & 1); });
        Placement pl;
        pl.origin = {-double(base), 0, 0};   // world x of cell `base` is 0
        for (const P3 dir : {P3{1, 0, 0}, normalized({1, 1e-3, 0}), normalized({1, 0.3, 0.4})}) {
            Ray ray;
            ray.origin = {0.25, 0.1, 0.2};
            ray.dir = dir;
            const RefHit hit = trace_reference(vol.view(), pl, ray, 0.5);
            ASSERT_TRUE(hit.is_hit()) << e;
            EXPECT_NEAR(hit.t, 0.25 / dir[0], 1e-9) << e;   // x_index == base + 1/2
            EXPECT_EQ(hit.cell[0], base);
        }
    }
}

/// Independent check on a curved field: march the trilinear interpolant in fine steps straight
/// from the array (no DDA, no cubic), then bisect the first sign change.
double march_first_root(const Dense<double>& vol, const Ray& ray, double iso, double t_max) {
    auto f = [&](double t) {
        double p[3];
        uint32_t c[3];
        const uint32_t n[3] = {vol.dims.x, vol.dims.y, vol.dims.z};
        for (int a = 0; a < 3; ++a) {
            p[a] = ray.origin[a] + t * ray.dir[a];
            if (p[a] < 0 || p[a] > n[a] - 1) return nan("");
            c[a] = std::min(uint32_t(p[a]), n[a] - 2);
            p[a] -= c[a];
        }
        double v = 0;
        for (int k = 0; k < 2; ++k)
            for (int j = 0; j < 2; ++j)
                for (int i = 0; i < 2; ++i)
                    v += vol.values[(c[0] + i) + size_t(vol.dims.x) * ((c[1] + j) + size_t(vol.dims.y) * (c[2] + k))] *
                         (i ? p[0] : 1 - p[0]) * (j ? p[1] : 1 - p[1]) * (k ? p[2] : 1 - p[2]);
        return v - iso;
    };
    const double step = 1e-3;
    double t0 = 0, f0 = f(0);
    for (double t = step; t <= t_max; t += step) {
        const double f1 = f(t);
        if (std::isnan(f1)) break;
        if ((f0 < 0) != (f1 < 0)) {
            double a = t0, b = t;
            for (int it = 0; it < 80; ++it) {
                const double m = 0.5 * (a + b);
                ((f(m) < 0) == (f0 < 0) ? a : b) = m;
            }
            return 0.5 * (a + b);
        }
        t0 = t, f0 = f1;
    }
    return kInf;
}

TEST(BruteForce, CurvedFieldMatchesAFineMarchFromAnInsideEye) {
    const Dims dims{12, 11, 10};
    const P3 c{5.3, 4.9, 4.6};
    const Dense<double> vol(dims, [&](uint32_t x, uint32_t y, uint32_t z) {
        return (x - c[0]) * (x - c[0]) + (y - c[1]) * (y - c[1]) + (z - c[2]) * (z - c[2]);
    });
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-1, 1);
    int hits = 0;
    for (int n = 0; n < 300; ++n) {
        Ray ray;
        ray.origin = {c[0] + u(rng), c[1] + u(rng), c[2] + u(rng)};
        ray.dir = normalized({u(rng), u(rng), u(rng)});
        const RefHit hit = trace_reference(vol.view(), Placement{}, ray, 16.0);   // "sphere" of radius ~4
        const double t_march = march_first_root(vol, ray, 16.0, 30.0);
        ASSERT_EQ(hit.is_hit(), t_march < kInf) << n;
        if (hit.is_hit()) {
            ++hits;
            EXPECT_NEAR(hit.t, t_march, 1e-9) << n;
        }
    }
    EXPECT_GT(hits, 250);
}

TEST(RayClip, SignedZeroAndDegenerateBoxes) {
    const double z = 0.0;
    IndexRay r = IndexRay::make({-1, 2, 3}, {1, -z, z});
    BoxClip clip = clip_to_box(r, {4, 4, 4});
    EXPECT_EQ(clip.t_in, 1.0);
    EXPECT_EQ(clip.t_out, 5.0);
    r.origin = {-1, 4, 0};   // on the box edge
    clip = clip_to_box(r, {4, 4, 4});
    EXPECT_FALSE(clip.empty());
    r.origin = {-1, std::nextafter(4.0, 5.0), 0};
    EXPECT_TRUE(clip_to_box(r, {4, 4, 4}).empty());
    r = IndexRay::make({2, 2, 2}, {-1, 0, 0});   // origin inside: t_in clamps to 0
    clip = clip_to_box(r, {4, 4, 4});
    EXPECT_EQ(clip.t_in, 0.0);
    EXPECT_EQ(clip.t_out, 2.0);
    EXPECT_TRUE(clip_to_box(IndexRay::make({2, 2, 2}, {0, 0, 0}), {4, 4, 4}).empty());
    EXPECT_EQ(r.plane_t(1, 3.0), kInf);
    Placement pl;
    pl.spacing = {2, 4, 0.5};
    pl.origin = {1, 1, 1};
    const IndexRay ir = index_from_world(Ray{{3, 5, 2}, {1, 0, 0}}, pl);
    EXPECT_EQ(ir.origin[0], 1.0);
    EXPECT_EQ(ir.origin[1], 1.0);
    EXPECT_EQ(ir.origin[2], 2.0);
    EXPECT_EQ(ir.dir[0], 0.5);
}

}  // namespace
}  // namespace octiso
