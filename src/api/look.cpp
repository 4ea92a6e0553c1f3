// LookShader (include/octiso/look.h): per hit pixel, the surfaces along its primary ray (one, or
// several composited by opacity), per surface the key light's shadow ray and the AO rays, the
// light kit shaded with what they let through, and the layers composited over the background.
// The secondary rays go through a TracerKernel of the frame's own options (same scalar type,
// root finder, instruction set, traversal), called directly: the shadow rays of a 4x2 block of
// pixels as one packet (bit-identical to single rays; 2-3 % off the shadow pass on ch2better,
// BENCHMARKS.md, "Ray-traced look"), AO rays and continuations one by one (they scatter).
#include "octiso/look.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>

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
#include "util/huge_pages.h"
#include "util/shared_arena.h"

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
    Impl(const AnyOctree& t, const RenderOptions& o, const Look& l) : tree(t), options(o), look(l) {}
    AnyOctree tree;
    RenderOptions options;
    Look look;
    TracerKernel kernel;
    double voxel = 1;
    std::mutex lod_mutex;                     ///< held while a frame with level of detail is shaded (the cut is the camera's)
};

LookShader::LookShader(const AnyOctree& tree, const RenderOptions& options, const Look& look, ShadingModel model)
    : impl_(std::make_unique<Impl>(tree, options, look)) {
    validate_options(options, tree.render_limits());
    validate_look(look, options.isovalues.size(), model);
    dispatch_scalar_type(tree.type(), [&](auto zero) {
        using T = decltype(zero);
        impl_->kernel = make_tracer_kernel(*tree.as<T>(), tree.placement(), options, options.isa);
    });
    const auto& s = tree.placement().spacing;
    impl_->voxel = std::min({std::fabs(s[0]), std::fabs(s[1]), std::fabs(s[2])});
}

LookShader::~LookShader() = default;
LookShader::LookShader(LookShader&&) noexcept = default;
LookShader& LookShader::operator=(LookShader&&) noexcept = default;

namespace {

/// Pixels are shaded in blocks of 4x4, the primary rays' direct packet shape (renderer.cpp), so
/// that the block's shadow rays go to the kernel as one packet: the shading pass with --shadows
/// took 0.82-0.88 x its time with 4x2 blocks, plain shading unchanged (min of 5 pairs,
/// build_ab_shadow_packets16.json, build_ab_shade_blocks16.json).
constexpr int kBlockW = 4, kBlockH = 4, kBlock = kBlockW * kBlockH;
static_assert(kBlock <= kMaxTracePacket);

/// One pixel of a block between its passes: its ray, its surfaces and their key light.
struct BlockPixel {
    int px = 0, py = 0;
    size_t i = 0;
    Ray ray;
    Layers layers;
    double key[kMaxLayers];   ///< transmittance of the key light's shadow ray per layer (1: lit)
};

}  // namespace

