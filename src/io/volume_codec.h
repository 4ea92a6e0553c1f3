// The volume codec: what octiso asks of VTK (reading VTK image data, legacy structured points,
// MetaImage, NRRD and, on request, NIfTI; writing .vti and NIfTI), behind a table of functions
// that lives in a module of its own (liboctiso_volumes.so, src/io/volume_codec_vtk.cpp) and is
// loaded the first time a file needs VTK (volume_codec_loader.h).
//
// Why a module: the common inputs, raw arrays and NIfTI, are read by octiso itself (raw_reader,
// nifti_stream), yet every process that linked the VTK readers (octiso-convert, octiso-info)
// loaded 19 VTK libraries at start-up and kept about 10 MiB of them resident:
// octiso-convert's floor was 19 MiB (BENCHMARKS, compression: the converter's peak RSS). Loaded on
// demand, only a process that opens or writes a VTK-only format pays, once.
//
// As for the image codec (image_codec.h): both sides are built by this project with the same
// compiler and standard library, so the table passes std::string and std::shared_ptr;
// kVolumeCodecAbi guards against a stale module. Failures come back as a message (the caller
// throws octiso::Error naming the file), not as an exception across the module boundary.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "io/vtk_information.h"
#include "octiso/loaded_volume.h"
#include "octiso/volume.h"

namespace octiso::volume_codec {

/// Bumped whenever VolumeCodec or a request changes.
inline constexpr int kVolumeCodecAbi = 1;
/// The module's file name (dlopen) and the one symbol it exports.
inline constexpr const char* kModuleFile = "liboctiso_volumes.so";
inline constexpr const char* kEntrySymbol = "octiso_volume_codec";

/// What went wrong: `message` for the user (the caller names the file); `other` marks a failure
/// of the library or the write rather than of the named input (ErrorKind::Other).
struct Failure {
    std::string message;
    bool other = false;
    bool failed() const { return !message.empty(); }
};

/// A volume VTK read: the voxels stay in VTK's array, which `owner` keeps alive (no copy).
struct ReadVolume {
    std::shared_ptr<const void> owner;
    const std::byte* data = nullptr;
    ScalarType type = ScalarType::u8;
    Dims dims{};
    Placement placement;
};

/// A volume to write: dims x scalar size bytes at `data`, x fastest, in the order the file
/// takes; the NIfTI writer's placement (sform, qform) is built from `placement` and the axes
/// reversed in `flipped_axes` (volume_writer.h).
struct WriteRequest {
    ScalarType type = ScalarType::u8;
    Dims dims{};
    Placement placement;
    std::span<const std::byte> data;
    ValueScale scale;
    uint8_t flipped_axes = 0;
};

struct VolumeCodec {
    int abi;
    /// The whole file through VTK's reader for `format`, checked (one complete single-component
    /// image of a stored type); `array` (may be null) names the point data array to take.
    Failure (*read)(const std::string& path, VolumeFormat format, const std::string* array, ReadVolume& out);
    /// What VTK's reader makes of the header alone (vtk_information.h).
    Failure (*read_information)(const std::string& path, VolumeFormat format, io::VtkImageInformation& out);
    /// VTK's XML image data writer (appended, zlib) into `file`, a temporary the caller renames.
    Failure (*write_vti)(const std::string& file, const WriteRequest& request);
    /// VTK's NIfTI-1 writer into `file` (gzip where it ends in .gz), a temporary the caller renames.
    Failure (*write_nifti)(const std::string& file, const WriteRequest& request);
};

}  // namespace octiso::volume_codec

/// The module's entry: its codec table (static storage).
extern "C" const octiso::volume_codec::VolumeCodec* octiso_volume_codec();
