// VolumeStream: a volume read front to back, a few layers (z slices) at a time, for the
// out-of-core converter (issue 13). Unlike LoadedVolume nothing is mapped or kept: each call
// reads the next layers with ordinary reads into the caller's buffer, in native byte order.
// The readers behind it: raw_stream.cpp, nifti_stream.cpp, text_stream.cpp; open_volume_stream()
// picks one.
#pragma once

#include <cstddef>
#include <cstdint>
#include <algorithm>
#include <cstring>
#include <memory>
#include <optional>
#include <string>

#include "octiso/loaded_volume.h"
#include "octiso/reader.h"
#include "octiso/volume.h"

namespace octiso {

/// Invariants: dims() passed checked_volume_bytes; next_layer() <= dims().z counts the layers
/// handed out so far. Not thread-safe (one reader, one cursor).
class VolumeStream {
public:
    VolumeStream(ScalarType type, Dims dims, Placement placement, std::string source, VolumeFormat format)
        : type_(type), dims_(dims), placement_(placement), source_(std::move(source)), format_(format) {}
    virtual ~VolumeStream() = default;
    VolumeStream(const VolumeStream&) = delete;
    VolumeStream& operator=(const VolumeStream&) = delete;

    ScalarType type() const { return type_; }
    Dims dims() const { return dims_; }
    const Placement& placement() const { return placement_; }
    void set_placement(const Placement& p) { placement_ = p; }
    /// As LoadedVolume's: stored-to-real values, source axes reversed as read, a reader's note.
    const ValueScale& value_scale() const { return value_scale_; }
    uint8_t flipped_axes() const { return flipped_axes_; }
    const std::string& warning() const { return warning_; }
    const std::string& source() const { return source_; }
    VolumeFormat format() const { return format_; }
    uint64_t layer_bytes() const { return uint64_t(dims_.x) * dims_.y * scalar_type_bytes(type_); }
    uint64_t bytes() const { return layer_bytes() * dims_.z; }   ///< dense voxel bytes of the step
    uint32_t next_layer() const { return next_layer_; }
    /// Volumes in the file, read one after the other (a 4-D NIfTI); 1 for most formats.
    uint32_t time_steps() const { return time_steps_; }
    /// After every layer of one volume was read: the cursor moves to layer 0 of the next.
    void start_next_step() {
        if (next_layer_ != dims_.z || step_ + 1 >= time_steps_)
            throw Error(source_, "no next time step to read", ErrorKind::Other);
        next_layer_ = 0;
        ++step_;
    }
    /// Bytes taken from the file so far (compressed bytes for gzip input).
    virtual uint64_t file_bytes_read() const = 0;

