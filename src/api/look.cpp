// LookShader (include/octiso/look.h): per hit pixel, the surfaces along its primary ray (one, or
// several composited by opacity), per surface the key light's shadow ray and the AO rays, the
// light kit shaded with what they let through, and the layers composited over the background.
// The secondary rays go through a TracerKernel of the frame's own options (same scalar type,
// root finder, instruction set), called directly, one ray at a time: shadow rays of a block of
// pixels are coherent enough for packets, AO rays are not (left for later, BENCHMARKS.md).
#include "octiso/look.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

#include <tbb/task_arena.h>

#include "api/hit_colour.h"
#include "math/vec.h"
#include "octiso/error.h"
#include "render/clip.h"
#include "render/composite.h"
#include "render/light_kit.h"
#include "render/pinhole_camera.h"
#include "render/secondary.h"
#include "render/shade.h"
#include "render/tile_loop.h"
#include "render/tracer_kernel.h"

namespace octiso {

// The public default (look.h) is the documented constant (secondary.h), kept in one place by this check.
static_assert(Look{}.ao_distance_voxels == kDefaultAoDistanceVoxels);

bool Look::composites() const {
    return std::any_of(opacity.begin(), opacity.end(), [](double a) { return a < 1.0; });
}

void validate_look(const Look& look, size_t iso_count, ShadingModel model) {
    if (look.opacity.size() > iso_count)
        throw Error("--opacity", "given " + std::to_string(look.opacity.size()) + " times for " + std::to_string(iso_count) +
                                     " isovalue(s) (the k-th --opacity belongs to the k-th isovalue)");
    for (double a : look.opacity)
        if (!(a >= 0.0 && a <= 1.0)) throw Error("--opacity", "expected an opacity in [0, 1], found " + std::to_string(a));
    if (look.ao_samples < 0 || look.ao_samples > kMaxAoSamples)
        throw Error("--ao", "expected 0 .. " + std::to_string(kMaxAoSamples) + " rays per hit, found " + std::to_string(look.ao_samples));
    if (!(look.ao_distance_voxels > 0 && std::isfinite(look.ao_distance_voxels)))
        throw Error("--ao-distance", "expected a positive distance in voxels");
    if (model != ShadingModel::kit && look.shadows) throw Error("--shadows", "needs the light kit (--shading kit, the default)");
    if (model != ShadingModel::kit && look.ao_samples > 0) throw Error("--ao", "needs the light kit (--shading kit, the default)");
}

struct LookShader::Impl {
    AnyOctree tree;
    RenderOptions options;
    Look look;
    TracerKernel kernel;
    double voxel = 1;
    std::unique_ptr<tbb::task_arena> arena;   ///< only when options.threads > 0, as the Renderer's
};

LookShader::LookShader(const AnyOctree& tree, const RenderOptions& options, const Look& look, ShadingModel model)
    : impl_(std::make_unique<Impl>(Impl{tree, options, look, {}, 1, nullptr})) {
    validate_options(options, tree.render_limits());
    validate_look(look, options.isovalues.size(), model);
    dispatch_scalar_type(tree.type(), [&](auto zero) {
        using T = decltype(zero);
        impl_->kernel = make_tracer_kernel(*tree.as<T>(), tree.placement(), options, options.isa);
    });
    const auto& s = tree.placement().spacing;
    impl_->voxel = std::min({std::fabs(s[0]), std::fabs(s[1]), std::fabs(s[2])});
    if (options.threads > 0) impl_->arena = std::make_unique<tbb::task_arena>(options.threads);
}

LookShader::~LookShader() = default;
LookShader::LookShader(LookShader&&) noexcept = default;
LookShader& LookShader::operator=(LookShader&&) noexcept = default;

LookStats LookShader::shade(const Camera& camera, const Shading& shading, Frame& frame) const {
    const Impl& m = *impl_;
    const size_t pixels = size_t(frame.width) * size_t(frame.height);
    if (frame.depth.size() != pixels || frame.normal.size() != 3 * pixels || frame.width != camera.width || frame.height != camera.height)
        throw Error("LookShader::shade", "needs the depth and normal AOVs of the frame", ErrorKind::Other);
    frame.rgb.resize(3 * pixels);
    const PinholeCamera pinhole(camera);
    CameraFrame cam;
    cam.forward = vec_normalized(vec_sub(camera.look, camera.eye));
    cam.right = vec_normalized(vec_cross(cam.forward, camera.up));
    cam.up = vec_cross(cam.right, cam.forward);
    const LightKit kit;
    const std::array<Vec3, kKitLights> to_light = light_directions(kit, cam);
    const bool is_kit = shading.model == ShadingModel::kit;
    const SrgbTable& to_srgb8 = SrgbTable::instance();
    const std::span<const ClipPlane> planes = m.options.clip_planes;
    const Opacities opacity{m.look.opacity};
    const bool composite = m.look.composites();
    const double offset = kSecondaryOffsetVoxels * m.voxel, reach = m.look.ao_distance_voxels * m.voxel;
    const int n_ao = m.look.ao_samples;
    const std::array<double, 3> background{shading.background[0], shading.background[1], shading.background[2]};
    const TracerKernel& kernel = m.kernel;
    const auto trace = [&](const Ray& r, bool normal) { return kernel.trace(kernel.user, r, normal); };
    std::atomic<uint64_t> shadow_rays{0}, ao_rays{0}, layer_rays{0};

    const auto t0 = std::chrono::steady_clock::now();
    const auto run = [&] {
        return dispatch_scalar_type(m.tree.type(), [&](auto zero) {
            using T = decltype(zero);
            const Octree<T>& octree = *m.tree.as<T>();
            const TileGrid grid = tile_grid_for(camera.width, camera.height, m.options.tile_size);
            for_each_tile(grid, {}, true, [&](const PixelRect& rect, TileCounters& tile) {
                SecondaryCounters local;
                Layers layers;
                std::array<double, 3> colour[kMaxLayers];
                double alpha[kMaxLayers];
                for (int py = rect.y0; py < rect.y1; ++py)
                    for (int px = rect.x0; px < rect.x1; ++px) {
                        const size_t i = size_t(py) * size_t(frame.width) + size_t(px);
                        uint8_t* out = &frame.rgb[3 * i];
                        Ray ray = pinhole.ray(px, py);
                        clip_ray(planes, ray);
                        // 1. The surfaces: the frame's own hit, or the composited list (whose
                        //    first entry is that same hit: the same kernel on the same ray).
                        if (composite) {
                            if (std::isfinite(frame.depth[i])) collect_layers(trace, ray, opacity, offset, layers, local);
                            else layers.count = 0;
                        } else if (std::isfinite(frame.depth[i])) {
                            // The AOV's float t lies within t * 2^-24 of the traced double: for
                            // any camera within 10^4 voxels of the data, far inside the 0.02-voxel
                            // start offset of the secondary rays, so re-tracing it would buy nothing.
                            TraceHit& h = layers.hit[0];
                            h.t = double(frame.depth[i]);
                            h.normal = {frame.normal[3 * i], frame.normal[3 * i + 1], frame.normal[3 * i + 2]};
                            h.iso_index = m.options.isovalues.size() > 1
                                              ? nearest_isovalue(field_at(octree, m.tree.placement(), point_at(ray, h.t)), m.options.isovalues)
                                              : 0;
                            layers.count = 1;
                        } else {
                            layers.count = 0;
                        }
                        if (layers.count == 0) {
                            for (int a = 0; a < 3; ++a) out[a] = to_srgb8(shading.background[size_t(a)]);
                            continue;
                        }
                        // 2. Per surface, what reaches it of the key light and of the sky, and its colour.
                        const uint32_t seed = n_ao > 0 ? pixel_seed(px, py, camera.pixel_offset) : 0;
                        for (int k = 0; k < layers.count; ++k) {
                            const TraceHit& h = layers.hit[k];
                            alpha[k] = composite ? opacity.of(h.iso_index) : 1.0;
                            if (alpha[k] == 0) {   // invisible (--opacity 0): no secondary rays for it
                                colour[k] = {0, 0, 0};
                                continue;
                            }
                            const Vec3 p = point_at(ray, h.t);
                            KitVisibility visible;
                            if (m.look.shadows && vec_dot(h.normal, to_light[kKeyLight]) > 0) {
                                ++local.shadow_rays;
                                visible.key = transmittance(trace, shadow_ray(p, to_light[kKeyLight], offset, planes), opacity, offset, local);
                            }
                            if (n_ao > 0) {
                                const uint32_t layer_seed = hash32(seed + uint32_t(k));
                                double open = 0;
                                for (int s = 0; s < n_ao; ++s)
                                    open += transmittance(trace, ao_ray(p, h.normal, ao_sample(s, n_ao, layer_seed), offset, reach, planes),
                                                          opacity, offset, local);
                                local.ao_rays += uint64_t(n_ao);
                                visible.ambient = open / double(n_ao);
                            }
                            const float* albedo = albedo_of(shading, h.iso_index);
                            if (is_kit) {
                                colour[k] = shade_light_kit(kit, to_light, h.normal, ray.dir, albedo, visible);
                            } else {   // the headlight formula of shade_frame
                                const double lambert = std::fabs(vec_dot(h.normal, ray.dir));
                                for (int a = 0; a < 3; ++a) colour[k][size_t(a)] = albedo[a] * (kAmbient + (1.0f - kAmbient) * lambert);
                            }
                        }
                        // 3. Front to back over the background.
                        const std::array<double, 3> rgb = composite ? composite_over(colour, alpha, layers.count, background) : colour[0];
                        for (int a = 0; a < 3; ++a) out[a] = to_srgb8(float(rgb[size_t(a)]));
                        ++tile.hits;
                    }
                shadow_rays += local.shadow_rays, ao_rays += local.ao_rays, layer_rays += local.layer_rays;
            });
            return 0;
        });
    };
    if (m.arena) m.arena->execute(run);
    else run();
    LookStats stats;
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    stats.shadow_rays = shadow_rays, stats.ao_rays = ao_rays, stats.layer_rays = layer_rays;
    return stats;
}

}  // namespace octiso
