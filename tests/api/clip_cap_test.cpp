// Caps on the cut faces of clip planes (include/octiso/clip_cap.h, --clip-cap) against the dense
// exact reference: two nested spheres (iso 30 and 60) cut by two planes, the octree frame capped by
// cap_clip_planes and, independently, per pixel the plane entry of the primary ray computed here,
// the dense trilinear field there, and where it lies inside neither isovalue the reference trace of
// the clipped ray. Same hit mask, the caps at the plane's t with its unit normal, the innermost
// isovalue shown on each cap (shown_isovalue, what shading reads back); no cap is no change.
#include <cmath>

#include <gtest/gtest.h>

#include "api/hit_colour.h"
#include "octiso/any_octree.h"
#include "octiso/clip_cap.h"
#include "render/look_test_util.h"
#include "render/render_test_util.h"
#include "render/secondary.h"

namespace octiso::test {
namespace {

/// The trilinear interpolant of `v` at world point p inside the data box, straight from the array.
double dense_at(const DenseVolume<float>& v, const Placement& placement, const Vec3& p) {
    double q[3], f[3];
    uint32_t lo[3];
    const uint32_t n[3] = {v.dims.x, v.dims.y, v.dims.z};
    for (int a = 0; a < 3; ++a) {
        q[a] = (p[a] - placement.origin[a]) / placement.spacing[a];
        lo[a] = uint32_t(std::min(std::max(std::floor(q[a]), 0.0), double(n[a] - 2)));
        f[a] = q[a] - lo[a];
    }
    double s = 0;
    for (int c = 0; c < 8; ++c) {
        const int dx = (c >> 2) & 1, dy = (c >> 1) & 1, dz = c & 1;
        s += (dx ? f[0] : 1 - f[0]) * (dy ? f[1] : 1 - f[1]) * (dz ? f[2] : 1 - f[2]) * v.at(lo[0] + dx, lo[1] + dy, lo[2] + dz);
    }
    return s;
}

TEST(CapIsovalue, InnermostIsovalueHoldingTheValue) {
    const std::vector<double> iso{30, 60};
    EXPECT_EQ(cap_isovalue(70, iso, true), 1);
    EXPECT_EQ(cap_isovalue(60, iso, true), 1);
    EXPECT_EQ(cap_isovalue(45, iso, true), 0);
    EXPECT_EQ(cap_isovalue(10, iso, true), -1);
    EXPECT_EQ(cap_isovalue(NAN, iso, true), -1);
    EXPECT_EQ(cap_isovalue(20, iso, false), 0);   // a negative scale: inside is the smaller stored values
    EXPECT_EQ(cap_isovalue(50, iso, false), 1);
    EXPECT_EQ(cap_isovalue(70, iso, false), -1);
    EXPECT_EQ(cap_isovalue(45, {60, 30}, true), 1);   // the order of the isovalues does not matter
}

TEST(ClipCap, CapsWhereTheDenseFieldIsInsideAndTheReferenceElsewhere) {
    const DenseVolume<float> v = nested_spheres();   // f = 100 at voxel (15,15,15), 0 from radius 12
    Placement placement;
    placement.spacing = {1.0, 1.0, 1.25};
    placement.origin = {-3, 2, 1};
    const Vec3 centre{12, 17, 19.75};
    const AnyOctree tree = AnyOctree::build(v.view(), placement, {});
    RenderOptions options;
    options.isovalues = {30.0, 60.0};
    options.root_finder = RootFinder::exact;
    options.want_colour = false;
    options.want_depth = options.want_normal = true;
    // Keep z <= the centre's and 2x + 2y <= 2 * (x + y of the centre) + 6: both cut the spheres.
    options.clip_planes = {{{0, 0, 1}, centre[2]}, {{2, 2, 0}, 2 * (centre[0] + centre[1]) + 6}};
    const ClipCap cap{options.clip_planes, true};
    const Camera camera = look_at({40, 45, 60}, centre, {0, 0, 1}, 40, 64);
    const Renderer renderer = tree.make_renderer(options);
    Frame frame;
    renderer.render(camera, frame);
    const Frame open = frame;
    const size_t capped = cap_clip_planes(tree, options.isovalues, cap, camera, frame);

    // The expected frame, computed here.
    const ReferenceTracer<float> ref{v.view(), placement, options.isovalues};
    Frame expected = reference_frame_clipped(ref, camera, options.clip_planes);
    const PinholeCamera pinhole(camera);
    size_t n_caps = 0, shown[2] = {0, 0};
    const Octree<float>& octree = *tree.as<float>();
    for (int py = 0; py < camera.height; ++py)
        for (int px = 0; px < camera.width; ++px) {
            const size_t i = size_t(py) * size_t(camera.width) + size_t(px);
            const Ray ray = pinhole.ray(px, py);
            double t_in = 0, t_out = INFINITY;
            int plane = -1;
            for (int k = 0; k < 2; ++k) {
                const ClipPlane& c = options.clip_planes[size_t(k)];
                const double along = vec_dot(c.normal, ray.dir), t = (c.d - vec_dot(c.normal, ray.origin)) / along;
                if (along < 0 && t > t_in) t_in = t, plane = k;
                if (along > 0) t_out = std::min(t_out, t);
            }
            if (plane < 0 || t_in > t_out) continue;
            const Vec3 p = point_at(ray, t_in);
            bool in_box = true;
            for (int a = 0; a < 3; ++a) {
                const double q = (p[a] - placement.origin[a]) / placement.spacing[a];
                in_box = in_box && q >= 0 && q <= 30;
            }
            if (!in_box) continue;
            const double f = dense_at(v, placement, p);
            if (!(f >= 30)) continue;
            ++n_caps;
            const int inner = f >= 60 ? 1 : 0;
            ++shown[inner];
            expected.depth[i] = float(t_in);
            SCOPED_TRACE(testing::Message() << "pixel " << px << "," << py);
            EXPECT_NEAR(frame.depth[i], t_in, 1e-5 * t_in);
            const Vec3 unit = vec_normalized(options.clip_planes[size_t(plane)].normal);
            for (int a = 0; a < 3; ++a) EXPECT_EQ(frame.normal[3 * i + size_t(a)], float(unit[size_t(a)]));
            EXPECT_LT(vec_dot(unit, ray.dir), 0) << "the cap faces the ray";
            EXPECT_EQ(shown_isovalue(octree, placement, options.isovalues, ray, frame.depth[i], &cap), inner);
        }
    EXPECT_EQ(capped, n_caps);
    EXPECT_GT(shown[0], 50u) << "caps in the shell between the spheres";
    EXPECT_GT(shown[1], 50u) << "caps inside the inner sphere";
    expect_agreement(compare_frames(frame, expected, 1.0), "capped", kExactFinderBar);

    // Without caps the frame is the open one; planes that cut nothing inside cap nothing.
    Frame again = open;
    EXPECT_EQ(cap_clip_planes(tree, options.isovalues, ClipCap{{{{0, 0, 1}, 1000}}, true}, camera, again), 0u);
    EXPECT_EQ(again.depth, open.depth);
    EXPECT_EQ(again.normal, open.normal);
}

}  // namespace
}  // namespace octiso::test
