// Rendering isosurfaces of an octree volume: what a render is asked for (RenderOptions) and the
// persistent Renderer that answers it frame after frame. A Renderer is built once per octree
// (or series step) and keeps the Embree device and scene, the thread arena and the traversal
// set-up, so a series or an interactive session pays them once. render() is the one-call
// convenience over it. Cameras are camera.h, frames frame.h, tiles tiles.h.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "octiso/camera.h"
#include "octiso/frame.h"
#include "octiso/limits.h"
#include "octiso/octree.h"
#include "octiso/root_finder.h"
#include "octiso/tiles.h"
#include "octiso/volume.h"

namespace octiso {

/// How primary rays traverse the octree: in packets of up to 8 neighbouring pixels that share
/// node visits, culls and corner lookups (the default; Knoll, Wald, Hansen 2009), or one by one.
/// Both give bit-identical frames; `single` exists for comparison and for the benchmark.
enum class Traversal { packets, single };

/// Which build of the traversal kernel runs: automatic (AVX2 + FMA where the CPU has them, else
/// the portable x86-64-v2 build), or one forced (avx2 on a CPU without it is refused). All give
/// bit-identical frames.
enum class Isa { automatic, baseline, avx2 };
/// The kernel `requested` runs on this CPU: automatic picks avx2 where the CPU has AVX2 and FMA,
/// else baseline; an explicit avx2 on a CPU without them throws Error("isa", ...).
Isa resolve_isa(Isa requested);
/// Whether this CPU can run the AVX2 kernel (AVX2 and FMA).
bool cpu_has_avx2();

/// A clip plane (issue 17 item 7, `--clip NX,NY,NZ,D`): in world coordinates, the half-space
/// n . p <= d is kept and the rest of the volume is cut away for every ray (primary and
/// secondary). n need not be unit length (d then scales with |n|); it must be finite and non-zero.
struct ClipPlane {
    std::array<double, 3> normal{0, 0, 1};
    double d = 0;
};

struct RenderOptions {
    std::vector<double> isovalues;      ///< 1 .. kMaxIsovalues, each with its own colour
    RootFinder root_finder = RootFinder::neubauer;
    int iterations = -1;                ///< refinement steps of the root finder; < 0: its default
    bool want_colour = true;            ///< false: depth-only renders skip shading
    bool want_depth = false;
    bool want_normal = false;
    /// true: primary rays through an Embree scene holding the volume as a user geometry (the
    /// path a scene mixing meshes and volumes takes). false (the default since issue 11): the
    /// scene holds only the volume, so the traversal is called directly; the same pixels
    /// (RenderPaths.EmbreeAndDirectGiveIdenticalFrames) for 0-9 % less per frame (medians of
    /// bench/results/build_ab_direct_default.json; BENCHMARKS.md, Embree dispatch).
    bool use_embree = false;
    Traversal traversal = Traversal::packets;
    Isa isa = Isa::automatic;
    /// Expert: a packet continues while at least this many lanes enter a subtree; 0 keeps the
    /// measured default (OctreeTracer::kDefaultMinPacketLanes, 2). At the root a packet starts
    /// only with at least 4 lanes of the same direction signs (kMinStartLanes) or this many, if
    /// more. For the benchmark's A/B.
    int packet_min_lanes = 0;
    /// Sort-last rendering (octiso-render --distribute data, octiso/bricks.h): only the cells of
    /// this box are tested, and nodes wholly outside it are never visited (nor their file pages
    /// touched); a ray's hit is its first hit among those cells, bit for bit the hit of the whole
    /// volume wherever that lies in the box. Unset: every cell.
    std::optional<CellBox> owned_cells;
    /// With owned_cells: the voxels of the plane x = owned_cells->hi[0] (element y + ny * z), the
    /// ghost face its last cells need. They are read from here instead of the neighbour's nodes,
    /// whose face is spread over all of its pages (Morton order); null: read from the octree.
    std::shared_ptr<const std::vector<double>> ghost_plane;
    int threads = 0;                    ///< 0: all cores
    int tile_size = 0;                  ///< square tile side in pixels; 0: tile_size_for() picks it
    TileOrder tile_order = TileOrder::split;   ///< expert: how tiles go to threads (tiles.h); same pixels
    /// Every ray's interval is cut to the intersection of these half-spaces before traversal
    /// (src/render/clip.h); empty: no clipping, the frames of before bit for bit.
    std::vector<ClipPlane> clip_planes;
    /// Level of detail (issue 14, `--lod F`): 0 (the default) traces every surface at full
    /// resolution; F > 0 stops descending where a node's cells would be no wider than F pixels at
    /// its nearest point to the camera, and traces the trilinear field of the voxels on that
    /// node's coarse lattice instead (src/render/lod.h). Below two voxels per F pixels nothing
    /// changes: close up the frame is the exact one bit for bit. A Renderer with lod > 0 renders
    /// its frames one at a time (the cut belongs to the camera); not with owned_cells.
    double lod = 0;
};

/// What the renderer must know about the octree's source beyond its voxels: a file converted
/// with --iso-range LO,HI is exact only for isovalues strictly inside (LO, HI).
struct RenderLimits {
    std::optional<std::array<double, 2>> iso_range;
    std::string source;                 ///< the file, named in the refusal
};

class Renderer {
public:
    /// Prepares rendering `tree` placed in the world by `placement`. The octree's storage (an
    /// OctreeData or a mapped OctFile) must outlive the Renderer, or be handed to keep_alive(). Throws Error on bad options
    /// (set_options) or when Embree cannot be set up.
    template <typename T>
    Renderer(const Octree<T>& tree, const Placement& placement, const RenderOptions& options,
             const RenderLimits& limits = {});
    ~Renderer();
    Renderer(Renderer&&) noexcept;
    Renderer& operator=(Renderer&&) noexcept;

