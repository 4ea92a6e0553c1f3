// write_volume_file (include/octiso/volume_writer.h): .vti through VTK's XML writer, .nrrd with a
// header written here (the format is a few text lines; "kinds: domain" on every axis, which teem
// and 3D Slicer honour; VTK's own NRRD reader still takes a first axis of 9 or fewer samples for
// components, so such a grid reads back through VTK only as .vti), .raw as the bytes. Every file goes through
// AtomicOutput, so a failed write leaves nothing under the name.
#include "octiso/volume_writer.h"

#include <bit>
#include <cstdio>
#include <cstring>
#include <string_view>
#include <vector>

#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkType.h>
#include <vtkXMLImageDataWriter.h>

#include "octiso/error.h"
#include "util/atomic_output.h"

namespace octiso {

namespace {

bool ends_with(std::string_view s, std::string_view tail) { return s.size() >= tail.size() && s.substr(s.size() - tail.size()) == tail; }

int vtk_type_of(ScalarType t) {
    switch (t) {
        case ScalarType::u8: return VTK_UNSIGNED_CHAR;
        case ScalarType::i8: return VTK_SIGNED_CHAR;
        case ScalarType::u16: return VTK_UNSIGNED_SHORT;
        case ScalarType::i16: return VTK_SHORT;
        case ScalarType::u32: return VTK_UNSIGNED_INT;
        case ScalarType::i32: return VTK_INT;
        case ScalarType::f32: return VTK_FLOAT;
        case ScalarType::f64: break;
    }
    return VTK_DOUBLE;
}

const char* nrrd_type_of(ScalarType t) {
    switch (t) {
        case ScalarType::u8: return "uint8";
        case ScalarType::i8: return "int8";
        case ScalarType::u16: return "uint16";
        case ScalarType::i16: return "int16";
        case ScalarType::u32: return "uint32";
        case ScalarType::i32: return "int32";
        case ScalarType::f32: return "float";
        case ScalarType::f64: break;
    }
    return "double";
}

std::string g17(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

void write_vti(const std::string& path, ScalarType type, Dims dims, const Placement& p, std::span<const std::byte> data) {
    vtkNew<vtkImageData> image;
    image->SetDimensions(int(dims.x), int(dims.y), int(dims.z));
    image->SetSpacing(p.spacing[0], p.spacing[1], p.spacing[2]);
    image->SetOrigin(p.origin[0], p.origin[1], p.origin[2]);
    vtkSmartPointer<vtkDataArray> array = vtkSmartPointer<vtkDataArray>::Take(vtkDataArray::CreateDataArray(vtk_type_of(type)));
    array->SetNumberOfComponents(1);
    array->SetName("scalars");
    // The writer only reads the array; save = 1: VTK never frees memory it does not own.
    array->SetVoidArray(const_cast<std::byte*>(data.data()), vtkIdType(dims.voxels()), 1);
    image->GetPointData()->SetScalars(array);
    AtomicOutput out(path);
    vtkNew<vtkXMLImageDataWriter> writer;
    writer->SetFileName(out.temp_path().c_str());
    writer->SetInputData(image);
    writer->SetDataModeToAppended();
    writer->SetCompressorTypeToZLib();
    if (writer->Write() != 1 || writer->GetErrorCode() != 0) throw Error(path, "VTK's image writer failed", ErrorKind::Other);
    out.commit();
}

void write_nrrd(const std::string& path, ScalarType type, Dims dims, const Placement& p, std::span<const std::byte> data) {
    std::string header = "NRRD0004\n# octiso-info --extract\ntype: " + std::string(nrrd_type_of(type)) +
                         "\ndimension: 3\nspace: 3D-right-handed\nkinds: domain domain domain\nsizes: " + std::to_string(dims.x) + " " + std::to_string(dims.y) + " " +
                         std::to_string(dims.z) + "\nspace directions: (" + g17(p.spacing[0]) + ",0,0) (0," + g17(p.spacing[1]) +
                         ",0) (0,0," + g17(p.spacing[2]) + ")\nspace origin: (" + g17(p.origin[0]) + "," + g17(p.origin[1]) + "," +
                         g17(p.origin[2]) + ")\nendian: " + (std::endian::native == std::endian::little ? "little" : "big") +
                         "\nencoding: raw\n\n";
    std::vector<std::byte> bytes(header.size() + data.size());
    std::memcpy(bytes.data(), header.data(), header.size());
    std::memcpy(bytes.data() + header.size(), data.data(), data.size());
    write_file_atomically(path, bytes.data(), bytes.size());
}

}  // namespace

bool is_volume_file_format(const std::string& path) {
    return ends_with(path, ".vti") || ends_with(path, ".nrrd") || ends_with(path, ".raw");
}

void write_volume_file(const std::string& path, ScalarType type, Dims dims, const Placement& placement,
                       std::span<const std::byte> data) {
    if (data.size() != checked_volume_bytes(dims, type, path))
        throw Error(path, "the data is " + std::to_string(data.size()) + " bytes, the grid needs " +
                              std::to_string(checked_volume_bytes(dims, type, path)), ErrorKind::Other);
    if (ends_with(path, ".vti")) return write_vti(path, type, dims, placement, data);
    if (ends_with(path, ".nrrd")) return write_nrrd(path, type, dims, placement, data);
    if (ends_with(path, ".raw")) return write_file_atomically(path, data.data(), data.size());
    throw Error(path, "no volume format for this extension (.vti, .nrrd or .raw)");
}

}  // namespace octiso
