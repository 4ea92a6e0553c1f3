// Header checks made before a VTK reader sees a file (issue 18): VTK's NIfTI reader segfaulted on
// datatypes it does not handle (1234, 1536, 2048) and threw length_error on 255; its NRRD, legacy
// VTK and MetaImage readers zero-filled voxels a header declared but the file did not hold (and a
// 1000^3 declaration allocated 4 GB first). Each check parses just enough of the header to know
// the element type and count and where the data lies, and compares that with the bytes there.
// Compressed data is bounded by deflate's largest ratio (1032:1). Layouts VTK accepts that these
// parsers do not recognise (file lists, patterns) are left to VTK and the array-length check after.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "octiso/reader.h"

namespace octiso::io {

/// Throws Error(path, ...) (bad input) if the header of `path` (format `format`) declares
/// something octiso cannot read or more voxel bytes than the file (or its data file) holds.
/// Returns the voxel bytes the header declares (what VTK will allocate), 0 where it was not
/// parsed (NIfTI, file lists and patterns, layouts left to VTK).
uint64_t check_declared_size(const std::string& path, VolumeFormat format);

/// The NIfTI-1/-2 header check on bytes already read: `header` holds the first `n` bytes of the
/// (decompressed) file, `data_bytes_bound` the most bytes the file can hold after vox_offset's
/// origin (file size, or compressed size x 1032). Exposed for the fuzzer.
void check_nifti_header(const unsigned char* header, size_t n, uint64_t data_bytes_bound, bool exact, const std::string& path);

}  // namespace octiso::io
