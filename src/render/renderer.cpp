// The persistent Renderer: per octree, the traversal set-up for the chosen scalar type and root
// finder, the Embree device and scene (created once, re-pointed when options change) and the
// thread arena; per frame, one primary ray per pixel through the one tile loop (tile_loop.h),
// then shading and the AOVs. The traversal is a TracerKernel (tracer_kernel.h) built in
// set_options for the scalar type, root finder and instruction set; the frame loop calls it once
// per packet of up to kMaxTracePacket rays (packet_size.h), through Embree or directly. What a
// frame does not ask for is not computed: no normals unless colour or the normal AOV is wanted,
// no shading without colour.
#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>

#include <tbb/task_arena.h>

#include "octiso/error.h"
#include "octiso/render.h"
#include "render/clip.h"
#include "render/pinhole_camera.h"
#include "render/shade.h"
#include "render/tile_loop.h"
#include "util/huge_pages.h"
#include "util/shared_arena.h"
#include "render/tracer_kernel.h"
#include "scene/embree_scene.h"

namespace octiso {

void validate_options(const RenderOptions& options, const RenderLimits& limits) {
    if (options.isovalues.empty()) throw Error("--iso", "at least one isovalue is needed");
    if (int(options.isovalues.size()) > kMaxIsovalues)
        throw Error("--iso", "at most " + std::to_string(kMaxIsovalues) + " isovalues at once");
    for (double v : options.isovalues)
        if (!std::isfinite(v)) throw Error("--iso", "isovalues must be finite");
    if (limits.iso_range) {
        const auto [lo, hi] = *limits.iso_range;
        for (double iso : options.isovalues)
            if (!(iso > lo && iso < hi))
                throw Error("--iso", "isovalue " + std::to_string(iso) + " lies outside the file's iso-range (" +
                                         std::to_string(lo) + ", " + std::to_string(hi) +
                                         "): the data there was clamped when " + limits.source + " was converted");
    }
    if (options.tile_size < 0) throw Error("tile_size", "must not be negative");
    if (!(std::isfinite(options.lod) && options.lod >= 0))
        throw Error("--lod", "expected a finite factor >= 0 (0: full resolution)");
    if (options.lod > 0 && options.owned_cells)
        throw Error("--lod", "level of detail is not available with --distribute data (each rank's cut would differ)");
    for (const ClipPlane& c : options.clip_planes) {
        const auto& n = c.normal;
        if (!std::isfinite(n[0]) || !std::isfinite(n[1]) || !std::isfinite(n[2]) || !std::isfinite(c.d) ||
            (n[0] == 0 && n[1] == 0 && n[2] == 0))
            throw Error("--clip", "a clip plane needs a finite, non-zero normal and a finite offset (NX,NY,NZ,D)");
    }
}

struct Renderer::Impl {
    virtual ~Impl() = default;
    virtual void set_options(const RenderOptions& options) = 0;
    virtual RenderStats render_tiles(const Camera& camera, std::span<const int> tiles, bool all, Frame& frame) const = 0;
    virtual ScalarType type() const = 0;
    RenderOptions options;
    RenderLimits limits;
    std::shared_ptr<const void> storage;      ///< keep_alive(): the octree's arrays, if shared

