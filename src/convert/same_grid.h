// The same-grid rule of a time series: every step must agree with the first in everything the
// .oct header records once for all steps (dims, scalar type, spacing, origin, value scale, flipped axes). GridOfStep keeps
// what the check and the report need from step 0 without keeping its voxels alive.
#pragma once

#include <cstdint>
#include <string>

#include "octiso/reader.h"
#include "octiso/volume.h"

namespace octiso::convert_detail {

struct GridOfStep {
    std::string source;
    VolumeFormat format = VolumeFormat::raw;
    ScalarType type = ScalarType::u8;
    Dims dims;
    Placement placement;
    uint64_t bytes = 0;   ///< dense voxel bytes
    ValueScale value_scale;      ///< stored-to-real values (recorded once for all steps)
    uint8_t flipped_axes = 0;
    std::string warning;         ///< the reader's note, if any
    explicit GridOfStep(const LoadedVolume& v);
    GridOfStep(std::string source, VolumeFormat format, ScalarType type, Dims dims, Placement placement, uint64_t bytes,
               ValueScale value_scale = {}, uint8_t flipped_axes = 0, std::string warning = {})
        : source(std::move(source)), format(format), type(type), dims(dims), placement(placement), bytes(bytes),
          value_scale(value_scale), flipped_axes(flipped_axes), warning(std::move(warning)) {}
};

/// Throws Error(step.source(), ...) (bad input, exit 2) naming the first field that differs
/// from step 0, with both values for dims and type.
void check_same_grid(const GridOfStep& first, const LoadedVolume& step);
/// The same rule for a step described by `step` (a streamed step, whose voxels are not loaded).
void check_same_grid(const GridOfStep& first, const GridOfStep& step);

}  // namespace octiso::convert_detail
