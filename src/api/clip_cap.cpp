// cap_clip_planes (include/octiso/clip_cap.h): per pixel, the primary ray's entry through a clip
// plane (render/clip.h, clip_entry: clip_ray's own arithmetic), the field there, and the cap.
#include "octiso/clip_cap.h"

#include <cmath>

#include "api/hit_colour.h"
#include "math/vec.h"
#include "octiso/error.h"
#include "render/clip.h"
#include "render/pinhole_camera.h"
#include "render/secondary.h"

namespace octiso {

int cap_isovalue(double v, const std::vector<double>& isovalues, bool inside_above) {
    int best = -1;
    for (int i = 0; i < int(isovalues.size()); ++i) {
        const double V = isovalues[size_t(i)];
        if (inside_above ? !(v >= V) : !(v <= V)) continue;
        if (best < 0 || (inside_above ? V > isovalues[size_t(best)] : V < isovalues[size_t(best)])) best = i;
    }
    return best;
}

size_t cap_clip_planes(const AnyOctree& tree, const std::vector<double>& isovalues, const ClipCap& cap, const Camera& camera,
                       Frame& frame) {
    const size_t pixels = size_t(frame.width) * size_t(frame.height);
    if (frame.depth.size() != pixels || frame.width != camera.width || frame.height != camera.height)
        throw Error("cap_clip_planes", "needs the depth AOV of the frame", ErrorKind::Other);
    const bool has_normal = frame.normal.size() == 3 * pixels;
    if (cap.planes.empty()) return 0;
    // The data box in index space is [0, n-1] per axis; a plane on a box face must keep its cap,
    // so the test forgives the rounding of one division.
    const Dims dims = tree.dims();
    const Placement& placement = tree.placement();
    const double n[3] = {double(dims.x), double(dims.y), double(dims.z)};
    const PinholeCamera pinhole(camera);
    size_t capped = 0;
    dispatch_scalar_type(tree.type(), [&](auto zero) {
        using T = decltype(zero);
        const Octree<T>& octree = *tree.as<T>();
        for (int py = 0; py < frame.height; ++py)
            for (int px = 0; px < frame.width; ++px) {
                const Ray ray = pinhole.ray(px, py);
                const ClipEntry entry = clip_entry(cap.planes, ray);
                if (entry.plane < 0) continue;
                const Vec3 p = point_at(ray, entry.t);
                bool in_box = true;
                for (int a = 0; a < 3; ++a) {
                    const double q = (p[a] - placement.origin[a]) / placement.spacing[a], eps = 1e-9 * n[a];
                    in_box = in_box && q >= -eps && q <= n[a] - 1 + eps;
                }
                if (!in_box || cap_isovalue(field_at(octree, placement, p), isovalues, cap.inside_above) < 0) continue;
                const size_t i = size_t(py) * size_t(frame.width) + size_t(px);
                frame.depth[i] = float(entry.t);
                if (has_normal) {
                    const Vec3 unit = vec_normalized(cap.planes[size_t(entry.plane)].normal);
                    for (int a = 0; a < 3; ++a) frame.normal[3 * i + size_t(a)] = float(unit[size_t(a)]);
                }
                ++capped;
            }
    });
    return capped;
}

}  // namespace octiso
