// The OpenVDB peer (the only file that includes OpenVDB: its headers are slow to compile). Without
// OCTISO_HAVE_OPENVDB it compiles to a stub that says OpenVDB was not found. With it: the volume as
// a lossless float grid (copyFromDense, tolerance 0), and the level-set path of notes/peers.md 1.3
// for an arbitrary scalar: g = s * (iso - f) with s = 1.9 voxel / (largest per-cell range), so
// every cell that brackets iso keeps its corners inside the intersector's +-2 voxel value window.
#include "bench/peers_vdb.h"

#ifndef OCTISO_HAVE_OPENVDB

namespace octiso::bench {
bool vdb_available() { return false; }
VdbPeerResult run_vdb_peer(const LoadedVolume&, double, const Camera&) {
    VdbPeerResult r;
    r.skipped = "OpenVDB was not found when octiso-bench was configured";
    return r;
}
}  // namespace octiso::bench

#else

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/RayIntersector.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "bench/bench.h"
#include "render/pinhole_camera.h"
#include "render/tile_loop.h"
#include "util/huge_pages.h"

namespace octiso::bench {

bool vdb_available() { return true; }

namespace {

/// The volume as dense floats, x fastest (LayoutXYZ below keeps that order).
std::vector<float> float_copy(const LoadedVolume& volume) {
    std::vector<float> out(volume.dims().voxels());
    dispatch_scalar_type(volume.type(), [&](auto tag) {
        using T = decltype(tag);
        const VolumeView<T> view = volume.view<T>();
        tbb::parallel_for(tbb::blocked_range<uint64_t>(0, out.size(), 1 << 16), [&](const tbb::blocked_range<uint64_t>& r) {
            for (uint64_t i = r.begin(); i < r.end(); ++i) out[i] = float(view.load(i));
        });
    });
    return out;
}

/// Largest max - min over the 8 corners of any cell (CONVENTIONS 1: only cells inside the data).
double max_cell_range(const std::vector<float>& f, Dims d) {
    if (d.x < 2 || d.y < 2 || d.z < 2) return 0;
    const uint64_t sx = 1, sy = d.x, sz = uint64_t(d.x) * d.y;
    return tbb::parallel_reduce(
        tbb::blocked_range<uint32_t>(0, d.z - 1), 0.0,
        [&](const tbb::blocked_range<uint32_t>& r, double best) {
            for (uint32_t z = r.begin(); z < r.end(); ++z)
                for (uint32_t y = 0; y + 1 < d.y; ++y)
                    for (uint32_t x = 0; x + 1 < d.x; ++x) {
                        const uint64_t i = x + sy * y + sz * z;
                        const float c[8] = {f[i], f[i + sx], f[i + sy], f[i + sx + sy],
                                            f[i + sz], f[i + sx + sz], f[i + sy + sz], f[i + sx + sy + sz]};
                        const auto [lo, hi] = std::minmax_element(c, c + 8);
                        best = std::max(best, double(*hi) - double(*lo));
                    }
            return best;
        },
        [](double a, double b) { return std::max(a, b); });
}

openvdb::FloatGrid::Ptr grid_from_dense(std::vector<float>& values, Dims d, float background, const Placement& p, double h) {
    using namespace openvdb;
    const CoordBBox bbox(openvdb::Coord(0), openvdb::Coord(int(d.x) - 1, int(d.y) - 1, int(d.z) - 1));
    tools::Dense<float, tools::LayoutXYZ> dense(bbox, values.data());
    FloatGrid::Ptr grid = FloatGrid::create(background);
    // Vertex-centred: voxel (i,j,k) at origin + h*(i,j,k), exactly CONVENTIONS 1 for uniform spacing.
    math::Transform::Ptr xf = math::Transform::createLinearTransform(h);
    xf->postTranslate(Vec3d(p.origin[0], p.origin[1], p.origin[2]));
    grid->setTransform(xf);
    tools::copyFromDense(dense, *grid, 0.0f);   // tolerance 0: lossless
    return grid;
}

}  // namespace

VdbPeerResult run_vdb_peer(const LoadedVolume& volume, double iso, const Camera& camera) {
    using namespace openvdb;
    openvdb::initialize();
    VdbPeerResult r;
    const Placement& p = volume.placement();
    const double h = p.spacing[0];
    if (std::fabs(p.spacing[1] - h) > 1e-9 * h || std::fabs(p.spacing[2] - h) > 1e-9 * h) {
        r.skipped = "anisotropic spacing: LevelSetRayIntersector needs uniform voxels";
        return r;
    }
    const Dims d = volume.dims();

    auto t0 = std::chrono::steady_clock::now();
    std::vector<float> values = float_copy(volume);
    r.to_float_seconds = seconds_since(t0);
    const auto [lo_it, hi_it] = std::minmax_element(values.begin(), values.end());
    const double f_min = *lo_it, f_max = *hi_it;
    if (!(iso > f_min && iso < f_max)) {
        r.skipped = "isovalue outside the data range: no surface";
        return r;
    }

    // (1) The data itself as a sparse float grid; the most common "empty" value of these data sets
    // is the minimum (ambient air, light fluid), so that is the background.
    {
        t0 = std::chrono::steady_clock::now();
        FloatGrid::Ptr grid = grid_from_dense(values, d, float(f_min), p, h);
        r.dense_seconds = seconds_since(t0);
        r.dense_bytes = grid->memUsage();
        r.dense_leaves = grid->tree().leafCount();
        r.dense_active_voxels = grid->activeVoxelCount();
    }

    // (2) The level set g = s * (iso - f): inside (f > iso) negative, zero set unchanged.
    // Deviation from a true SDF: |grad g| ~ 1 only where the data changes fastest; elsewhere the
    // field is flatter, which the intersector tolerates (it only needs the corners of bracketing
    // cells inside its +-2 voxel window).
    using Intersector = tools::LevelSetRayIntersector<FloatGrid>;
    t0 = std::chrono::steady_clock::now();
    const double range = max_cell_range(values, d);
    r.scale = range > 0 ? 1.9 * h / range : 1.0;
    r.background = r.scale * (iso - f_min);   // > 0 because iso > f_min
    const float s = float(r.scale), v = float(iso);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, values.size(), 1 << 16), [&](const tbb::blocked_range<size_t>& b) {
        for (size_t i = b.begin(); i < b.end(); ++i) values[i] = s * (v - values[i]);
    });
    // What stays alive between frames: the grid and the intersector that refers to it.
    struct State {
        FloatGrid::Ptr level_set;
        std::unique_ptr<Intersector> master;
    };
    auto state = std::make_shared<State>();
    state->level_set = grid_from_dense(values, d, float(r.background), p, h);
    FloatGrid::Ptr level_set = state->level_set;
    level_set->setGridClass(GRID_LEVEL_SET);
    std::vector<float>().swap(values);
    state->master = std::make_unique<Intersector>(*level_set, 0.0f);
    r.levelset_seconds = seconds_since(t0);
    r.levelset_bytes = level_set->memUsage();

    // (3) The same primary rays, tiles and partitioner as octiso; one intersector copy per thread
    // (it caches a ValueAccessor and is not thread-safe).
    const PinholeCamera pinhole(camera);
    const int W = camera.width, H = camera.height;
    auto render_once = [state, pinhole, W, H](Frame& frame) {
        const Intersector& master = *state->master;
        frame.width = W, frame.height = H;
        assign_on_huge_pages(frame.depth, size_t(W) * H, 0.0f);   // as octiso's frames (util/huge_pages.h)
        assign_on_huge_pages(frame.normal, size_t(W) * H * 3, 0.0f);
        tbb::enumerable_thread_specific<Intersector> per_thread(master);
        std::atomic<uint64_t> hits{0};
        const auto start = std::chrono::steady_clock::now();
        for_each_tile(  // render()'s tile loop over render()'s tiles
            tile_grid_for(W, H, 0), {}, true,
            [&](const PixelRect& tile, TileCounters&) {
                Intersector& intersector = per_thread.local();
                uint64_t tile_hits = 0;
                for (int py = tile.y0; py < tile.y1; ++py)
                    for (int px = tile.x0; px < tile.x1; ++px) {
                        const Ray ray = pinhole.ray(px, py);
                        const math::Ray<Real> w_ray(Vec3R(ray.origin[0], ray.origin[1], ray.origin[2]),
                                                    Vec3R(ray.dir[0], ray.dir[1], ray.dir[2]));
                        Vec3R xyz, n;
                        Real t = 0;
                        const size_t i = size_t(py) * W + px;
                        // The (ray, xyz, normal, t) overload: the (ray, t) ones return a stale t in 10.0.1.
                        if (!intersector.intersectsWS(w_ray, xyz, n, t)) {
                            frame.depth[i] = std::numeric_limits<float>::infinity();
                            continue;
                        }
                        ++tile_hits;
                        frame.depth[i] = float(t);
                        const double len = n.length();
                        const double dot = n[0] * ray.dir[0] + n[1] * ray.dir[1] + n[2] * ray.dir[2];
                        const double sign = dot > 0 ? -1.0 : 1.0;
                        for (int a = 0; a < 3; ++a)
                            frame.normal[3 * i + a] = len > 0 ? float(sign * n[a] / len) : float(-ray.dir[a]);
                    }
                hits += tile_hits;
            });
        frame.stats.seconds = seconds_since(start);
        frame.stats.rays = uint64_t(W) * H;
        frame.stats.hits = hits;
    };
    t0 = std::chrono::steady_clock::now();
    render_once(r.frame);
    r.first_render_seconds = seconds_since(t0);
    r.render = [render_once](Frame* out) {
        Frame scratch;
        Frame& f = out ? *out : scratch;
        render_once(f);
        return f.stats.seconds;
    };
    r.ran = true;
    return r;
}

}  // namespace octiso::bench

#endif  // OCTISO_HAVE_OPENVDB
