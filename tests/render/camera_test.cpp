// The camera, checked on its own. The renderer and the dense reference share PinholeCamera, so
// every agreement test would pass a camera bug; here the pixel rays of CONVENTIONS 2 are written
// out again by hand in long double, without PinholeCamera's helpers, and compared with it (corners,
// centre, odd and non-square sizes, an up vector not orthogonal to the view), and render()'s depth
// of an analytic plane is compared with where those hand-made rays meet the plane.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "octiso/build.h"
#include "octiso/render.h"
#include "octree/octree_test_util.h"
#include "render/pinhole_camera.h"

namespace octiso::test {
namespace {

using L3 = std::array<long double, 3>;

/// CONVENTIONS 2, term by term: f = normalize(look - eye); r = normalize(cross(f, up));
/// u = cross(r, f); a = tan(fov/2); dir = normalize(f + ((2(px+0.5)/W - 1) a W/H) r + ((1 - 2(py+0.5)/H) a) u).
L3 conventions_dir(const Camera& c, int px, int py) {
    const long double pi = 3.141592653589793238462643383279502884L;
    L3 f{c.look[0] - (long double)c.eye[0], c.look[1] - (long double)c.eye[1], c.look[2] - (long double)c.eye[2]};
    const long double lf = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (auto& x : f) x /= lf;
    L3 r{f[1] * c.up[2] - f[2] * c.up[1], f[2] * c.up[0] - f[0] * c.up[2], f[0] * c.up[1] - f[1] * c.up[0]};
    const long double lr = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (auto& x : r) x /= lr;
    const L3 u{r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
    const long double a = std::tan((long double)c.fov_deg / 2 * pi / 180);
    const long double W = c.width, H = c.height;
    const long double sx = (2 * (px + 0.5L) / W - 1) * a * W / H;
    const long double sy = (1 - 2 * (py + 0.5L) / H) * a;
    L3 d{f[0] + sx * r[0] + sy * u[0], f[1] + sx * r[1] + sy * u[1], f[2] + sx * r[2] + sy * u[2]};
    const long double ld = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (auto& x : d) x /= ld;
    return d;
}

Camera camera(std::array<double, 3> eye, std::array<double, 3> look, std::array<double, 3> up, double fov, int w, int h) {
    Camera c;
    c.eye = eye, c.look = look, c.up = up, c.fov_deg = fov, c.width = w, c.height = h;
    return c;
}

const Camera kCameras[] = {
    camera({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 40, 512, 512),          // the defaults
    camera({3, -2, 7}, {-1, 5, 2}, {0, 0, 1}, 35, 7, 5),            // odd, wider than tall
    camera({-4, 9, 1}, {2, 2, 2}, {0.3, 1, 0.2}, 90, 3, 11),        // odd, taller than wide, up not orthogonal to f
    camera({10, 10, 10}, {0, 0, 0}, {0, 0, 1}, 1, 1, 1),            // one pixel: its ray is f itself
    camera({0.5, 0.25, -8}, {0.5, 0.25, 3}, {1, 0, 0}, 120, 64, 36),
};

TEST(PinholeCameraConventions, EveryPixelRayIsTheFormulaWrittenOut) {
    for (const Camera& c : kCameras) {
        SCOPED_TRACE(::testing::Message() << c.width << "x" << c.height << " fov " << c.fov_deg);
        const PinholeCamera pinhole(c);
        for (int py = 0; py < c.height; ++py)
            for (int px = 0; px < c.width; ++px) {
                const Ray ray = pinhole.ray(px, py);
                const L3 d = conventions_dir(c, px, py);
                for (int a = 0; a < 3; ++a) {
                    ASSERT_EQ(ray.origin[a], c.eye[a]) << "the origin is the eye";
                    ASSERT_NEAR(ray.dir[a], double(d[a]), 4e-16) << "pixel " << px << "," << py << " axis " << a;
                }
            }
    }
}

/// The renderer's packets take their rays from block_rays (screen coordinates once per column and
/// row, normalisations two at a time): every block shape up to 8 x 2 and 4 x 4, wherever it lands
/// (cut by the image's edge too), on every camera above and one with a sub-pixel offset, gives
/// ray(px, py) bit for bit.
TEST(PinholeCameraConventions, BlockRaysAreTheSinglePixelRaysBitForBit) {
    std::vector<Camera> cameras(std::begin(kCameras), std::end(kCameras));
    Camera shifted = kCameras[4];
    shifted.pixel_offset = {0.3125, -0.41};
    cameras.push_back(shifted);
    int blocks = 0;
    for (const Camera& c : cameras) {
        SCOPED_TRACE(::testing::Message() << c.width << "x" << c.height << " fov " << c.fov_deg);
        const PinholeCamera pinhole(c);
        for (int bw = 1; bw <= PinholeCamera::kMaxBlockSide; ++bw)
            for (int bh = 1; bh <= PinholeCamera::kMaxBlockSide && bw * bh <= PinholeCamera::kMaxBlockRays; ++bh)
                for (int y0 = 0; y0 < c.height; y0 += bh)
                    for (int x0 = 0; x0 < c.width; x0 += bw) {
                        const int w = std::min(bw, c.width - x0), h = std::min(bh, c.height - y0);
                        Ray block[PinholeCamera::kMaxBlockRays];
                        pinhole.block_rays(x0, y0, w, h, block);
                        ++blocks;
                        for (int k = 0; k < w * h; ++k) {
                            const Ray one = pinhole.ray(x0 + k % w, y0 + k / w);
                            ASSERT_EQ(std::memcmp(&one, &block[k], sizeof(Ray)), 0)
                                << "block " << bw << "x" << bh << " at " << x0 << "," << y0 << ", ray " << k;
                        }
                    }
    }
    EXPECT_GT(blocks, 1000);
}

TEST(PinholeCameraConventions, CornersCentreAndOrientation) {
    // Looking down +z with up +y: f = +z, r = f x up = -x, u = +y. The top-left pixel looks up
    // (+y) and to the left of the image, which is -r = +x; the ray grazes the frustum corner at
    // (W/H * a * (1 - 1/W), a * (1 - 1/H)) in the plane z = 1.
    const int W = 9, H = 5;
    const double fov = 60, a = std::tan(30 * M_PI / 180);
    const PinholeCamera pinhole(camera({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, fov, W, H));
    auto expect_dir = [](const Ray& ray, double x, double y, const char* what) {
        const double len = std::sqrt(x * x + y * y + 1);
        EXPECT_NEAR(ray.dir[0], x / len, 1e-15) << what;
        EXPECT_NEAR(ray.dir[1], y / len, 1e-15) << what;
        EXPECT_NEAR(ray.dir[2], 1 / len, 1e-15) << what;
    };
    const double cx = double(W) / H * a * (1 - 1.0 / W), cy = a * (1 - 1.0 / H);
    expect_dir(pinhole.ray(0, 0), cx, cy, "top left");
    expect_dir(pinhole.ray(W - 1, 0), -cx, cy, "top right");
    expect_dir(pinhole.ray(0, H - 1), cx, -cy, "bottom left");
    expect_dir(pinhole.ray(W - 1, H - 1), -cx, -cy, "bottom right");
    // Odd sizes: the middle pixel's ray is exactly the view direction.
    const Ray centre = pinhole.ray(W / 2, H / 2);
    EXPECT_EQ(std::fabs(centre.dir[0]), 0.0);
    EXPECT_EQ(std::fabs(centre.dir[1]), 0.0);
    EXPECT_EQ(centre.dir[2], 1.0);
    // Every direction is unit length.
    for (int py = 0; py < H; ++py)
        for (int px = 0; px < W; ++px) {
            const Ray r = pinhole.ray(px, py);
            EXPECT_NEAR(r.dir[0] * r.dir[0] + r.dir[1] * r.dir[1] + r.dir[2] * r.dir[2], 1.0, 4e-16);
        }
}

TEST(PinholeCameraConventions, RenderedPlaneDepthIsWhereTheHandRaysMeetIt) {
    // f = x on an anisotropic grid: the isosurface f = iso is the world plane x = origin + iso*SX.
    // Each pixel's depth must be where the hand-made CONVENTIONS 2 ray meets that plane inside the
    // data box, and +inf where it meets it outside (pixels within 1e-6 of the box edge are not judged).
    const Dims dims{12, 9, 7};
    DenseVolume<float> v{dims, std::vector<float>(dims.voxels())};
    for (uint32_t z = 0; z < dims.z; ++z)
        for (uint32_t y = 0; y < dims.y; ++y)
            for (uint32_t x = 0; x < dims.x; ++x) v.values[x + dims.x * (y + uint64_t(dims.y) * z)] = float(x);
    Placement placement;
    placement.spacing = {0.5, 1.25, 2.0};
    placement.origin = {-1, 2, 3};
    const double iso = 6.25, plane_x = placement.origin[0] + iso * placement.spacing[0];
    const double lo[3] = {placement.origin[0], placement.origin[1], placement.origin[2]};
    const double hi[3] = {lo[0] + (dims.x - 1) * placement.spacing[0], lo[1] + (dims.y - 1) * placement.spacing[1],
                          lo[2] + (dims.z - 1) * placement.spacing[2]};
    const auto data = build_octree(v.view(), {});
    RenderOptions options;
    options.isovalues = {iso};
    options.want_colour = false;
    options.want_depth = true;
    options.root_finder = RootFinder::exact;
    for (const Camera& c : {camera({-9, 4, 10}, {plane_x, 7, 9}, {0, 0, 1}, 50, 33, 21),
                            camera({-6, 20, -4}, {plane_x, 6, 8}, {0.2, 0, 1}, 70, 16, 25)}) {
        const Frame frame = render(data.view(), placement, c, options);
        int hits = 0, misses = 0;
        for (int py = 0; py < c.height; ++py)
            for (int px = 0; px < c.width; ++px) {
                const L3 d = conventions_dir(c, px, py);
                const long double t = (plane_x - (long double)c.eye[0]) / d[0];
                const long double y = c.eye[1] + t * d[1], z = c.eye[2] + t * d[2];
                const long double margin = 1e-6;
                const bool inside = t > 0 && y > lo[1] + margin && y < hi[1] - margin && z > lo[2] + margin && z < hi[2] - margin;
                const bool outside = !(t > 0) || y < lo[1] - margin || y > hi[1] + margin || z < lo[2] - margin || z > hi[2] + margin;
                const float depth = frame.depth[size_t(py) * c.width + px];
                if (inside) {
                    ++hits;
                    EXPECT_NEAR(depth, double(t), 1e-6 * double(t)) << "pixel " << px << "," << py;
                } else if (outside) {
                    ++misses;
                    EXPECT_TRUE(std::isinf(depth)) << "pixel " << px << "," << py << " depth " << depth;
                }
            }
        EXPECT_GT(hits, 40) << "the plane must fill part of the view";
        EXPECT_GT(misses, 0) << "the view must show the edge of the data box";
    }
}

}  // namespace
}  // namespace octiso::test
