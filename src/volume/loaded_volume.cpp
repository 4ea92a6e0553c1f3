// LoadedVolume's constructor and the format names of reader.h. They live in the core library
// (not with the readers in src/io) because the synthetic generators of src/volume make
// LoadedVolumes too, and the core must link without VTK or OpenImageIO.
#include "octiso/loaded_volume.h"

namespace octiso {

LoadedVolume::LoadedVolume(std::shared_ptr<const void> owner, const std::byte* data, ScalarType type, Dims dims,
                           Placement placement, bool swap_bytes, std::string source, VolumeFormat format)
    : owner_(std::move(owner)), data_(data), type_(type), dims_(dims), placement_(placement),
      swap_bytes_(swap_bytes), source_(std::move(source)), format_(format) {}

std::string_view volume_format_name(VolumeFormat f) {
    switch (f) {
        case VolumeFormat::raw: return "raw";
        case VolumeFormat::nifti: return "NIfTI";
        case VolumeFormat::vti: return "VTK XML image data";
        case VolumeFormat::legacy_vtk: return "legacy VTK";
        case VolumeFormat::meta_image: return "MetaImage";
        case VolumeFormat::nrrd: return "NRRD";
        case VolumeFormat::synthetic: return "synthetic";
    }
    return "unknown";
}

}  // namespace octiso
