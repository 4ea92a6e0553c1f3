// Tests for src/octree/sparse_synthetic.h: on small grids the directly built octree equals
// build_octree of the dense array node for node (layout, min/max, padding); at 16384^3 and 2^30
// virtual voxels it passes the .oct loader's full validation and renders with depth error
// <= 1e-3 voxel against an exact reference that never builds a dense volume: trace_reference
// over each blob's small sub-volume, placed by its world origin.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>

#include "format/oct_test_util.h"
#include "octiso/error.h"
#include "octiso/render.h"
#include "octree/sparse_synthetic.h"
#include "reference/brute_force.h"
#include "render/pinhole_camera.h"
#include "render/traverse.h"
#include "test_util/run_shell.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

template <typename T> DenseVolume<T> dense_of(const SparseSpheres& f) {
    DenseVolume<T> v{f.dims, std::vector<T>(f.dims.voxels())};
    for (uint32_t z = 0; z < f.dims.z; ++z)
        for (uint32_t y = 0; y < f.dims.y; ++y)
            for (uint32_t x = 0; x < f.dims.x; ++x)
                v.values[x + uint64_t(f.dims.x) * (y + uint64_t(f.dims.y) * z)] = f.value<T>(x, y, z);
    return v;
}

template <typename T> void expect_same_arrays(const OctreeData<T>& a, const OctreeData<T>& b) {
    ASSERT_EQ(a.dmax, b.dmax);
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    for (size_t d = 0; d < a.nodes.size(); ++d) {
        ASSERT_EQ(a.nodes[d].size, b.nodes[d].size) << "depth " << d;
        for (uint64_t i = 0; i < a.nodes[d].size; ++i)
            ASSERT_EQ(std::memcmp(&a.nodes[d].data[i], &b.nodes[d].data[i], sizeof(InteriorNode<T>)), 0)
                << "depth " << d << " node " << i;
    }
    ASSERT_EQ(a.cap_count, b.cap_count);
    ASSERT_EQ(a.cap_bytes, b.cap_bytes);
    ASSERT_EQ(std::memcmp(a.caps.data.get(), b.caps.data.get(), a.cap_bytes + kCapReadSlack), 0) << "packed caps";
    EXPECT_EQ(a.stats.nodes_per_depth, b.stats.nodes_per_depth);
    EXPECT_EQ(a.stats.scalar_leaves_per_depth, b.stats.scalar_leaves_per_depth);
}

template <typename T> class SparseOctreeTyped : public ::testing::Test {};
TYPED_TEST_SUITE(SparseOctreeTyped, AllScalarTypes);

TYPED_TEST(SparseOctreeTyped, EqualsBuildOctreeOfTheDenseArray) {
    using T = TypeParam;
    // Cubes and odd shapes (padding, blobs clipped or cut away by the data box).
    const struct { uint32_t layout; Dims dims; } cases[] = {
        {64, {64, 64, 64}}, {64, {64, 50, 61}}, {64, {37, 64, 45}}, {128, {128, 90, 77}}, {64, {65, 64, 3}}};
    for (const auto& c : cases) {
        SparseSpheres f = sparse_spheres_layout(c.layout);
        f.dims = c.dims;
        const OctreeData<T> direct = build_sparse_octree<T>(f);
        const OctreeData<T> dense = build_octree(dense_of<T>(f).view(), {});
        SCOPED_TRACE(::testing::Message() << c.dims.x << "x" << c.dims.y << "x" << c.dims.z);
        expect_same_arrays(direct, dense);
    }
}

TEST(SparseOctree, RejectsBadSpecs) {
    EXPECT_EQ(parse_sparse_spheres("sphere:64"), 0u);
    EXPECT_EQ(parse_sparse_spheres("sparse-spheres:16384"), 16384u);
    for (const char* bad : {"sparse-spheres", "sparse-spheres:", "sparse-spheres:63", "sparse-spheres:-5",
                            "sparse-spheres:12x", "sparse-spheres:2147483648", "sparse-spheresX:64"})
        EXPECT_THROW(parse_sparse_spheres(bad), Error) << bad;
    SparseSpheres f = sparse_spheres_layout(64);
    f.blobs[0].peak = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(build_sparse_octree<float>(f), Error);
}

