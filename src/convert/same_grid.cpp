// The same-grid check of a series (same_grid.h). Exact comparison of spacing and origin is
// deliberate: the header stores them once, so any difference would misplace a step.
#include "convert/same_grid.h"

#include "octiso/error.h"

namespace octiso::convert_detail {

namespace {
std::string dims_text(Dims d) { return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z); }
}  // namespace

GridOfStep::GridOfStep(const LoadedVolume& v)
    : source(v.source()), format(v.format()), type(v.type()), dims(v.dims()), placement(v.placement()), bytes(v.bytes()),
      value_scale(v.value_scale()), flipped_axes(v.flipped_axes()), warning(v.warning()) {}

void check_same_grid(const GridOfStep& first, const LoadedVolume& v) { check_same_grid(first, GridOfStep(v)); }

void check_same_grid(const GridOfStep& first, const GridOfStep& v) {
    if (v.dims != first.dims)
        throw Error(v.source, "dims differ from the first step (expected " + dims_text(first.dims) + ", found " +
                                    dims_text(v.dims) + ")");
    if (v.type != first.type)
        throw Error(v.source, "scalar type differs from the first step (expected " +
                                    std::string(scalar_type_name(first.type)) + ", found " +
                                    std::string(scalar_type_name(v.type)) + ")");
    if (v.placement.spacing != first.placement.spacing || v.placement.origin != first.placement.origin)
        throw Error(v.source, "spacing or origin differs from the first step (override both with --spacing/--origin)");
    if (v.value_scale != first.value_scale)
        throw Error(v.source, "value scale (NIfTI scl_slope/scl_inter) differs from the first step (expected " +
                                    std::to_string(first.value_scale.slope) + "/" + std::to_string(first.value_scale.inter) +
                                    ", found " + std::to_string(v.value_scale.slope) + "/" + std::to_string(v.value_scale.inter) +
                                    "): the file records one for all steps");
    if (v.flipped_axes != first.flipped_axes)
        throw Error(v.source, "axis orientation (the NIfTI affine's signs) differs from the first step");
}

}  // namespace octiso::convert_detail
