// The NIfTI-1/-2 header as both NIfTI readers need it (issues 13, 17): after check_nifti_header()
// (header_check.h) has bounded it, the grid, time steps, scalar type, byte order, vox_offset,
// value scaling and the placement of CONVENTIONS 2b, as nibabel reads it: the affine of the
// sform if sform_code > 0, else of the qform if qform_code > 0 (quaternion, pixdim, qfac), else
// pixdim with origin 0. A diagonal affine places the grid (a negative entry is a reversed axis);
// any other is placed as VTK does (|pixdim| spacing, origin 0, slices reversed when qfac is -1).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "octiso/volume.h"

namespace octiso::io {

struct NiftiHeader {
    Dims dims;                 ///< dim[1..3]; missing dimensions are 1
    uint32_t time_steps = 1;   ///< dim[4] (a 4-D file is a time series)
    ScalarType type = ScalarType::u8;
    bool swap = false;         ///< the file's byte order is not the host's
    uint64_t vox_offset = 0;   ///< where the voxels start in the (decompressed) file
    double scl_slope = 0, scl_inter = 0;   ///< as stored
    ValueScale value_scale;    ///< nibabel's: identity when scl_slope is 0 or not finite
    double qfac = 1;           ///< pixdim[0] < 0 gives -1
    uint32_t header_bytes = 348;   ///< 348 (NIfTI-1) or 540 (NIfTI-2)
    /// Where the grid sits once the axes in `flipped_axes` are reversed (positive spacing).
    Placement placement;
    uint8_t flipped_axes = 0;  ///< bit a: file axis a runs opposite to world axis a
    /// Empty for a diagonal affine; else the one-line note that the affine was not followed
    /// ("oblique sform (rotation or shear) placed as VTK does: ...").
    std::string warning;
};

/// Parses the first `n` bytes of a (decompressed) NIfTI file, which check_nifti_header() must have
/// accepted (bounds, datatype, dims). Throws Error(path, ...) for dimensions octiso cannot hold
/// (more than 4 used, an extent above Dims::kMaxExtent, more than 2^32-1 time steps) and for a
/// valid scl_slope with a non-finite scl_inter (nibabel refuses that too).
NiftiHeader parse_nifti_header(const unsigned char* header, size_t n, const std::string& path);

/// check_declared_size() on `path`, then its header read (through zlib, so .nii and .nii.gz
/// alike) and parsed. Throws Error(path, ...) on any defect.
NiftiHeader read_nifti_header(const std::string& path);

}  // namespace octiso::io
