// What VTK's reader makes of a header without reading the voxels (vtkAlgorithm::UpdateInformation):
// the streaming NRRD and MetaImage reader takes its placement from here, so that it places a
// volume exactly as the in-memory path (read_vtk) does, and checks its own parse of grid and
// type against VTK's.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "octiso/loaded_volume.h"
#include "octiso/volume.h"

namespace octiso::io {

struct VtkImageInformation {
    std::array<uint64_t, 3> extent{};      ///< points per axis of the whole extent
    std::optional<ScalarType> type;        ///< nullopt: a type octiso does not store
    int components = 1;
    Placement placement;                   ///< as read_vtk() would report it
};

/// Throws Error(path, ...) where VTK reports an error reading the header.
VtkImageInformation read_vtk_information(const std::string& path, VolumeFormat format);

}  // namespace octiso::io
