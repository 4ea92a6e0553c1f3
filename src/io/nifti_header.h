// The NIfTI-1/-2 header as the streaming reader needs it (issue 13): after check_nifti_header()
// (header_check.h) has bounded it, the grid, time steps, scalar type, byte order, vox_offset,
// value scaling and the placement of CONVENTIONS 2b (sform if sform_code > 0, else qform if
// qform_code > 0, else pixdim with origin 0). Only axis-aligned affines without a flipped axis
// are placed here; the others are named so that callers can refuse or fall back.
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
    double scl_slope = 0, scl_inter = 0;
    double qfac = 1;           ///< pixdim[0]: -1 means VTK's reader reverses the slices
    uint32_t header_bytes = 348;   ///< 348 (NIfTI-1) or 540 (NIfTI-2)
    Placement placement;       ///< valid when `unplaced` is empty
    /// Why the affine could not be turned into spacing + origin ("oblique sform", "sform flips
    /// axis x", ...); empty when it could.
    std::string unplaced;
    /// Whether scl_slope/scl_inter change any value (slope not 0 and not the identity).
    bool scales_values() const { return scl_slope != 0 && !(scl_slope == 1 && scl_inter == 0); }
};

/// Parses the first `n` bytes of a (decompressed) NIfTI file, which check_nifti_header() must have
/// accepted (bounds, datatype, dims). Throws Error(path, ...) for dimensions octiso cannot hold
/// (more than 4 used, an extent above Dims::kMaxExtent, more than 2^32-1 time steps).
NiftiHeader parse_nifti_header(const unsigned char* header, size_t n, const std::string& path);

/// check_declared_size() on `path`, then its header read (through zlib, so .nii and .nii.gz
/// alike) and parsed. Throws Error(path, ...) on any defect.
NiftiHeader read_nifti_header(const std::string& path);

}  // namespace octiso::io
