// Reading volumes: LoadedVolume, an owning handle over voxels that stay where they were loaded
// (an mmap'd raw file, a VTK image kept alive behind a type-erased owner, or a generated buffer),
// and the readers that make one: raw arrays (mmap, endian, offset) and the VTK-readable formats
// (NIfTI, VTI, legacy VTK, MetaImage, NRRD). open_volume() picks the reader (CONVENTIONS 3).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "octiso/error.h"
#include "octiso/volume.h"

namespace octiso {

enum class Endian { little, big };

/// The formats open_volume() knows. `raw` is whatever no other format claims (CONVENTIONS 3).
enum class VolumeFormat { raw, nifti, vti, legacy_vtk, meta_image, nrrd, synthetic };
std::string_view volume_format_name(VolumeFormat f);

/// Owns (or shares ownership of) the bytes of one volume and hands out typed views of them.
/// Invariants: data() points to dims().voxels() scalars of type(), x fastest, valid for the
/// lifetime of any copy of this handle; swap_bytes() says they are of the other endianness.
/// Copies share the same bytes; the handle is immutable apart from its placement.
class LoadedVolume {
public:
    LoadedVolume() = default;
    /// `owner` keeps `data` alive (munmap, vtkImageData release, vector...) when the last copy goes.
    LoadedVolume(std::shared_ptr<const void> owner, const std::byte* data, ScalarType type, Dims dims,
                 Placement placement, bool swap_bytes, std::string source, VolumeFormat format);

    ScalarType type() const { return type_; }
    Dims dims() const { return dims_; }
    const Placement& placement() const { return placement_; }
    void set_placement(const Placement& placement) { placement_ = placement; }
    uint64_t bytes() const { return dims_.voxels() * scalar_type_bytes(type_); }   ///< voxel bytes
    bool swap_bytes() const { return swap_bytes_; }
    const std::byte* data() const { return data_; }
    const std::string& source() const { return source_; }   ///< file path or synthetic spec
    VolumeFormat format() const { return format_; }
    bool empty() const { return data_ == nullptr; }

    /// Typed view; throws Error(source, ...) if T is not type() (use dispatch_scalar_type first).
    template <typename T> VolumeView<T> view() const {
        if (scalar_type_of<T>() != type_)
            throw Error(source_, "volume holds " + std::string(scalar_type_name(type_)) + ", not " +
                                     std::string(scalar_type_name(scalar_type_of<T>())), ErrorKind::Other);
        VolumeView<T> v;
        v.data = data_;
        v.dims = dims_;
        v.swap_bytes = swap_bytes_;
        return v;
    }

private:
    std::shared_ptr<const void> owner_;
    const std::byte* data_ = nullptr;
    ScalarType type_ = ScalarType::u8;
    Dims dims_;
    Placement placement_;
    bool swap_bytes_ = false;
    std::string source_;
    VolumeFormat format_ = VolumeFormat::raw;
};

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
LoadedVolume read_vtk(const std::string& path, VolumeFormat format);

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
};

/// Opens any input: picks the reader with detect_volume_format() (a file whose magic names a
/// format but that comes with --dims/--type is taken as raw), applies the placement overrides
/// and checks the result (spacing finite and > 0, origin finite). Throws Error naming the file
/// or the missing flag (--dims, --type) on any problem.
LoadedVolume open_volume(const std::string& path, const RawOptions& options);

}  // namespace octiso