/// Exact first hit without a dense array: each blob's support plus one voxel of background on
/// every side as a small dense sub-volume placed at its world origin, traced with Exact; the
/// nearest over the blobs. Everything outside these boxes is background, which never reaches iso.
class SubVolumeReference {
public:
    SubVolumeReference(const SparseSpheres& f, double iso) : iso_(iso) {
        for (size_t i = 0; i < f.blobs.size(); ++i) {
            auto box = f.support(i);
            const uint32_t n[3] = {f.dims.x, f.dims.y, f.dims.z};
            bool empty = false;
            for (int a = 0; a < 3; ++a) {
                box[0][a] = std::max<int64_t>(0, box[0][a] - 1);
                box[1][a] = std::min<int64_t>(n[a] - 1, box[1][a] + 1);
                empty |= box[0][a] > box[1][a];
            }
            if (empty) continue;
            Part p;
            p.volume.dims = {uint32_t(box[1][0] - box[0][0] + 1), uint32_t(box[1][1] - box[0][1] + 1),
                             uint32_t(box[1][2] - box[0][2] + 1)};
            p.volume.values.resize(p.volume.dims.voxels());
            for (uint32_t z = 0; z < p.volume.dims.z; ++z)
                for (uint32_t y = 0; y < p.volume.dims.y; ++y)
                    for (uint32_t x = 0; x < p.volume.dims.x; ++x)
                        p.volume.values[x + uint64_t(p.volume.dims.x) * (y + uint64_t(p.volume.dims.y) * z)] =
                            f.value<float>(uint32_t(box[0][0] + x), uint32_t(box[0][1] + y), uint32_t(box[0][2] + z));
            p.placement.origin = {double(box[0][0]), double(box[0][1]), double(box[0][2])};
            parts_.push_back(std::move(p));
        }
    }
    RefHit trace(const Ray& ray) const {
        RefHit best;
        for (const Part& p : parts_) {
            const RefHit h = trace_reference(p.volume.view(), p.placement, ray, iso_);
            if (h.t < best.t) best = h;
        }
        return best;
    }

private:
    struct Part {
        DenseVolume<float> volume;
        Placement placement;
    };
    std::vector<Part> parts_;
    double iso_;
};

Camera look_at(std::array<double, 3> eye, std::array<double, 3> look, double fov, int size) {
    Camera c;
    c.eye = eye, c.look = look, c.up = {0, 0, 1}, c.fov_deg = fov, c.width = c.height = size;
    if (std::fabs(look[0] - eye[0]) < 1e-9 && std::fabs(look[1] - eye[1]) < 1e-9) c.up = {0, 1, 0};
    return c;
}

struct Tally {
    uint64_t misses = 0, false_hits = 0, both = 0;
    double max_depth_err = 0;
};

/// Pixels of `frame` (depth AOV) against the sub-volume reference.
Tally compare_frame(const Frame& frame, const Camera& cam, const SubVolumeReference& ref) {
    Tally tally;
    const PinholeCamera pinhole(cam);
    for (int py = 0; py < cam.height; ++py)
        for (int px = 0; px < cam.width; ++px) {
            const RefHit r = ref.trace(pinhole.ray(px, py));
            const double t = frame.depth[size_t(py) * cam.width + px];
            if (r.is_hit() && !std::isfinite(t)) ++tally.misses;
            else if (!r.is_hit() && std::isfinite(t)) ++tally.false_hits;
            else if (r.is_hit()) ++tally.both, tally.max_depth_err = std::max(tally.max_depth_err, std::fabs(t - r.t));
        }
    return tally;
}

