// VolumeStream: a volume read front to back, a few layers (z slices) at a time, for the
// out-of-core converter (issue 13). Unlike LoadedVolume nothing is mapped or kept: each call
// reads the next layers with ordinary reads into the caller's buffer, in native byte order.
// The readers behind it: raw_stream.cpp, nifti_stream.cpp; open_volume_stream() picks one.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
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
    /// The next `bytes` voxel bytes of the file in native byte order.
    virtual void read_bytes(uint64_t bytes, std::byte* dst) = 0;

private:
    ScalarType type_;
    Dims dims_;
    Placement placement_;
    std::string source_;
    VolumeFormat format_;
    uint32_t next_layer_ = 0;
    uint32_t time_steps_ = 1, step_ = 0;
};

/// A raw array (CONVENTIONS 3) checked like read_raw() (dims, then exactly offset + voxel bytes),
/// read with pread in slabs; big-endian data is swapped as it is read.
std::unique_ptr<VolumeStream> open_raw_stream(const std::string& path, Dims dims, ScalarType type, Endian endian,
                                              uint64_t offset);

/// NIfTI-1/-2, .nii or .nii.gz (nifti_stream.cpp): header checked and parsed, placement from an
/// axis-aligned sform/qform (CONVENTIONS 2b). Refused with a message for now: a flipped or oblique
/// affine, and scl_slope/scl_inter that change values.
std::unique_ptr<VolumeStream> open_nifti_stream(const std::string& path);

/// Whether open_volume_stream() can stream `path` (raw and NIfTI input); other formats are read
/// whole by open_volume().
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

}  // namespace octiso
