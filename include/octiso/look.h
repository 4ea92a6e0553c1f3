// The ray-traced look of octiso-render (issue 17 item 7): shadows of the light kit's key light,
// ambient occlusion, and nested surfaces composited by per-isovalue opacity. All three trace
// secondary rays through the same exact octree tracer as the frame (src/render/secondary.h,
// composite.h), honour the frame's clip planes (RenderOptions::clip_planes), and colour the
// frame after it is traced, like shade_frame (shading.h) whose light model they extend. With
// everything off (the default) nothing here runs and the frames are those of before.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "octiso/any_octree.h"
#include "octiso/camera.h"
#include "octiso/frame.h"
#include "octiso/render.h"
#include "octiso/shading.h"

namespace octiso {

inline constexpr int kMaxAoSamples = 256;

struct Look {
    bool shadows = false;              ///< `--shadows`: occlusion rays toward the key light (kit shading only)
    int ao_samples = 0;                ///< `--ao N`: ambient-occlusion rays per hit, 0 .. kMaxAoSamples; 0 off (kit only)
    double ao_distance_voxels = 10.0;  ///< `--ao-distance`: reach of an AO ray in voxels (secondary.h, kDefaultAoDistanceVoxels)
    /// `--opacity A` per isovalue in [0, 1], in the order of the isovalues; those not given are 1.
    /// Any below 1 turns on front-to-back compositing of the surfaces along each primary ray.
    std::vector<double> opacity;

    bool composites() const;
    /// Whether any effect is on (else the frame is shaded by shade_frame alone).
    bool active() const { return shadows || ao_samples > 0 || composites(); }
};

/// Throws Error(flag, ...) unless `look` can be rendered with `iso_count` isovalues under `model`.
void validate_look(const Look& look, size_t iso_count, ShadingModel model);

/// What the look cost in one frame (summed over the samples of --spp).
struct LookStats {
    double seconds = 0;                 ///< wall time of the look passes (secondary rays and shading)
    uint64_t shadow_rays = 0;           ///< one per lit hit (n . key > 0) when --shadows
    uint64_t ao_rays = 0;               ///< N per hit with --ao N
    uint64_t layer_rays = 0;            ///< continuations past a translucent surface (composited or secondary rays)
    void add(const LookStats& o) {
        seconds += o.seconds, shadow_rays += o.shadow_rays, ao_rays += o.ao_rays, layer_rays += o.layer_rays;
    }
    uint64_t secondary_rays() const { return shadow_rays + ao_rays + layer_rays; }
};

/// The look of one octree step under the options its frames are traced with (isovalues, root
/// finder, isa, clip planes, threads): built once per step, then shade() per frame or sample.
class LookShader {
public:
    /// Throws Error on a bad look (validate_look) or bad options.
    LookShader(const AnyOctree& tree, const RenderOptions& options, const Look& look, ShadingModel model);
    ~LookShader();
    LookShader(LookShader&&) noexcept;
    LookShader& operator=(LookShader&&) noexcept;

    /// Fills frame.rgb (8-bit sRGB) from frame.depth and frame.normal (both required, rendered
    /// with the options given at construction through `camera`) and the secondary rays of each
    /// hit. Thread-safe for distinct frames.
    LookStats shade(const Camera& camera, const Shading& shading, Frame& frame) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace octiso
