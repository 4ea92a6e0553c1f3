// LodCut: where level of detail (issue 14, RenderOptions::lod) stops the descent, for one camera.
// GigaVoxels' rule (papers 000_, 003_; notes/anchors-wave2.md): a pixel is a cone whose width grows
// with distance, and detail finer than F times that width is not visited. Here the width is
// measured at a node's nearest point to the eye, so the decision belongs to the node, not to the
// ray: every ray (primary, shadow, AO) sees the same cut through the tree, hence the same coarse
// surface, and a child is never coarser than its parent allowed (its nearest point is no nearer).
//
// The coarse field of lattice unit u (a power of two) is the trilinear interpolant of the voxels
// at the multiples of u, the lattice sample each stored node keeps (format 4, octree.h
// lattice_value). Decimation, not a mean: every coarse corner is a voxel of the node's own
// closed cube, so the node's full-resolution [min, max] still bounds the coarse cell and culling
// stays conservative, and the coarse surface passes through the data where the lattice does
// (the choice measured against block means and range midpoints: `octiso-bench lod`, BENCHMARKS.md).
//
// Outside the ISA namespaces on purpose: the Renderer builds one and hands it to either kernel.
// unit() runs inside the traversal, so it is forced inline (check_isa: no AVX copy outside
// isa_avx2).
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "octiso/camera.h"
#include "octiso/inline.h"
#include "octiso/octree.h"
#include "octiso/volume.h"

namespace octiso {

struct LodCut {
    std::array<double, 3> eye{};     ///< the camera's eye in index space
    std::array<double, 3> scale{};   ///< |spacing|: index-space lengths to world lengths, per axis
    /// F x the pixel's width per unit of distance, in voxels of the coarsest axis: the coarse cell
    /// side (in voxels) allowed at world distance r is r x this.
    double voxels_per_distance = 0;

    /// Level of detail is on: a positive factor made the cut (make_lod_cut); 0, the default, is off.
    OCTISO_ALWAYS_INLINE bool on() const { return voxels_per_distance > 0; }

    /// The lattice unit for the cube [o, o + side]^3: the largest power of two no larger than the
    /// allowed cell side at the cube's nearest point to the eye, at most `side`; 1 below two
    /// voxels (full resolution: the exact traversal).
    OCTISO_ALWAYS_INLINE uint32_t unit(const Coord& o, uint32_t side) const {
        const double lo[3] = {double(o.x), double(o.y), double(o.z)};
        double r2 = 0;
        for (int a = 0; a < 3; ++a) {
            const double hi = lo[a] + double(side);
            const double gap = eye[a] < lo[a] ? lo[a] - eye[a] : eye[a] > hi ? eye[a] - hi : 0.0;
            const double g = gap * scale[a];
            r2 += g * g;
        }
        const double allowed = std::sqrt(r2) * voxels_per_distance;
        if (!(allowed >= 2.0)) return 1;
        if (allowed >= double(side)) return side;
        return std::bit_floor(uint32_t(allowed));
    }
};

/// The cut for `camera` over data placed by `placement` at factor `factor` (> 0; 0 is off). The
/// pixel's width at unit distance is the vertical one at the image centre, 2 tan(fov/2) / height
/// (CONVENTIONS 2); voxels are counted along the axis of largest spacing, so an anisotropic
/// coarse cell is never wider than F pixels along any axis.
inline LodCut make_lod_cut(const Camera& camera, const Placement& placement, double factor) {
    LodCut cut;
    if (!(factor > 0)) return cut;
    double widest = 0;
    for (int a = 0; a < 3; ++a) {
        cut.scale[a] = std::fabs(placement.spacing[a]);
        cut.eye[a] = (camera.eye[a] - placement.origin[a]) / placement.spacing[a];
        widest = std::max(widest, cut.scale[a]);
    }
    const double pixel = 2.0 * std::tan(camera.fov_deg * 0.5 * (std::numbers::pi / 180.0)) / double(camera.height);
    cut.voxels_per_distance = factor * pixel / widest;
    return cut;
}

}  // namespace octiso
