// A decoded volume back into the file formats of the ecosystem (octiso-info --extract, issue 17):
// VTK image data (.vti, VTK's XML writer, zlib-compressed), NRRD (.nrrd, a detached-free header
// with sizes, spacing and origin, raw little-endian data) and raw (.raw, the bytes alone). NIfTI
// is not written yet: its placement rules (sform/qform, flips, CONVENTIONS 2b) are the reader's
// and are being settled there.
#pragma once

#include <cstddef>
#include <span>
#include <string>

#include "octiso/volume.h"

namespace octiso {

/// Whether `path` names a format write_volume_file writes (by extension: .vti .nrrd .raw).
bool is_volume_file_format(const std::string& path);

/// Writes `data` (dims x scalar size bytes, x fastest, native byte order) placed by `placement`
/// to `path` through a temporary renamed on success. Throws Error(path, ...): bad input for an
/// unknown extension or a size mismatch, other for a failed write.
void write_volume_file(const std::string& path, ScalarType type, Dims dims, const Placement& placement,
                       std::span<const std::byte> data);

}  // namespace octiso
