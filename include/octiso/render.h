// Rendering isosurfaces of an octree volume: the pinhole camera of CONVENTIONS 2, what a render is
// asked for (isovalues, root finder, which outputs), and the Frame it returns (colour and the depth
// and normal AOVs). render() runs tile-parallel on all cores (TBB) through an Embree scene, or
// directly (`use_embree = false`) for comparison; both trace the same rays.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "octiso/octree.h"
#include "octiso/volume.h"

namespace octiso {

/// Perspective pinhole, world units (CONVENTIONS 2). fov_deg is the vertical field of view.
struct Camera {
    std::array<double, 3> eye{0, 0, 0}, look{0, 0, 1}, up{0, 1, 0};
    double fov_deg = 40.0;
    int width = 512, height = 512;
};

/// A camera that frames the data box of `dims` placed by `placement` from a three-quarter view.
Camera frame_data_box(Dims dims, const Placement& placement, int width, int height);

enum class RootFinder { neubauer, schwarze, linear, exact };
/// "neubauer", "schwarze", "linear", "exact"; throws Error("--root-finder", ...) otherwise.
RootFinder parse_root_finder_name(const std::string& name);

struct RenderOptions {
    std::vector<double> isovalues;      ///< 1 .. kMaxIsovalues, each with its own colour
    RootFinder root_finder = RootFinder::neubauer;
    int iterations = -1;                ///< refinement steps of the root finder; < 0: its default
    bool want_colour = true;            ///< false: depth-only renders skip shading
    bool want_depth = false;
    bool want_normal = false;
    bool use_embree = true;             ///< false: call the traversal directly (no Embree dispatch)
    int threads = 0;                    ///< 0: all cores
    /// Square tile side in pixels; 0 picks it: 16 when the frame holds at least 4096 such tiles,
    /// else 8, so even 512^2 frames have enough tiles to balance many cores (octiso-bench scaling:
    /// simulated 64-thread efficiency at 512^2 82 % with 16x16 tiles, 96 % with 8x8).
    int tile_size = 0;
};
inline constexpr int kMaxIsovalues = 8;

struct RenderStats {
    double seconds = 0;                 ///< wall time of the tile loop
    uint64_t rays = 0, hits = 0;
    int threads = 0;
    double mrays_per_second() const { return seconds > 0 ? double(rays) / seconds * 1e-6 : 0; }
};

/// One rendered image. Row 0 is the top row. Empty vectors for outputs not asked for.
struct Frame {
    int width = 0, height = 0;
    std::vector<uint8_t> rgb;           ///< 8-bit sRGB, 3 per pixel
    std::vector<float> depth;           ///< world distance t, +inf on a miss
    std::vector<float> normal;          ///< world unit normal facing the ray, 0,0,0 on a miss
    RenderStats stats;
};

/// The tile side render() uses for a frame of width x height under `requested` (0: automatic).
int tile_size_for(int width, int height, int requested);

/// Renders the isosurfaces of `tree` placed in the world by `placement`. Throws Error on bad
/// options (no isovalue, too many). Thread-safe for distinct frames.
template <typename T>
Frame render(const Octree<T>& tree, const Placement& placement, const Camera& camera, const RenderOptions& options);

}  // namespace octiso
