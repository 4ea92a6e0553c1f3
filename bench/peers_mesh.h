// The extract-then-trace peer of `octiso-bench peers`: VTK's vtkFlyingEdges3D turns the volume into
// a triangle mesh in world space, Embree 3 builds a triangle BVH over it (robust or not, medium or
// high quality), and the same TBB tile loop as octiso's render() (same tile size, same rows) shoots
// the same primary rays, either one at a time (rtcIntersect1) or as coherent 8-ray packets along
// tile rows (rtcIntersect8 with RTC_INTERSECT_CONTEXT_FLAG_COHERENT, what render() itself does).
// Reports every cost a user pays after an isovalue change: extraction, BVH build, render, bytes.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "octiso/reader.h"
#include "octiso/render.h"

namespace octiso::bench {

enum class BvhQuality { medium, high };
std::string bvh_quality_name(BvhQuality q);

/// How the mesh's primary rays go to Embree.
/// packet8: 8 pixels of a tile row per rtcIntersect8; packet8_block: 4x2 pixel blocks;
/// packet16_block: 4x4 pixel blocks per rtcIntersect16.
enum class MeshRays { single, packet8, packet8_block, packet16_block };
std::string mesh_rays_name(MeshRays r);

struct MeshPeerOptions {
    BvhQuality quality = BvhQuality::high;
    /// RTC_SCENE_FLAG_ROBUST (Embree's robust triangle intersection). With it the MEDIUM and HIGH
    /// builds measured the same bytes and render times (issue 10), so HIGH is not claimed to add
    /// anything there; the non-robust HIGH build is Embree's fastest-tracing configuration.
    bool robust = true;
    /// true: flying edges also computes vertex normals (VTK's default) and hits shade with the
    /// barycentric interpolation of them; false: the triangle's geometric normal.
    bool vertex_normals = false;
    int threads = 0;     ///< 0: all cores (Embree device threads)
};

struct MeshPeerResult {
    uint64_t vertices = 0, triangles = 0;
    double extract_seconds = 0;        ///< vtkFlyingEdges3D::Update()
    double bvh_seconds = 0;            ///< copy into render buffers + rtcCommitScene
    double first_render_seconds = 0;   ///< wall time of the first whole frame after the build (packets)
    uint64_t mesh_bytes = 0;           ///< vertices + indices (+ vertex normals) as rendered
    uint64_t bvh_bytes = 0;            ///< Embree's allocations, from its memory monitor
    Frame frame;                       ///< depth + the chosen normals (first frame, packets)
    Frame frame_geometric;             ///< depth + geometric normals (for the error table)
    /// Renders the frame again with `rays` (the BVH stays built while this result lives) and
    /// returns the tile-loop seconds; the caller interleaves these repeats with the other methods.
    std::function<double(MeshRays rays, Frame* out)> render;
    /// extraction + BVH build + one render: what an isovalue change costs.
    double time_to_first_image() const { return extract_seconds + bvh_seconds + first_render_seconds; }
};

/// Extracts the isosurface `iso` of `volume` (placed by volume.placement()), builds the BVH and
/// traces one frame with `camera` (packets). Throws Error on an Embree device/scene failure.
MeshPeerResult run_mesh_peer(const LoadedVolume& volume, double iso, const Camera& camera, const MeshPeerOptions& options);

}  // namespace octiso::bench
