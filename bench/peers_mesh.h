// The extract-then-trace peer of `octiso-bench peers`: VTK's vtkFlyingEdges3D turns the volume into
// a triangle mesh in world space, Embree 3 builds a robust triangle BVH over it, and the same TBB
// tile loop as octiso shoots the same primary rays (rtcIntersect1). Reports every cost a user pays
// after an isovalue change: extraction, BVH build, render, and the bytes of mesh and BVH.
#pragma once

#include <cstdint>
#include <string>

#include "octiso/reader.h"
#include "octiso/render.h"

namespace octiso::bench {

enum class BvhQuality { medium, high };
std::string bvh_quality_name(BvhQuality q);

struct MeshPeerOptions {
    BvhQuality quality = BvhQuality::high;
    /// true: flying edges also computes vertex normals (VTK's default) and hits shade with the
    /// barycentric interpolation of them; false: the triangle's geometric normal.
    bool vertex_normals = false;
    int repeats = 3;     ///< timed renders after the first; the median is reported
    int threads = 0;     ///< 0: all cores (Embree device threads)
};

struct MeshPeerResult {
    uint64_t vertices = 0, triangles = 0;
    double extract_seconds = 0;        ///< vtkFlyingEdges3D::Update()
    double bvh_seconds = 0;            ///< copy into render buffers + rtcCommitScene
    double first_render_seconds = 0;   ///< wall time of the first whole frame after the build
    double render_seconds = 0;         ///< median tile-loop time of the repeated frames
    uint64_t mesh_bytes = 0;           ///< vertices + indices (+ vertex normals) as rendered
    uint64_t bvh_bytes = 0;            ///< Embree's allocations, from its memory monitor
    Frame frame;                       ///< depth + the chosen normals
    Frame frame_geometric;             ///< depth + geometric normals (for the error table)
    /// extraction + BVH build + one render: what an isovalue change costs.
    double time_to_first_image() const { return extract_seconds + bvh_seconds + first_render_seconds; }
};

/// Extracts the isosurface `iso` of `volume` (placed by volume.placement()) and ray traces it with
/// `camera`. Throws Error on an Embree device/scene failure.
MeshPeerResult run_mesh_peer(const LoadedVolume& volume, double iso, const Camera& camera, const MeshPeerOptions& options);

}  // namespace octiso::bench