/// Builds `n`^3, writes it, loads it back (full validation), renders a close-up of every blob
/// and a far view of the far-corner blob, all against the sub-volume reference.
void check_huge_domain(uint32_t n, const std::string& file) {
    const SparseSpheres f = sparse_spheres_layout(n);
    const OctreeData<float> built = build_sparse_octree<float>(f);
    EXPECT_EQ(built.dmax, std::countr_zero(n));
    EXPECT_LT(built.cap_count, 200000u) << "sparse: the tree must stay small";

    OctInfo info;
    info.type = ScalarType::f32;
    info.dims = f.dims;
    info.dmax = built.dmax;
    {
        OctWriter w(file, info);
        w.add_step(built.view());
        w.finish();
    }
    const OctFile oct = OctFile::open(file, Verify::Full);
    ASSERT_EQ(oct.info().dims, f.dims);
    const Octree<float> tree = oct.step<float>(0);
    EXPECT_EQ(tree.point_locate({uint32_t(f.blobs[1].centre[0]), uint32_t(f.blobs[1].centre[1]),
                                 uint32_t(f.blobs[1].centre[2])}),
              f.value<float>(uint32_t(f.blobs[1].centre[0]), uint32_t(f.blobs[1].centre[1]),
                             uint32_t(f.blobs[1].centre[2])));

    const double iso = 50.0;
    const SubVolumeReference ref(f, iso);
    const Placement placement;
    RenderOptions options;
    options.isovalues = {iso};
    options.want_colour = false;
    options.want_depth = true;
    for (size_t b = 0; b < f.blobs.size(); ++b) {
        const auto& c = f.blobs[b].centre;
        const double r = f.blobs[b].radius;
        // From inside the data towards the blob, from the low side (the cut blob is open at the far faces).
        const Camera cam = look_at({c[0] - 2.6 * r, c[1] - 2.1 * r, c[2] - 1.7 * r}, c, 45, 40);
        for (bool embree : {true, false}) {
            options.use_embree = embree;
            const Frame frame = render(tree, placement, cam, options);
            const Tally t = compare_frame(frame, cam, ref);
            SCOPED_TRACE(::testing::Message() << "n " << n << " blob " << b << " embree " << embree);
            EXPECT_EQ(t.misses, 0u);
            EXPECT_EQ(t.false_hits, 0u);
            EXPECT_GT(t.both, 100u);
            EXPECT_LE(t.max_depth_err, 1e-3);
        }
    }

    // Far view: eye outside the data near the origin, the far-corner blob ~1.7 n away. The float
    // depth AOV cannot hold 1e-3 at that distance, so the tracer's double t is compared directly.
    const auto& c = f.blobs[1].centre;
    const std::array<double, 3> eye{-0.01 * n, -0.02 * n, -0.015 * n};
    double dist = 0;
    for (int a = 0; a < 3; ++a) dist += (c[a] - eye[a]) * (c[a] - eye[a]);
    dist = std::sqrt(dist);
    const double fov = 2 * std::atan(1.3 * f.blobs[1].radius / dist) * 180 / M_PI;
    const Camera far_cam = look_at(eye, c, fov, 32);
    const PinholeCamera pinhole(far_cam);
    const OctreeTracer<float, Neubauer> tracer(tree, placement, &iso, 1, Neubauer{});
    Tally far;
    for (int py = 0; py < far_cam.height; ++py)
        for (int px = 0; px < far_cam.width; ++px) {
            const Ray ray = pinhole.ray(px, py);
            const TraceHit h = tracer.trace(ray, true);
            const RefHit r = ref.trace(ray);
            ASSERT_FALSE(std::isnan(h.t));
            if (r.is_hit() && !h.is_hit()) ++far.misses;
            else if (!r.is_hit() && h.is_hit()) ++far.false_hits;
            else if (r.is_hit()) {
                ++far.both;
                far.max_depth_err = std::max(far.max_depth_err, std::fabs(h.t - r.t));
                for (double v : h.normal) EXPECT_TRUE(std::isfinite(v));
            }
        }
    SCOPED_TRACE(::testing::Message() << "far view, n " << n << ", distance " << dist);
    EXPECT_EQ(far.misses, 0u);
    EXPECT_EQ(far.false_hits, 0u);
    EXPECT_GT(far.both, 200u);
    EXPECT_LE(far.max_depth_err, 1e-3);
}

TEST(SparseOctree, Domain16384CubedValidatesAndRendersExactly) {
    ScratchDir dir;
    check_huge_domain(16384, dir.file("sparse16384.oct"));
}

TEST(SparseOctree, Domain2To30CubedValidatesAndRendersExactly) {
    // 2^90 virtual voxels: the largest extent the format allows, dmax 30.
    ScratchDir dir;
    check_huge_domain(Dims::kMaxExtent, dir.file("sparse2p30.oct"));
}

TEST(SparseOctree, ConvertToolWritesTheSameTree) {
    const std::string tool = std::string(OCTISO_TOOLS_DIR) + "/octiso-convert";
    if (!std::filesystem::exists(tool)) {
        OCTISO_SKIP(tool << " not built");
    }
    ScratchDir dir;
    const std::string out = dir.file("big.oct");
    ASSERT_EQ(std::system(("'" + tool + "' --synthetic sparse-spheres:16384 -o '" + out + "' >/dev/null 2>&1").c_str()), 0);
    const OctFile oct = OctFile::open(out, Verify::Full);
    EXPECT_EQ(oct.info().dims, (Dims{16384, 16384, 16384}));
    EXPECT_EQ(oct.info().type, ScalarType::f32);
    const OctreeData<float> built = build_sparse_octree<float>(sparse_spheres_layout(16384));
    const Octree<float> tree = oct.step<float>(0);
    ASSERT_EQ(tree.cap_count(), built.cap_count);
    ASSERT_EQ(tree.cap_bytes(), built.cap_bytes);
    EXPECT_EQ(std::memcmp(tree.arrays().caps, built.caps.data.get(), built.cap_bytes), 0);
    // Bad input: exactly status 2 (a crash or a sanitizer abort is not a refusal).
    EXPECT_EQ(run_shell("'" + tool + "' --synthetic sparse-spheres:63 -o '" + dir.file("x.oct") + "' 2>/dev/null"), 2);
    EXPECT_FALSE(std::filesystem::exists(dir.file("x.oct")));
}

}  // namespace
}  // namespace octiso::test