    /// New isovalues, root finder, outputs or threads; validated as at construction. The Embree
    /// device and scene are kept. Not to be called while a render of this Renderer runs.
    void set_options(const RenderOptions& options);
    const RenderOptions& options() const;
    ScalarType type() const;

    /// Shares ownership of `storage`, whatever holds the octree's arrays (AnyOctree passes its
    /// own), so the Renderer stays valid however long it is kept. Optional for typed callers.
    void keep_alive(std::shared_ptr<const void> storage);

    /// The tiles a frame of width x height is cut into under these options.
    TileGrid tile_grid(int width, int height) const;

    /// Renders the whole frame into `frame`, resized to the camera (buffers are reused when the
    /// size and outputs match the previous frame). Throws Error for an invalid camera.
    /// Thread-safe for distinct frames.
    RenderStats render(const Camera& camera, Frame& frame) const;
    Frame render(const Camera& camera) const;

    /// Sizes `frame` for `camera` and these options (as render() does) without tracing.
    void prepare_frame(const Camera& camera, Frame& frame) const;
    /// Renders only `tiles` (indices into tile_grid(camera.width, camera.height)) into `frame`,
    /// which prepare_frame() sized; pixels of other tiles are left as they are. Throws Error for
    /// an invalid camera, a frame of another size or a tile index out of range.
    RenderStats render_tiles(const Camera& camera, std::span<const int> tiles, Frame& frame) const;

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

/// Throws Error(flag, ...) unless `options` can be rendered: 1 .. kMaxIsovalues finite
/// isovalues (inside the iso-range of `limits`, if any), a non-negative tile size, clip planes
/// with finite, non-zero normals and finite offsets.
void validate_options(const RenderOptions& options, const RenderLimits& limits = {});

/// One frame in one call: a Renderer built, used once and dropped. Throws Error on bad options.
template <typename T>
Frame render(const Octree<T>& tree, const Placement& placement, const Camera& camera, const RenderOptions& options);

}  // namespace octiso
