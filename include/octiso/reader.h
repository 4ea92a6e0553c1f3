// Reading volumes into a LoadedVolume (loaded_volume.h): raw arrays (mmap, endian, offset) and
// the VTK-readable formats (NIfTI, VTI, legacy VTK, MetaImage, NRRD). open_volume() picks the
// reader (CONVENTIONS 3).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "octiso/error.h"
#include "octiso/loaded_volume.h"
#include "octiso/volume.h"

namespace octiso {

enum class Endian { little, big };

/// Maps `path` read-only (no copy) as NX*NY*NZ scalars of `type` after `offset` header bytes.
/// The file must hold exactly offset + voxel bytes. Throws Error(path, ...) for a missing,
/// unreadable, empty or wrongly sized file, a directory, or dims that are zero or overflow.
/// Placement is the default (spacing 1, origin 0).
LoadedVolume read_raw(const std::string& path, Dims dims, ScalarType type, Endian endian = Endian::little,
                      uint64_t offset = 0);

/// Reads a VTK-readable file of format `format` (not raw) through VTK; the vtkImageData stays
/// alive inside the handle, no copy is made. Spacing and origin are what VTK's reader reports
/// (CONVENTIONS 2b). Throws Error(path, ...) for anything VTK cannot read, a multi-component or
/// 64-bit integer image, or an image VTK reads but whose array does not match its dimensions.
/// `array` picks a point data array by name (octiso-convert --array) in a file with several;
/// without it the file's active scalars are read, else its first array. An unknown name throws
/// Error(path, ...) listing the arrays the file has.
LoadedVolume read_vtk(const std::string& path, VolumeFormat format, const std::optional<std::string>& array = std::nullopt);

/// Which format claims `path`: by extension (.nii .nii.gz .vti .vtk .mhd .mha .nrrd .nhdr, any
/// case), else by magic bytes at the start of the file; raw when nothing claims it.
VolumeFormat detect_volume_format(const std::string& path);

/// Command-line options that shape reading (CONVENTIONS 3). dims/type/endian/offset apply to raw
/// input only; spacing/origin override any file's placement.
struct RawOptions {
    std::optional<Dims> dims;
    std::optional<ScalarType> type;
    std::optional<Endian> endian;
    std::optional<uint64_t> offset;
    std::optional<std::array<double, 3>> spacing;
    std::optional<std::array<double, 3>> origin;
    /// --array NAME: the point data array of a VTK file with several (.vti, legacy .vtk).
    std::optional<std::string> array;
};

/// Opens any input: picks the reader with detect_volume_format() (NIfTI: read_nifti() of
/// src/io/volume_stream.h, placed and scaled as CONVENTIONS 2b says) (a file whose magic names a
/// format but that comes with --dims/--type is taken as raw), applies the placement overrides
/// and checks the result (spacing finite and > 0, origin finite). Throws Error naming the file
/// or the missing flag (--dims, --type) on any problem.
LoadedVolume open_volume(const std::string& path, const RawOptions& options);

}  // namespace octiso
