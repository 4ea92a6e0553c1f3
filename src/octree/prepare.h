// Conditioning the input before the build: non-finite values (refused, or replaced with --nan-as)
// and --iso-range clamping. Both return a view of the input itself when nothing changes, and make
// one private copy only when values must change.
#pragma once

#include <vector>

#include "octiso/build.h"

namespace octiso::detail {

template <typename T> struct PreparedVolume {
    VolumeView<T> view;      ///< what the builder reads: the input, or `storage`
    std::vector<T> storage;  ///< the modified copy, empty when the input is used as is
};

/// `input` may be a slab of layers [z_first, z_first + input.dims.z) of a larger grid (the
/// streaming converter): messages then name global voxels, and iso-range clamping is exact on
/// every layer whose 3x3x3 neighbourhood the slab holds (all but its first and last, unless those
/// are the grid's own ends).
template <typename T>
PreparedVolume<T> prepare_volume(const VolumeView<T>& input, const BuildOptions& options, uint32_t z_first = 0);

/// The stored value that stands for "at or below LO" (resp. "at or above HI"): the largest T <= lo
/// (smallest T >= hi), so a clamped voxel stays on the same side of every iso in (LO, HI).
template <typename T> T clamp_target_low(double lo);
template <typename T> T clamp_target_high(double hi);

}  // namespace octiso::detail