    void adopt(const RenderOptions& o) {
        validate_options(o, limits);
        options = o;
    }
    /// The process's arena of options.threads (util/shared_arena.h), shared with the frame's other passes.
    template <class F> decltype(auto) in_arena(F&& f) const { return in_shared_arena(options.threads, f); }
};

namespace {

/// Pixels of `rect` into `frame`, one packet per kernel or Embree call: blocks of pixels, whose
/// rays stay closer together than a row's (more lanes share each node and cap; BENCHMARKS.md,
/// packets: 4x2 against 8x1). Through Embree 4x2 (one rtcIntersect8 packet); called directly
/// 4x4 (kMaxTracePacket, packet_size.h: the tracer's per-packet work shared by twice the rays).
constexpr int kEmbreePacketW = 4, kEmbreePacketH = 2;
static_assert(kEmbreePacketW * kEmbreePacketH == EmbreeVolumeScene::kPacket);
constexpr int kDirectPacketW = 4, kDirectPacketH = 4;
static_assert(kDirectPacketW * kDirectPacketH == kMaxTracePacket);
static_assert(kDirectPacketW <= PinholeCamera::kMaxBlockSide && kDirectPacketH <= PinholeCamera::kMaxBlockSide &&
              kMaxTracePacket <= PinholeCamera::kMaxBlockRays);

void trace_rect(const TracerKernel& kernel, const EmbreeVolumeScene* scene, const PinholeCamera& pinhole,
                const RenderOptions& options, const PixelRect& rect, Frame& frame, TileCounters& counters) {
    constexpr int kPacket = kMaxTracePacket;
    const int packet_w = scene ? kEmbreePacketW : kDirectPacketW;
    const int packet_h = scene ? kEmbreePacketH : kDirectPacketH;
    const bool want_normal = options.want_colour || options.want_normal;
    const bool packets = options.traversal == Traversal::packets;
    const std::span<const ClipPlane> clip_planes = options.clip_planes;
    const SrgbTable& to_srgb8 = SrgbTable::instance();
    const int W = frame.width;
    Ray rays[kPacket];
    TraceHit traced[kPacket];
    size_t pixel[kPacket];
    for (int y0 = rect.y0; y0 < rect.y1; y0 += packet_h)
        for (int x0 = rect.x0; x0 < rect.x1; x0 += packet_w) {
            const int bw = std::min(packet_w, rect.x1 - x0), bh = std::min(packet_h, rect.y1 - y0);
            const int count = bw * bh;
            pinhole.block_rays(x0, y0, bw, bh, rays);
            for (int j = 0, k = 0; j < bh; ++j)
                for (int i = 0; i < bw; ++i, ++k) {
                    if (!clip_planes.empty()) clip_ray(clip_planes, rays[k]);
                    pixel[k] = size_t(y0 + j) * W + size_t(x0 + i);
                }
            if (scene) scene->intersect_packet(rays, count, want_normal, traced);
            else if (packets) kernel.trace_packet(kernel.user, rays, count, nullptr, want_normal, traced);
            else for (int k = 0; k < count; ++k) traced[k] = kernel.trace(kernel.user, rays[k], want_normal);
            for (int k = 0; k < count; ++k) {
                const TraceHit& hit = traced[k];
                const size_t i = pixel[k];
                counters.hits += hit.is_hit();
                if (hit.is_hit()) ++counters.hits_by_cell_log2[size_t(hit.cell_log2) & 31u];
                if (options.want_depth) frame.depth[i] = float(hit.t);
                if (options.want_normal)
                    for (int a = 0; a < 3; ++a) frame.normal[3 * i + a] = hit.is_hit() ? float(hit.normal[a]) : 0.0f;
                if (options.want_colour) shade_pixel(to_srgb8, hit, rays[k].dir, &frame.rgb[3 * i]);
            }
        }
    counters.rays += uint64_t(rect.x1 - rect.x0) * uint64_t(rect.y1 - rect.y0);
}

template <typename T> class TypedRenderer final : public Renderer::Impl {
public:
    TypedRenderer(const Octree<T>& tree, const Placement& placement) : tree_(tree), placement_(placement) {}

    ScalarType type() const override { return scalar_type_of<T>(); }

    void set_options(const RenderOptions& o) override {
        adopt(o);
        // The scene points at the new kernel before the old one is dropped.
        TracerKernel kernel = make_tracer_kernel(tree_, placement_, o, o.isa);
        const EmbreeVolumeScene::TracePacketFn packet = o.traversal == Traversal::packets ? kernel.trace_packet : nullptr;
        if (o.use_embree) {
            if (!scene_) {
                scene_ = std::make_unique<EmbreeVolumeScene>();
                scene_->add_volume(data_box_lo(), data_box_hi(), kernel.user, kernel.trace, packet);
                scene_->commit();
            } else {
                scene_->set_volume_trace(0, kernel.user, kernel.trace, packet);
            }
        }
        kernel_ = std::move(kernel);
    }

    RenderStats render_tiles(const Camera& camera, std::span<const int> tiles, bool all, Frame& frame) const override {
        const PinholeCamera pinhole(camera);
        const TileGrid grid = tile_grid_for(camera.width, camera.height, options.tile_size);
        const EmbreeVolumeScene* scene = options.use_embree ? scene_.get() : nullptr;
        // Level of detail: the cut is the camera's, so frames of this Renderer take turns.
        std::unique_lock<std::mutex> lod_turn;
        if (options.lod > 0) {
            lod_turn = std::unique_lock<std::mutex>(lod_mutex_);
            kernel_.set_lod(kernel_.user, make_lod_cut(camera, placement_, options.lod));
        }
        return in_arena([&] {
            return for_each_tile(grid, tiles, all, [&](const PixelRect& rect, TileCounters& counters) {
                trace_rect(kernel_, scene, pinhole, options, rect, frame, counters);
            }, options.tile_order);
        });
    }

private:
    // The data box in world space, [origin, origin + (n-1) * spacing] per axis (either order).
    std::array<double, 3> data_box_lo() const { return data_box_corner(true); }
    std::array<double, 3> data_box_hi() const { return data_box_corner(false); }
    std::array<double, 3> data_box_corner(bool lower) const {
        const Dims d = tree_.dims();
        const uint32_t n[3] = {d.x, d.y, d.z};
        std::array<double, 3> c;
        for (int a = 0; a < 3; ++a) {
            const double e0 = placement_.origin[a], e1 = placement_.origin[a] + double(n[a] - 1) * placement_.spacing[a];
            c[a] = lower ? std::min(e0, e1) : std::max(e0, e1);
        }
        return c;
    }

    const Octree<T> tree_;
    const Placement placement_;
    // The kernel the scene's user geometry points at: it lives here, so its tracer's address is
    // stable until the next set_options(), which re-points the scene.
    TracerKernel kernel_;
    std::unique_ptr<EmbreeVolumeScene> scene_;
    mutable std::mutex lod_mutex_;   ///< held by a frame with level of detail (its cut is set on the kernel)
};

}  // namespace

template <typename T>
Renderer::Renderer(const Octree<T>& tree, const Placement& placement, const RenderOptions& options,
                   const RenderLimits& limits) {
    auto impl = std::make_unique<TypedRenderer<T>>(tree, placement);
    impl->limits = limits;
    impl->set_options(options);
    impl_ = std::move(impl);
}

Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

void Renderer::set_options(const RenderOptions& options) { impl_->set_options(options); }
const RenderOptions& Renderer::options() const { return impl_->options; }
void Renderer::keep_alive(std::shared_ptr<const void> storage) { impl_->storage = std::move(storage); }
ScalarType Renderer::type() const { return impl_->type(); }

TileGrid Renderer::tile_grid(int width, int height) const {
    return tile_grid_for(width, height, impl_->options.tile_size);
}

void Renderer::prepare_frame(const Camera& camera, Frame& frame) const {
    validate_camera(camera);
    const RenderOptions& o = impl_->options;
    const size_t pixels = size_t(camera.width) * size_t(camera.height);
    frame.width = camera.width;
    frame.height = camera.height;
    // Every pixel of a traced tile is written, so reused buffers need no clearing; fresh ones
    // are faulted in on huge pages (util/huge_pages.h).
    resize_on_huge_pages(frame.rgb, o.want_colour ? pixels * 3 : 0);
    resize_on_huge_pages(frame.depth, o.want_depth ? pixels : 0);
    resize_on_huge_pages(frame.normal, o.want_normal ? pixels * 3 : 0);
    frame.stats = {};
}

RenderStats Renderer::render(const Camera& camera, Frame& frame) const {
    prepare_frame(camera, frame);
    frame.stats = impl_->render_tiles(camera, {}, true, frame);
    return frame.stats;
}

Frame Renderer::render(const Camera& camera) const {
    Frame frame;
    render(camera, frame);
    return frame;
}

RenderStats Renderer::render_tiles(const Camera& camera, std::span<const int> tiles, Frame& frame) const {
    validate_camera(camera);
    const RenderOptions& o = impl_->options;
    const size_t pixels = size_t(camera.width) * size_t(camera.height);
    if (frame.width != camera.width || frame.height != camera.height || frame.rgb.size() != (o.want_colour ? pixels * 3 : 0) ||
        frame.depth.size() != (o.want_depth ? pixels : 0) || frame.normal.size() != (o.want_normal ? pixels * 3 : 0))
        throw Error("render_tiles", "the frame was not prepared for this camera and these options (prepare_frame)");
    const int count = tile_grid(camera.width, camera.height).count();
    for (int t : tiles)
        if (t < 0 || t >= count)
            throw Error("render_tiles", "tile " + std::to_string(t) + " outside 0.." + std::to_string(count - 1));
    return impl_->render_tiles(camera, tiles, false, frame);
}

template <typename T>
Frame render(const Octree<T>& tree, const Placement& placement, const Camera& camera, const RenderOptions& options) {
    return Renderer(tree, placement, options).render(camera);   // options, then the camera, are checked there
}

#define OCTISO_INSTANTIATE(T)                                                                                       \
    template Renderer::Renderer(const Octree<T>&, const Placement&, const RenderOptions&, const RenderLimits&);    \
    template Frame render<T>(const Octree<T>&, const Placement&, const Camera&, const RenderOptions&);
OCTISO_FOR_EACH_SCALAR_TYPE(OCTISO_INSTANTIATE)
#undef OCTISO_INSTANTIATE

}  // namespace octiso