LookStats LookShader::shade(const Camera& camera, const Shading& shading, Frame& frame) const {
    Impl& m = *impl_;
    // Level of detail: secondary rays see the primary rays' coarse surface, the same cut.
    std::unique_lock<std::mutex> lod_turn;
    if (m.options.lod > 0) {
        lod_turn = std::unique_lock<std::mutex>(m.lod_mutex);
        m.kernel.set_lod(m.kernel.user, make_lod_cut(camera, m.tree.placement(), m.options.lod));
    }
    const size_t pixels = size_t(frame.width) * size_t(frame.height);
    if (frame.depth.size() != pixels || frame.normal.size() != 3 * pixels || frame.width != camera.width || frame.height != camera.height)
        throw Error("LookShader::shade", "needs the depth and normal AOVs of the frame", ErrorKind::Other);
    resize_on_huge_pages(frame.rgb, 3 * pixels);
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
    const bool packets = m.options.traversal == Traversal::packets;
    std::atomic<uint64_t> shadow_rays{0}, ao_rays{0}, layer_rays{0};

    const auto t0 = std::chrono::steady_clock::now();
    const auto run = [&] {
        return dispatch_scalar_type(m.tree.type(), [&](auto zero) {
            using T = decltype(zero);
            const Octree<T>& octree = *m.tree.as<T>();
            const TileGrid grid = tile_grid_for(camera.width, camera.height, m.options.tile_size);
            for_each_tile(grid, {}, true, [&](const PixelRect& rect, TileCounters& tile) {
                SecondaryCounters local;
                BlockPixel block[kBlock];
                std::array<double, 3> colour[kMaxLayers];
                double alpha[kMaxLayers];
                for (int y0 = rect.y0; y0 < rect.y1; y0 += kBlockH)
                    for (int x0 = rect.x0; x0 < rect.x1; x0 += kBlockW) {
                        // 1. The surfaces of each pixel of the block: the frame's own hit, or the
                        //    composited list (whose first entry is that same hit: the same kernel
                        //    on the same ray).
                        int n = 0;
                        for (int py = y0; py < std::min(y0 + kBlockH, rect.y1); ++py)
                            for (int px = x0; px < std::min(x0 + kBlockW, rect.x1); ++px) {
                                BlockPixel& b = block[n++];
                                b.px = px, b.py = py, b.i = size_t(py) * size_t(frame.width) + size_t(px);
                                b.ray = pinhole.ray(px, py);
                                clip_ray(planes, b.ray);
                                Layers& layers = b.layers;
                                const size_t i = b.i;
                                if (!std::isfinite(frame.depth[i])) {
                                    layers.count = 0;
                                } else if (composite) {
                                    collect_layers(trace, b.ray, opacity, offset, layers, local);
                                } else {
                                    // The AOV's float t lies within t * 2^-24 of the traced double:
                                    // for any camera within 10^4 voxels of the data, far inside the
                                    // 0.02-voxel start offset of the secondary rays, so re-tracing
                                    // it would buy nothing.
                                    TraceHit& h = layers.hit[0];
                                    h.t = double(frame.depth[i]);
                                    h.normal = {frame.normal[3 * i], frame.normal[3 * i + 1], frame.normal[3 * i + 2]};
                                    h.iso_index = shown_isovalue(octree, m.tree.placement(), m.options.isovalues, pinhole.ray(px, py),
                                                                 frame.depth[i], shading.cap ? &*shading.cap : nullptr);
                                    layers.count = 1;
                                }
                                for (int k = 0; k < layers.count; ++k) b.key[k] = 1.0;
                            }
                        // 2. The key light's shadow rays of the whole block, in one packet of up to
                        //    16: they share one direction and start close together, like primary rays.
                        if (m.look.shadows) {
                            Ray rays[kBlock];
                            int owner[kBlock][2];
                            int queued = 0;
                            const auto flush = [&] {
                                TraceHit first[kBlock];
                                if (packets) kernel.trace_packet(kernel.user, rays, queued, nullptr, false, first);
                                else for (int q = 0; q < queued; ++q) first[q] = trace(rays[q], false);
                                for (int q = 0; q < queued; ++q)
                                    block[owner[q][0]].key[owner[q][1]] = transmittance(trace, rays[q], opacity, offset, local, &first[q]);
                                queued = 0;
                            };
                            for (int j = 0; j < n; ++j)
                                for (int k = 0; k < block[j].layers.count; ++k) {
                                    const TraceHit& h = block[j].layers.hit[k];
                                    if ((composite && opacity.of(h.iso_index) == 0) || !(vec_dot(h.normal, to_light[kKeyLight]) > 0)) continue;
                                    ++local.shadow_rays;
                                    rays[queued] = shadow_ray(point_at(block[j].ray, h.t), to_light[kKeyLight], offset, planes);
                                    owner[queued][0] = j, owner[queued][1] = k;
                                    if (++queued == kBlock) flush();
                                }
                            if (queued) flush();
                        }
                        // 3. Per surface, what reaches it of the sky, and its colour; front to back
                        //    over the background.
                        for (int j = 0; j < n; ++j) {
                            const BlockPixel& b = block[j];
                            const Layers& layers = b.layers;
                            uint8_t* out = &frame.rgb[3 * b.i];
                            if (layers.count == 0) {
                                for (int a = 0; a < 3; ++a) out[a] = to_srgb8(shading.background[size_t(a)]);
                                continue;
                            }
                            const uint32_t seed = n_ao > 0 ? pixel_seed(b.px, b.py, camera.pixel_offset) : 0;
                            for (int k = 0; k < layers.count; ++k) {
                                const TraceHit& h = layers.hit[k];
                                alpha[k] = composite ? opacity.of(h.iso_index) : 1.0;
                                if (alpha[k] == 0) {   // invisible (--opacity 0): no secondary rays for it
                                    colour[k] = {0, 0, 0};
                                    continue;
                                }
                                KitVisibility visible;
                                visible.key = b.key[k];
                                if (n_ao > 0) {
                                    const Vec3 p = point_at(b.ray, h.t);
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
                                    colour[k] = shade_light_kit(kit, to_light, h.normal, b.ray.dir, albedo, visible);
                                } else {   // the headlight formula of shade_frame
                                    const double lambert = std::fabs(vec_dot(h.normal, b.ray.dir));
                                    for (int a = 0; a < 3; ++a) colour[k][size_t(a)] = albedo[a] * (kAmbient + (1.0f - kAmbient) * lambert);
                                }
                            }
                            const std::array<double, 3> rgb = composite ? composite_over(colour, alpha, layers.count, background) : colour[0];
                            for (int a = 0; a < 3; ++a) out[a] = to_srgb8(float(rgb[size_t(a)]));
                            ++tile.hits;
                        }
                    }
                shadow_rays += local.shadow_rays, ao_rays += local.ao_rays, layer_rays += local.layer_rays;
            });
            return 0;
        });
    };
    in_shared_arena(m.options.threads, run);   // the Renderer's arena: its workers are there (util/shared_arena.h)
    LookStats stats;
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    stats.shadow_rays = shadow_rays, stats.ao_rays = ao_rays, stats.layer_rays = layer_rays;
    return stats;
}

}  // namespace octiso
