// Front-to-back compositing of nested surfaces (issue 17 item 7, `--opacity`): a primary ray
// continues past each hit of an isovalue with opacity < 1 until the accumulated opacity reaches
// kOpaqueAlpha, no surface is left, or kMaxLayers surfaces were taken (render/secondary.h). The
// hits come from any `TraceHit trace(const Ray&, bool)` (the frame's TracerKernel, or the dense
// reference in the tests), so the list of layers can be checked against the reference's hits
// along the same ray. The colour of each layer is the caller's (api/look.cpp). No allocation.
#pragma once

#include <array>

#include "math/hit.h"
#include "math/ray.h"
#include "render/secondary.h"

namespace octiso {

/// The surfaces a composited ray takes, nearest first: hits[0 .. count), with their opacities.
struct Layers {
    TraceHit hit[kMaxLayers];
    int count = 0;
};

/// The layers along `ray` (its own interval, clip included), each next one searched from `offset`
/// (world units) past the last hit. Stops after the hit that brings the accumulated opacity to
/// kOpaqueAlpha or more (an opaque surface ends the list at once). Adds each continuation to
/// counters.layer_rays. Normals are computed (the layers are shaded).
template <class Trace>
void collect_layers(Trace&& trace, Ray ray, const Opacities& opacity, double offset, Layers& out, SecondaryCounters& counters) {
    out.count = 0;
    double covered = 0;   // accumulated opacity, front to back
    while (out.count < kMaxLayers) {
        if (out.count > 0) ++counters.layer_rays;
        const TraceHit hit = trace(ray, true);
        if (!hit.is_hit()) return;
        out.hit[out.count++] = hit;
        covered += (1.0 - covered) * opacity.of(hit.iso_index);
        if (covered >= kOpaqueAlpha) return;
        ray.t_min = hit.t + offset;
    }
}

/// Front-to-back "over" of linear colours: colour[k] with opacity alpha[k], nearest first, over the
/// background. Stops adding once the accumulated opacity reaches kOpaqueAlpha; what is left of
/// the coverage goes to the background.
inline std::array<double, 3> composite_over(const std::array<double, 3>* colour, const double* alpha, int count,
                                            const std::array<double, 3>& background) {
    std::array<double, 3> sum{0, 0, 0};
    double covered = 0;
    for (int k = 0; k < count && covered < kOpaqueAlpha; ++k) {
        const double w = (1.0 - covered) * alpha[k];
        for (int a = 0; a < 3; ++a) sum[a] += w * colour[k][a];
        covered += w;
    }
    for (int a = 0; a < 3; ++a) sum[a] += (1.0 - covered) * background[a];
    return sum;
}

}  // namespace octiso
