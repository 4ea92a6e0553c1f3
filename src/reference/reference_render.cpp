#include "reference/reference_render.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <tbb/parallel_for.h>

#include "octiso/error.h"
#include "render/pinhole_camera.h"
#include "util/huge_pages.h"

namespace octiso {

template <typename T>
Frame render_reference(const VolumeView<T>& volume, const Placement& placement, const Camera& camera,
                       const std::vector<double>& isovalues) {
    Frame f;
    f.width = camera.width, f.height = camera.height;
    assign_on_huge_pages(f.depth, size_t(f.width) * f.height, float(INFINITY));
    assign_on_huge_pages(f.normal, size_t(f.width) * f.height * 3, 0.0f);
    const PinholeCamera pinhole(camera);
    tbb::parallel_for(0, f.height, [&](int py) {
        for (int px = 0; px < f.width; ++px) {
            const Ray ray = pinhole.ray(px, py);
            RefHit best;
            for (double iso : isovalues) {
                const RefHit h = trace_reference(volume, placement, ray, iso);
                if (h.t < best.t) best = h;
            }
            const size_t i = size_t(py) * f.width + px;
            f.depth[i] = float(best.t);
            if (best.is_hit())
                for (int a = 0; a < 3; ++a) f.normal[3 * i + a] = float(best.normal[a]);
        }
    });
    f.stats.rays = uint64_t(f.width) * f.height;
    return f;
}

ImageError compare_frames(const Frame& frame, const Frame& reference, double voxel) {
    const bool normals = !frame.normal.empty() && !reference.normal.empty();
    if (frame.width != reference.width || frame.height != reference.height || frame.depth.size() != reference.depth.size() ||
        (normals && frame.normal.size() != reference.normal.size()))
        throw Error("compare_frames", "frames differ in size (" + std::to_string(frame.width) + "x" + std::to_string(frame.height) +
                                          ", " + std::to_string(frame.depth.size()) + " depths against " +
                                          std::to_string(reference.width) + "x" + std::to_string(reference.height) + ", " +
                                          std::to_string(reference.depth.size()) + ")", ErrorKind::Other);
    ImageError e;
    e.pixels = reference.depth.size();
    std::vector<double> depth_err, angle_err;
    for (size_t i = 0; i < e.pixels; ++i) {
        const bool a = std::isfinite(frame.depth[i]), b = std::isfinite(reference.depth[i]);
        if (a != b) { ++e.mask_mismatch; continue; }
        if (!a) continue;
        depth_err.push_back(std::abs(double(frame.depth[i]) - double(reference.depth[i])) / voxel);
        e.depth_above_1e3 += depth_err.back() > 1e-3;
        if (normals) {
            double dot = 0;
            for (int k = 0; k < 3; ++k) dot += double(frame.normal[3 * i + k]) * double(reference.normal[3 * i + k]);
            angle_err.push_back(std::acos(std::clamp(dot, -1.0, 1.0)) * 180.0 / M_PI);
        }
    }
    e.both_hit = depth_err.size();
    e.mask_mismatch_fraction = e.pixels ? double(e.mask_mismatch) / double(e.pixels) : 0;
    auto quantile = [](std::vector<double>& v, double q) {
        if (v.empty()) return 0.0;
        const size_t k = std::min(v.size() - 1, size_t(q * double(v.size() - 1) + 0.5));
        std::nth_element(v.begin(), v.begin() + long(k), v.end());
        return v[k];
    };
    e.depth_median = quantile(depth_err, 0.5);
    e.depth_p99 = quantile(depth_err, 0.99);
    e.depth_max = depth_err.empty() ? 0 : *std::max_element(depth_err.begin(), depth_err.end());
    e.normal_median_deg = quantile(angle_err, 0.5);
    e.normal_max_deg = angle_err.empty() ? 0 : *std::max_element(angle_err.begin(), angle_err.end());
    return e;
}

#define OCTISO_INSTANTIATE(T)                                                                        \
    template Frame render_reference<T>(const VolumeView<T>&, const Placement&, const Camera&, \
                                       const std::vector<double>&);
OCTISO_FOR_EACH_SCALAR_TYPE(OCTISO_INSTANTIATE)
#undef OCTISO_INSTANTIATE

}  // namespace octiso
