// write_volume_file (include/octiso/volume_writer.h): .vti and NIfTI through VTK's writers in the
// volume codec module (volume_codec.h, loaded on the first such file), .nrrd with a
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

#include "io/volume_codec_loader.h"
#include "io/volume_stream.h"
#include "octiso/error.h"
#include "util/atomic_output.h"

namespace octiso {

namespace {

bool ends_with(std::string_view s, std::string_view tail) { return s.size() >= tail.size() && s.substr(s.size() - tail.size()) == tail; }

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
    const volume_codec::VolumeCodec& codec = volume_codec::codec();   // before the temporary: a missing module leaves nothing
    AtomicOutput out(path);
    const volume_codec::Failure f = codec.write_vti(out.temp_path(), {type, dims, p, data, {}, 0});
    if (f.failed()) throw Error(path, f.message, ErrorKind::Other);
    out.commit();
}

/// NIfTI-1 in the source file's order: the voxels with the flipped axes turned back, the placement
/// as the module's writer builds it from them (volume_codec_vtk.cpp).
void write_nifti(const std::string& path, ScalarType type, Dims dims, const Placement& p, std::span<const std::byte> data,
                 const ValueScale& scale, uint8_t flipped) {
    const volume_codec::VolumeCodec& codec = volume_codec::codec();
    std::vector<std::byte> file_order;
    if (flipped) {
        file_order.assign(data.begin(), data.end());
        reverse_axes_in_place(file_order.data(), dims, dims.z, scalar_type_bytes(type), flipped);
        data = file_order;
    }
    AtomicOutput out(path);
    // VTK's writer picks gzip from the name it is given: keep the user's ending on the temporary.
    const std::string temp = out.temp_path() + (ends_with(path, ".gz") ? ".nii.gz" : ".nii");
    const volume_codec::Failure f = codec.write_nifti(temp, {type, dims, p, data, scale, flipped});
    if (f.failed() || std::rename(temp.c_str(), out.temp_path().c_str()) != 0) {
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
