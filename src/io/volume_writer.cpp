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
#include <vtkMatrix4x4.h>
#include <vtkNIFTIImageWriter.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkType.h>
#include <vtkXMLImageDataWriter.h>

#include "io/volume_stream.h"
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

vtkSmartPointer<vtkImageData> image_over(ScalarType type, Dims dims, std::span<const std::byte> data);

void write_vti(const std::string& path, ScalarType type, Dims dims, const Placement& p, std::span<const std::byte> data) {
    vtkSmartPointer<vtkImageData> image = image_over(type, dims, data);
    image->SetSpacing(p.spacing[0], p.spacing[1], p.spacing[2]);
    image->SetOrigin(p.origin[0], p.origin[1], p.origin[2]);
    AtomicOutput out(path);
    vtkNew<vtkXMLImageDataWriter> writer;
    writer->SetFileName(out.temp_path().c_str());
    writer->SetInputData(image);
    writer->SetDataModeToAppended();
    writer->SetCompressorTypeToZLib();
    if (writer->Write() != 1 || writer->GetErrorCode() != 0) throw Error(path, "VTK's image writer failed", ErrorKind::Other);
    out.commit();
}

/// vtkImageData over `data` without a copy (the writers only read it).
vtkSmartPointer<vtkImageData> image_over(ScalarType type, Dims dims, std::span<const std::byte> data) {
    auto image = vtkSmartPointer<vtkImageData>::New();
    image->SetDimensions(int(dims.x), int(dims.y), int(dims.z));
    vtkSmartPointer<vtkDataArray> array = vtkSmartPointer<vtkDataArray>::Take(vtkDataArray::CreateDataArray(vtk_type_of(type)));
    array->SetNumberOfComponents(1);
    array->SetName("scalars");
    // save = 1: VTK never frees memory it does not own.
    array->SetVoidArray(const_cast<std::byte*>(data.data()), vtkIdType(dims.voxels()), 1);
    image->GetPointData()->SetScalars(array);
    return image;
}

/// NIfTI-1 through vtkNIFTIImageWriter, in the source file's order: voxel (i,j,k) of the file
/// sits at srow * (i,j,k,1) with srow = diag(+-spacing) and, on a reversed axis, the far end of
/// the tree's box as its translation, which is what the reader turned round (CONVENTIONS 2b).
void write_nifti(const std::string& path, ScalarType type, Dims dims, const Placement& p, std::span<const std::byte> data,
                 const ValueScale& scale, uint8_t flipped) {
    std::vector<std::byte> file_order;
    if (flipped) {
        file_order.assign(data.begin(), data.end());
        reverse_axes_in_place(file_order.data(), dims, dims.z, scalar_type_bytes(type), flipped);
        data = file_order;
    }
    vtkSmartPointer<vtkImageData> image = image_over(type, dims, data);
    // The writer scales the sform's columns by the spacing and keeps the image origin out of it.
    image->SetSpacing(p.spacing[0], p.spacing[1], p.spacing[2]);
    image->SetOrigin(0, 0, 0);
    const uint32_t n[3] = {dims.x, dims.y, dims.z};
    vtkNew<vtkMatrix4x4> sform;
    for (int a = 0; a < 3; ++a) {
        const bool reversed = flipped & (1u << a);
        sform->SetElement(a, a, reversed ? -1.0 : 1.0);
        sform->SetElement(a, 3, reversed ? p.origin[size_t(a)] + p.spacing[size_t(a)] * double(n[a] - 1) : p.origin[size_t(a)]);
    }
    AtomicOutput out(path);
    // VTK's writer picks gzip from the name it is given: keep the user's ending on the temporary.
    const std::string temp = out.temp_path() + (ends_with(path, ".gz") ? ".nii.gz" : ".nii");
    vtkNew<vtkNIFTIImageWriter> writer;
    writer->SetFileName(temp.c_str());
    writer->SetInputData(image);
    writer->SetSFormMatrix(sform);
    if (!flipped) {
        // A qform too (a rotation, so only without reversed axes): readers that prefer it agree.
        vtkNew<vtkMatrix4x4> qform;
        for (int a = 0; a < 3; ++a) qform->SetElement(a, 3, p.origin[size_t(a)]);
        writer->SetQFormMatrix(qform);
    }
    if (!scale.is_identity()) {
        writer->SetRescaleSlope(scale.slope);
        writer->SetRescaleIntercept(scale.inter);
    }
    writer->SetDescription("octiso-info --extract");
    writer->Write();
    const bool ok = writer->GetErrorCode() == 0;
    if (!ok || std::rename(temp.c_str(), out.temp_path().c_str()) != 0) {
        std::remove(temp.c_str());
        throw Error(path, "VTK's NIfTI writer failed", ErrorKind::Other);
    }
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
    return ends_with(path, ".vti") || ends_with(path, ".nrrd") || ends_with(path, ".raw") || ends_with(path, ".nii") ||
           ends_with(path, ".nii.gz");
}

void write_volume_file(const std::string& path, ScalarType type, Dims dims, const Placement& placement,
                       std::span<const std::byte> data, const ValueScale& scale, uint8_t flipped_axes) {
    if (data.size() != checked_volume_bytes(dims, type, path))
        throw Error(path, "the data is " + std::to_string(data.size()) + " bytes, the grid needs " +
                              std::to_string(checked_volume_bytes(dims, type, path)), ErrorKind::Other);
    if (ends_with(path, ".vti")) return write_vti(path, type, dims, placement, data);
    if (ends_with(path, ".nrrd")) return write_nrrd(path, type, dims, placement, data);
    if (ends_with(path, ".nii") || ends_with(path, ".nii.gz")) return write_nifti(path, type, dims, placement, data, scale, flipped_axes);
    if (ends_with(path, ".raw")) {
        if (!flipped_axes) return write_file_atomically(path, data.data(), data.size());
        std::vector<std::byte> file_order(data.begin(), data.end());
        reverse_axes_in_place(file_order.data(), dims, dims.z, scalar_type_bytes(type), flipped_axes);
        return write_file_atomically(path, file_order.data(), file_order.size());
    }
    throw Error(path, "no volume format for this extension (.vti, .nrrd, .nii, .nii.gz or .raw)");
}

}  // namespace octiso
