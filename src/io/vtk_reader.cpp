// read_vtk() and read_vtk_information(): NIfTI (on request), VTK XML image data, legacy VTK
// structured points, MetaImage and NRRD through VTK's own readers, which live in the volume codec
// module (volume_codec.h: loaded on the first such file, so that raw and NIfTI inputs, read by
// octiso itself, never load VTK). Here the file is checked before VTK sees it, and what the
// module reports becomes the Error naming the file. (open_volume() reads NIfTI with read_nifti()
// instead, nifti_stream.cpp: CONVENTIONS 2b's scaling and flips; NIfTI stays here for callers
// that ask for VTK's own reading.)
#include <string>

#include "io/header_check.h"
#include "io/input_file.h"
#include "io/volume_codec_loader.h"
#include "io/vtk_information.h"
#include "octiso/reader.h"

namespace octiso {
namespace {

void throw_failure(const std::string& path, const volume_codec::Failure& f) {
    if (f.failed()) throw Error(path, f.message, f.other ? ErrorKind::Other : ErrorKind::BadInput);
}

}  // namespace

LoadedVolume read_vtk(const std::string& path, VolumeFormat format, const std::optional<std::string>& array) {
    io::check_input_file(path);
    io::check_declared_size(path, format);   // before VTK: bad datatypes crash it, short data is zero-filled
    volume_codec::ReadVolume v;
    throw_failure(path, volume_codec::codec().read(path, format, array ? &*array : nullptr, v));
    return LoadedVolume(std::move(v.owner), v.data, v.type, v.dims, v.placement, false, path, format);
}

}  // namespace octiso

namespace octiso::io {

VtkImageInformation read_vtk_information(const std::string& path, VolumeFormat format) {
    io::check_input_file(path);
    io::check_declared_size(path, format);
    VtkImageInformation info;
    throw_failure(path, volume_codec::codec().read_information(path, format, info));
    return info;
}

}  // namespace octiso::io