    /// Reads layers next_layer() .. next_layer()+n-1 (x fastest, native byte order) into `dst`,
    /// which holds n * layer_bytes() bytes. Throws Error(source(), ...) past the last layer or
    /// when the file ends early or cannot be read.
    void read_layers(uint32_t n, std::byte* dst) {
        if (n > dims_.z - next_layer_)
            throw Error(source_, "read past the last layer (" + std::to_string(next_layer_) + " + " + std::to_string(n) +
                                     " > " + std::to_string(dims_.z) + ")", ErrorKind::Other);
        read_bytes(uint64_t(n) * layer_bytes(), dst);
        next_layer_ += n;
    }

protected:
    void set_time_steps(uint32_t n) { time_steps_ = n; }
    void set_source_order(const ValueScale& scale, uint8_t flipped, std::string warning) {
        value_scale_ = scale;
        flipped_axes_ = flipped;
        warning_ = std::move(warning);
    }
    /// The next `bytes` voxel bytes of the file in native byte order.
    virtual void read_bytes(uint64_t bytes, std::byte* dst) = 0;

private:
    ScalarType type_;
    Dims dims_;
    Placement placement_;
    ValueScale value_scale_;
    uint8_t flipped_axes_ = 0;
    std::string warning_;
    std::string source_;
    VolumeFormat format_;
    uint32_t next_layer_ = 0;
    uint32_t time_steps_ = 1, step_ = 0;
};

/// A raw array (CONVENTIONS 3) checked like read_raw() (dims, then exactly offset + voxel bytes),
/// read with pread in slabs; big-endian data is swapped as it is read.
std::unique_ptr<VolumeStream> open_raw_stream(const std::string& path, Dims dims, ScalarType type, Endian endian,
                                              uint64_t offset);

/// NIfTI-1/-2, .nii or .nii.gz (nifti_stream.cpp): header checked and parsed, placed as nibabel
/// reads it (CONVENTIONS 2b): axes with a negative affine entry are reversed as they are read
/// (a reversed z holds one volume in memory), scl_slope/scl_inter become value_scale(), an
/// oblique affine is placed as VTK does and named in warning().
std::unique_ptr<VolumeStream> open_nifti_stream(const std::string& path);

/// NRRD (.nrrd, .nhdr) or MetaImage (.mha, .mhd) with raw or gzip/zlib data (or NRRD ascii) in
/// one file (text_stream.cpp): the header's layout (text_layout.h) read with pread, inflated or
/// parsed as read,
/// swapped when big-endian, placed as VTK places it. Throws Error(path, ...) when
/// text_stream_refusal() gives a reason.
std::unique_ptr<VolumeStream> open_text_stream(const std::string& path, VolumeFormat format);
/// open_text_stream(), or null where text_stream_refusal() would give a reason (the header is
/// planned once, for open_volume()'s choice between the stream and VTK).
std::unique_ptr<VolumeStream> try_open_text_stream(const std::string& path, VolumeFormat format);
/// Why a NRRD or MetaImage file cannot be streamed (its layout is one the stream does not read,
/// or VTK reads its grid or type differently from the header's plain meaning); nullopt if it can.
std::optional<std::string> text_stream_refusal(const std::string& path, VolumeFormat format);

/// Reads exactly `bytes` at `pos` of `fd`, retrying short reads; Error(source, ...) if the file
/// ends first (it changed since its size was checked) or a read fails.
void pread_fully(int fd, std::byte* dst, uint64_t bytes, uint64_t pos, const std::string& source);

/// The whole of a 3-D NIfTI file through open_nifti_stream() into memory: the in-memory
/// converter's reader, so both paths read NIfTI with the same code. Throws Error(path, ...) for
/// a 4-D file (convert() makes those a series through the stream).
LoadedVolume read_nifti(const std::string& path);

/// Every layer of the stream's current volume (nothing read from it yet) into memory, as a
/// LoadedVolume with the stream's placement, value scale, flips and warning: the in-memory
/// converter's reader for the formats it streams, so that both paths read them with the same
/// code. Error(source, ...) when the voxels do not fit in memory.
LoadedVolume read_stream_whole(VolumeStream& stream);

/// Whether open_volume_stream() can stream `path` (raw, NIfTI, and NRRD or MetaImage that
/// text_stream_refusal() accepts); other input is read whole by open_volume().
bool is_streamable(const std::string& path, const RawOptions& options);

/// The streaming counterpart of open_volume(): the same format choice, flag checks, placement
/// overrides and placement check. Throws Error naming the file or flag; also when the format
/// cannot be streamed (check is_streamable first).
std::unique_ptr<VolumeStream> open_volume_stream(const std::string& path, const RawOptions& options);

/// Reverses the bytes of each of the `bytes / scalar_bytes` scalars at p, in place: a slab read
/// from a file of the other byte order, before it is handed out (both stream readers).
inline void swap_scalars_in_place(std::byte* p, uint64_t bytes, size_t scalar_bytes) {
    auto swap_all = [&](auto tag) {
        using U = decltype(tag);
        for (uint64_t i = 0; i < bytes / sizeof(U); ++i) {
            U u;
            std::memcpy(&u, p + i * sizeof(U), sizeof(U));
            u = VolumeView<U>::byte_swapped(u);
            std::memcpy(p + i * sizeof(U), &u, sizeof(U));
        }
    };
    if (scalar_bytes == 2) swap_all(uint16_t{});
    else if (scalar_bytes == 4) swap_all(uint32_t{});
    else if (scalar_bytes == 8) swap_all(uint64_t{});
}

/// Reverses the axes in `mask` (bit a: axis a = x, y, z) of `layers` x-fastest layers of a
/// `dims` grid (dims.z is ignored: z is reversed over the `layers` given), in place. The NIfTI
/// reader turns reversed file axes round with it, the writers give the file's order back.
inline void reverse_axes_in_place(std::byte* p, Dims dims, uint32_t layers, size_t scalar_bytes, uint8_t mask) {
    const size_t row = size_t(dims.x) * scalar_bytes, layer = row * dims.y;
    if (mask & 4)
        for (uint32_t k = 0; k < layers / 2; ++k) std::swap_ranges(p + k * layer, p + (k + 1) * layer, p + (layers - 1 - k) * layer);
    std::byte tmp[8];
    for (uint32_t k = 0; k < layers && (mask & 3); ++k) {
        std::byte* l = p + k * layer;
        if (mask & 2)
            for (uint32_t j = 0; j < dims.y / 2; ++j) std::swap_ranges(l + j * row, l + (j + 1) * row, l + (dims.y - 1 - j) * row);
        if (mask & 1)
            for (uint32_t j = 0; j < dims.y; ++j)
                for (uint32_t i = 0; i < dims.x / 2; ++i) {
                    std::byte* a = l + j * row + i * scalar_bytes;
                    std::byte* b = l + j * row + (dims.x - 1 - i) * scalar_bytes;
                    std::memcpy(tmp, a, scalar_bytes);
                    std::memcpy(a, b, scalar_bytes);
                    std::memcpy(b, tmp, scalar_bytes);
                }
    }
}

}  // namespace octiso
