// Whole reference frames from the dense brute-force tracer (TBB over rows), and the image error
// of CONVENTIONS 4 between a frame and its reference: hit-mask mismatch, depth error in voxels
// (median, p99, max over pixels both hit) and normal angle error in degrees (median, max).
#pragma once

#include "octiso/camera.h"
#include "octiso/frame.h"
#include "reference/brute_force.h"

namespace octiso {

/// Depth and normal of the exact reference for the first isovalue hit of each pixel (several
/// isovalues: the nearest over all). Fills frame.depth and frame.normal (no colour).
template <typename T>
Frame render_reference(const VolumeView<T>& volume, const Placement& placement, const Camera& camera,
                       const std::vector<double>& isovalues);

struct ImageError {
    uint64_t pixels = 0, mask_mismatch = 0, both_hit = 0;
    double mask_mismatch_fraction = 0;
    double depth_median = 0, depth_p99 = 0, depth_max = 0;   ///< voxel units
    uint64_t depth_above_1e3 = 0;                            ///< pixels both hit, depth error > 1e-3 voxel
    double normal_median_deg = 0, normal_max_deg = 0;        ///< only where both frames have normals
};

/// `frame` against `reference`; both need depth, normals are compared when both have them.
/// `voxel` is the smallest spacing component (CONVENTIONS 2b). Throws Error when the two frames
/// differ in size (width, height, depth or normal pixels): there is no pixel-by-pixel answer then.
ImageError compare_frames(const Frame& frame, const Frame& reference, double voxel);

}  // namespace octiso
