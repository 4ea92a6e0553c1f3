// LoadedVolume: an owning handle over the voxels of one volume that stay where they were loaded
// (an mmap'd raw file, a VTK image kept alive behind a type-erased owner, or a generated buffer),
// and the formats a volume can come from. The readers that make one are reader.h (io); the
// synthetic generators (synthetic.h) and the octree builders take one without any reader.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "octiso/error.h"
#include "octiso/volume.h"

namespace octiso {

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
    /// Stored-to-real values and the source axes reversed at reading (NIfTI, CONVENTIONS 2b);
    /// identity and 0 for every other source.
    const ValueScale& value_scale() const { return value_scale_; }
    uint8_t flipped_axes() const { return flipped_axes_; }
    void set_source_order(const ValueScale& scale, uint8_t flipped_axes) {
        value_scale_ = scale;
        flipped_axes_ = flipped_axes;
    }
    /// A reader's note for the user (an oblique NIfTI placed as VTK does); empty when none.
    const std::string& warning() const { return warning_; }
    void set_warning(std::string w) { warning_ = std::move(w); }
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
    ValueScale value_scale_;
    uint8_t flipped_axes_ = 0;
    std::string warning_;
    bool swap_bytes_ = false;
    std::string source_;
    VolumeFormat format_ = VolumeFormat::raw;
};

}  // namespace octiso
