// Shared by the tests of the ray-traced look (clip, secondary, composite, LookShader): the octree's
// own kernel and the dense exact reference as the same kind of callable, TraceHit(const Ray&, bool),
// so every secondary ray can be traced by both and compared.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "math/hit.h"
#include "math/ray.h"
#include "octiso/build.h"
#include "octree/octree_test_util.h"
#include "reference/brute_force.h"
#include "render/clip.h"
#include "render/pinhole_camera.h"
#include "render/tracer_kernel.h"

namespace octiso::test {

/// The dense brute-force tracer with exact roots over several isovalues: the nearest hit, its isovalue.
template <typename T> struct ReferenceTracer {
    VolumeView<T> volume;
    Placement placement;
    std::vector<double> isovalues;
    TraceHit operator()(const Ray& ray, bool) const {
        TraceHit best;
        for (size_t i = 0; i < isovalues.size(); ++i) {
            const RefHit h = trace_reference(volume, placement, ray, isovalues[i], Exact{});
            if (h.t < best.t) best.t = h.t, best.normal = h.normal, best.iso_index = int(i);
        }
        return best;
    }
};

/// The octree's TracerKernel for `options` (the renderer's own traversal), called directly.
struct KernelTracer {
    TracerKernel kernel;
    template <typename T>
    KernelTracer(const Octree<T>& tree, const Placement& placement, const RenderOptions& options)
        : kernel(make_tracer_kernel(tree, placement, options, options.isa)) {}
    TraceHit operator()(const Ray& ray, bool want_normal) const { return kernel.trace(kernel.user, ray, want_normal); }
};

/// The depth frame of the reference with the frame's clip planes applied to every primary ray.
template <typename T>
Frame reference_frame_clipped(const ReferenceTracer<T>& ref, const Camera& camera, const std::vector<ClipPlane>& planes) {
    Frame f;
    f.width = camera.width, f.height = camera.height;
    f.depth.assign(size_t(f.width) * size_t(f.height), INFINITY);
    const PinholeCamera pinhole(camera);
    for (int py = 0; py < f.height; ++py)
        for (int px = 0; px < f.width; ++px) {
            Ray ray = pinhole.ray(px, py);
            clip_ray(planes, ray);
            f.depth[size_t(py) * size_t(f.width) + size_t(px)] = float(ref(ray, false).t);
        }
    return f;
}

/// Two concentric shells: f = 100 at the centre falling to 0 at radius 12 voxels, so iso 60 and 30
/// are nested spheres (radius ~4.8 and ~8.4).
inline DenseVolume<float> nested_spheres() {
    const Dims dims{31, 31, 31};
    DenseVolume<float> v{dims, std::vector<float>(dims.voxels())};
    for (uint32_t z = 0; z < dims.z; ++z)
        for (uint32_t y = 0; y < dims.y; ++y)
            for (uint32_t x = 0; x < dims.x; ++x) {
                const double r = std::hypot(double(x) - 15, double(y) - 15, double(z) - 15);
                v.values[x + 31u * (y + 31u * z)] = float(std::max(0.0, 100.0 * (1 - r / 12)));
            }
    return v;
}

}  // namespace octiso::test
