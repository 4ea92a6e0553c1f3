// The frame loop: TBB tiles (16x16 by default, work-stealing), one primary ray per pixel through
// the Embree scene or straight into the traversal, then shading and the AOVs. Policies (scalar
// type x root finder) are chosen once here, so the per-ray code is one inlined instantiation.
// What a frame does not ask for is not computed: no normals unless colour or the normal AOV is
// wanted, no shading without colour.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>
#include <cmath>

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "octiso/error.h"
#include "octiso/render.h"
#include "render/camera.h"
#include "render/traverse.h"
#include "scene/embree_scene.h"

namespace octiso {

Camera frame_data_box(Dims dims, const Placement& placement, int width, int height) {
    std::array<double, 3> lo, hi, centre;
    double radius2 = 0;
    for (int a = 0; a < 3; ++a) {
        const uint32_t n = a == 0 ? dims.x : a == 1 ? dims.y : dims.z;
        lo[a] = placement.origin[a];
        hi[a] = placement.origin[a] + double(n > 0 ? n - 1 : 0) * placement.spacing[a];
        centre[a] = 0.5 * (lo[a] + hi[a]);
        radius2 += 0.25 * (hi[a] - lo[a]) * (hi[a] - lo[a]);
    }
    const double radius = std::max(std::sqrt(radius2), 1e-9);
    Camera c;
    c.width = width;
    c.height = height;
    c.fov_deg = 35.0;
    // A three-quarter view from +x, -y, +z with z up, far enough that the bounding sphere fits
    // the narrower of the two fields of view.
    const std::array<double, 3> view = vec_normalized({0.9, -1.3, 0.8});
    const double half_fov = c.fov_deg * 0.5 * 3.14159265358979323846 / 180.0;
    const double aspect = double(width) / double(height);
    const double narrow = aspect < 1 ? std::atan(std::tan(half_fov) * aspect) : half_fov;
    const double distance = radius / std::sin(narrow) * 1.02;
    for (int a = 0; a < 3; ++a) c.eye[a] = centre[a] + view[a] * distance;
    c.look = centre;
    c.up = {0, 0, 1};
    return c;
}

int tile_size_for(int width, int height, int requested) {
    if (requested > 0) return requested;
    return int64_t(width) * height / (16 * 16) >= 4096 ? 16 : 8;
}

RootFinder parse_root_finder_name(const std::string& name) {
    const auto kind = parse_root_finder(name);
    if (!kind) throw Error("--root-finder", "expected neubauer, schwarze, linear or exact, found '" + name + "'");
    return RootFinder(int(*kind));
}

namespace {

// Colours per isovalue (linear RGB): the first is a warm bone tone, then blue, green, rose ...
constexpr float kAlbedo[kMaxIsovalues][3] = {{0.90f, 0.62f, 0.36f}, {0.35f, 0.58f, 0.92f}, {0.45f, 0.80f, 0.42f},
                                             {0.88f, 0.40f, 0.52f}, {0.85f, 0.82f, 0.35f}, {0.55f, 0.45f, 0.85f},
                                             {0.40f, 0.80f, 0.80f}, {0.75f, 0.75f, 0.75f}};
constexpr float kBackground[3] = {0.015f, 0.017f, 0.022f};
constexpr float kAmbient = 0.18f;

/// Linear [0,1] -> 8-bit sRGB through a 4096-entry table (the exact curve costs a powf per
/// channel, ~5 % of a cheap frame); the table's step is far below one 8-bit level.
class SrgbTable {
public:
    SrgbTable() {
        for (int i = 0; i < kSize; ++i) {
            const float c = float(i) / float(kSize - 1);
            const float s = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
            table_[i] = uint8_t(std::lround(s * 255.0f));
        }
    }
    uint8_t operator()(float linear) const {
        const float c = std::clamp(linear, 0.0f, 1.0f);
        return table_[int(c * float(kSize - 1) + 0.5f)];
    }

private:
    static constexpr int kSize = 4096;
    uint8_t table_[kSize];
};

void validate(const Camera& camera, const RenderOptions& options) {
    if (options.isovalues.empty()) throw Error("--iso", "at least one isovalue is needed");
    if (int(options.isovalues.size()) > kMaxIsovalues)
        throw Error("--iso", "at most " + std::to_string(kMaxIsovalues) + " isovalues at once");
    for (double v : options.isovalues)
        if (!std::isfinite(v)) throw Error("--iso", "isovalues must be finite");
    if (camera.width < 1 || camera.height < 1) throw Error("--size", "width and height must be positive");
    if (!(camera.fov_deg > 0 && camera.fov_deg < 180)) throw Error("--fov", "must lie in (0, 180) degrees");
    const auto f = vec_sub(camera.look, camera.eye);
    if (!(vec_dot(f, f) > 0)) throw Error("--look", "must differ from --eye");
    const auto side = vec_cross(f, camera.up);
    if (!(vec_dot(side, side) > 1e-24 * vec_dot(f, f) * std::max(vec_dot(camera.up, camera.up), 1e-300)))
        throw Error("--up", "must not be parallel to the viewing direction (or zero)");
    if (options.tile_size < 0) throw Error("tile_size", "must not be negative");
}

template <typename T, class Finder>
Frame render_with(const Octree<T>& tree, const Placement& placement, const Camera& camera, const RenderOptions& options,
                  const Finder& finder) {
    const OctreeTracer<T, Finder> tracer(tree, placement, options.isovalues.data(), int(options.isovalues.size()), finder);
    const PinholeCamera pinhole(camera);
    const int W = camera.width, H = camera.height;
    Frame frame;
    frame.width = W;
    frame.height = H;
    if (options.want_colour) frame.rgb.assign(size_t(W) * H * 3, 0);
    if (options.want_depth) frame.depth.assign(size_t(W) * H, 0.0f);
    if (options.want_normal) frame.normal.assign(size_t(W) * H * 3, 0.0f);
    const bool want_normal = options.want_colour || options.want_normal;

    std::unique_ptr<EmbreeVolumeScene> scene;
    if (options.use_embree) {
        scene = std::make_unique<EmbreeVolumeScene>();
        const Dims d = tree.dims();
        std::array<double, 3> lo, hi;
        const uint32_t n[3] = {d.x, d.y, d.z};
        for (int a = 0; a < 3; ++a) {
            const double e0 = placement.origin[a], e1 = placement.origin[a] + double(n[a] - 1) * placement.spacing[a];
            lo[a] = std::min(e0, e1);
            hi[a] = std::max(e0, e1);
        }
        scene->add_volume(lo, hi, &tracer, [](const void* user, const Ray& ray, bool normal) {
            return static_cast<const OctreeTracer<T, Finder>*>(user)->trace(ray, normal);
        });
        scene->commit();
    }

    static const SrgbTable to_srgb8;
    std::atomic<uint64_t> hits{0};
    const auto t0 = std::chrono::steady_clock::now();
    const int ts = tile_size_for(W, H, options.tile_size);
    tbb::parallel_for(
        tbb::blocked_range2d<int>(0, H, ts, 0, W, ts),
        [&](const tbb::blocked_range2d<int>& tile) {
            uint64_t tile_hits = 0;   // folded into the shared counter once per tile
            constexpr int kPacket = EmbreeVolumeScene::kPacket;
            Ray rays[kPacket];
            TraceHit traced[kPacket];
            for (int py = tile.rows().begin(); py < tile.rows().end(); ++py)
                for (int x0 = tile.cols().begin(); x0 < tile.cols().end(); x0 += kPacket) {
                    // A run of up to kPacket pixels of this row: one Embree call per run.
                    const int count = std::min(kPacket, tile.cols().end() - x0);
                    for (int k = 0; k < count; ++k) rays[k] = pinhole.ray(x0 + k, py);
                    if (scene) scene->intersect_packet(rays, count, want_normal, traced);
                    else for (int k = 0; k < count; ++k) traced[k] = tracer.trace(rays[k], want_normal);
                    for (int k = 0; k < count; ++k) {
                        const TraceHit& hit = traced[k];
                        const size_t i = size_t(py) * W + size_t(x0 + k);
                        tile_hits += hit.is_hit();
                        if (options.want_depth) frame.depth[i] = float(hit.t);
                        if (options.want_normal && hit.is_hit())
                            for (int a = 0; a < 3; ++a) frame.normal[3 * i + a] = float(hit.normal[a]);
                        if (options.want_colour) {
                            float rgb[3];
                            if (hit.is_hit()) {
                                const float lambert = float(std::fabs(vec_dot(hit.normal, rays[k].dir)));
                                for (int a = 0; a < 3; ++a)
                                    rgb[a] = kAlbedo[hit.iso_index][a] * (kAmbient + (1.0f - kAmbient) * lambert);
                            } else {
                                for (int a = 0; a < 3; ++a) rgb[a] = kBackground[a];
                            }
                            for (int a = 0; a < 3; ++a) frame.rgb[3 * i + a] = to_srgb8(rgb[a]);
                        }
                    }
                }
            hits += tile_hits;
        },
        tbb::simple_partitioner());
    frame.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    frame.stats.rays = uint64_t(W) * H;
    frame.stats.hits = hits;
    frame.stats.threads = tbb::this_task_arena::max_concurrency();
    return frame;
}

}  // namespace

template <typename T>
Frame render(const Octree<T>& tree, const Placement& placement, const Camera& camera, const RenderOptions& options) {
    validate(camera, options);
    auto run = [&] {
        return dispatch_root_finder(RootFinderKind(int(options.root_finder)), options.iterations, [&](const auto& finder) {
            return render_with(tree, placement, camera, options, finder);
        });
    };
    if (options.threads > 0) {
        tbb::task_arena arena(options.threads);
        return arena.execute(run);
    }
    return run();
}

#define OCTISO_INSTANTIATE(T) \
    template Frame render<T>(const Octree<T>&, const Placement&, const Camera&, const RenderOptions&);
OCTISO_FOR_EACH_SCALAR_TYPE(OCTISO_INSTANTIATE)
#undef OCTISO_INSTANTIATE

}  // namespace octiso
