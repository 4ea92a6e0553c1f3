// A decoded volume back into the file formats of the ecosystem (octiso-info --extract, issue 17):
// VTK image data (.vti, VTK's XML writer, zlib-compressed), NRRD (.nrrd, a detached-free header
// with sizes, spacing and origin, raw little-endian data), NIfTI-1 (.nii, .nii.gz, VTK's NIfTI
// writer: sform and qform placement, scl_slope/scl_inter) and raw (.raw, the bytes alone).
// NIfTI and raw come back in the source file's order (axes reversed at conversion turned back,
// the sform's negative entries restored); .vti and .nrrd keep the tree's order, which their
// positive spacing describes exactly, and the stored values (neither carries a value scale).
#pragma once

#include <cstddef>
#include <span>
#include <string>

#include "octiso/volume.h"

namespace octiso {

/// Whether `path` names a format write_volume_file writes (by extension: .vti .nrrd .nii .nii.gz .raw).
bool is_volume_file_format(const std::string& path);

/// Writes `data` (dims x scalar size bytes, x fastest, native byte order, the tree's order)
/// placed by `placement` to `path` through a temporary renamed on success. `scale` and
/// `flipped_axes` are the tree's record of its source (oct_file.h): NIfTI writes them into its
/// header, NIfTI and raw reverse the flipped axes back. Throws Error(path, ...): bad input for
/// an unknown extension or a size mismatch, other for a failed write.
void write_volume_file(const std::string& path, ScalarType type, Dims dims, const Placement& placement,
                       std::span<const std::byte> data, const ValueScale& scale = {}, uint8_t flipped_axes = 0);

}  // namespace octiso
