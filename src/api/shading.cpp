// shade_frame (include/octiso/shading.h): per hit pixel, the isovalue it shows (read back from
// the field when there are several), its albedo, and the light model; misses get the background.
#include "octiso/shading.h"

#include <charconv>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "math/vec.h"
#include "octiso/error.h"
#include "api/hit_colour.h"
#include "render/light_kit.h"
#include "render/pinhole_camera.h"
#include "render/shade.h"
#include "util/huge_pages.h"
#include "util/shared_arena.h"

namespace octiso {

namespace {

float linear_from_srgb(double s) { return float(s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4)); }

}  // namespace

void shade_frame(const AnyOctree& tree, const std::vector<double>& isovalues, const Camera& camera, const Shading& shading,
                 Frame& frame) {
    const size_t pixels = size_t(frame.width) * size_t(frame.height);
    if (frame.depth.size() != pixels || frame.normal.size() != 3 * pixels)
        throw Error("shade_frame", "needs the depth and normal AOVs of the frame", ErrorKind::Other);
    resize_on_huge_pages(frame.rgb, 3 * pixels);
    const PinholeCamera pinhole(camera);
    CameraFrame cam;
    cam.forward = vec_normalized(vec_sub(camera.look, camera.eye));
    cam.right = vec_normalized(vec_cross(cam.forward, camera.up));
    cam.up = vec_cross(cam.right, cam.forward);
    const LightKit kit;
    const std::array<Vec3, kKitLights> to_light = light_directions(kit, cam);
    const SrgbTable& to_srgb8 = SrgbTable::instance();
    dispatch_scalar_type(tree.type(), [&](auto zero) {
        using T = decltype(zero);
        const Octree<T>& octree = *tree.as<T>();
        // Rows in parallel (issue 12), in the Renderer's arena: on one thread after a parallel
        // trace this pass was 22 ms of a 1024^2 ch2better frame (BENCHMARKS.md "Many-core"),
        // as long as the whole trace would be on 16 threads.
        const auto shade_rows = [&](const tbb::blocked_range<int>& rows) {
        for (int py = rows.begin(); py < rows.end(); ++py)
            for (int px = 0; px < frame.width; ++px) {
                const size_t i = size_t(py) * size_t(frame.width) + size_t(px);
                const float t = frame.depth[i];
                uint8_t* out = &frame.rgb[3 * i];
                if (!std::isfinite(t)) {
                    for (int a = 0; a < 3; ++a) out[a] = to_srgb8(shading.background[size_t(a)]);
                    continue;
                }
                const Ray ray = pinhole.ray(px, py);
                const Vec3 normal{frame.normal[3 * i], frame.normal[3 * i + 1], frame.normal[3 * i + 2]};
                const int iso = shown_isovalue(octree, tree.placement(), isovalues, ray, t, shading.cap ? &*shading.cap : nullptr);
                const float* albedo = albedo_of(shading, iso);
                std::array<double, 3> rgb;
                if (shading.model == ShadingModel::kit) {
                    rgb = shade_light_kit(kit, to_light, normal, ray.dir, albedo);
                } else {
                    const double lambert = std::fabs(vec_dot(normal, ray.dir));
                    for (int a = 0; a < 3; ++a) rgb[a] = albedo[a] * (kAmbient + (1.0f - kAmbient) * lambert);
                }
                for (int a = 0; a < 3; ++a) out[a] = to_srgb8(float(rgb[size_t(a)]));
            }
        };
        in_shared_arena(shading.threads, [&] { tbb::parallel_for(tbb::blocked_range<int>(0, frame.height, 4), shade_rows); });
    });
}

std::array<float, 3> parse_colour(const std::string& text, const std::string& flag) {
    std::array<double, 3> srgb{};
    const auto bad = [&] { return Error(flag, "expected R,G,B in [0, 1] or #RRGGBB, found '" + text + "'"); };
    if (!text.empty() && text[0] == '#') {
        if (text.size() != 7) throw bad();
        for (int a = 0; a < 3; ++a) {
            unsigned v = 0;
            const char* b = text.data() + 1 + 2 * a;
            const auto [p, ec] = std::from_chars(b, b + 2, v, 16);
            if (ec != std::errc() || p != b + 2) throw bad();
            srgb[size_t(a)] = v / 255.0;
        }
    } else {
        size_t start = 0;
        for (int a = 0; a < 3; ++a) {
            const size_t comma = text.find(',', start);
            if ((a < 2) != (comma != std::string::npos)) throw bad();
            const std::string part = text.substr(start, a < 2 ? comma - start : std::string::npos);
            double v = 0;
            const auto [p, ec] = std::from_chars(part.data(), part.data() + part.size(), v);
            if (part.empty() || ec != std::errc() || p != part.data() + part.size() || !(v >= 0 && v <= 1)) throw bad();
            srgb[size_t(a)] = v;
            start = comma + 1;
        }
    }
    return {linear_from_srgb(srgb[0]), linear_from_srgb(srgb[1]), linear_from_srgb(srgb[2])};
}

}  // namespace octiso
