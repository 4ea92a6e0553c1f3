// The NIfTI VolumeStream (volume_stream.h) and read_nifti(): .nii and .nii.gz through zlib's
// gzread (which reads uncompressed files as they are), header checked and parsed (nifti_header.h),
// voxels from vox_offset on, swapped when the file's byte order is not the host's, and the axes
// the affine reverses turned round as they are read so that the tree's spacing is positive
// (CONVENTIONS 2b). A 4-D file is a time series: its volumes follow each other in the one stream.
#include <algorithm>
#include <climits>
#include <cstring>
#include <vector>

#include <zlib.h>

#include "io/nifti_header.h"
#include "io/volume_stream.h"

namespace octiso {

namespace {

class NiftiStream final : public VolumeStream {
public:
    NiftiStream(const std::string& path, const io::NiftiHeader& h, gzFile f)
        : VolumeStream(h.type, h.dims, h.placement, path, VolumeFormat::nifti), f_(f), swap_(h.swap),
          flipped_(h.flipped_axes) {
        set_time_steps(h.time_steps);
        set_source_order(h.value_scale, h.flipped_axes, h.warning);
    }
    ~NiftiStream() override { ::gzclose(f_); }
    uint64_t file_bytes_read() const override { return uint64_t(::gzoffset(f_)); }

protected:
    void read_bytes(uint64_t n_bytes, std::byte* dst) override {
        const uint64_t layer = layer_bytes();
        const uint32_t first = next_layer(), n_layers = uint32_t(n_bytes / layer);
        if (flipped_ & 4) {
            // z reversed: the file's last layer comes first, so the whole volume is read into
            // memory at its first layer and handed out from the end (one volume, not the file).
            if (first == 0) {
                try {
                    volume_.resize(size_t(bytes()));
                } catch (const std::bad_alloc&) {
                    throw Error(source(), "out of memory holding one volume (" + std::to_string(bytes()) +
                                              " bytes) to reverse its z axis");
                }
                read_file(bytes(), volume_.data());
            }
            for (uint32_t k = 0; k < n_layers; ++k)
                std::memcpy(dst + k * layer, volume_.data() + (dims().z - 1 - (first + k)) * layer, size_t(layer));
            if (first + n_layers == dims().z) std::vector<std::byte>().swap(volume_);
        } else {
            read_file(n_bytes, dst);
        }
        if (flipped_ & 3) reverse_axes_in_place(dst, dims(), n_layers, scalar_type_bytes(type()), uint8_t(flipped_ & 3));
    }

private:
    /// The next `n_bytes` voxel bytes of the file, in native byte order.
    void read_file(uint64_t n_bytes, std::byte* dst) {
        uint64_t done = 0;
        while (done < n_bytes) {
            const unsigned chunk = unsigned(std::min<uint64_t>(n_bytes - done, uint64_t(1) << 30));
            const int n = ::gzread(f_, dst + done, chunk);
            if (n < 0) {
                int code = 0;
                const char* msg = ::gzerror(f_, &code);
                throw Error(source(), std::string("cannot decompress: ") + (msg ? msg : "zlib error"));
            }
            if (n == 0) throw Error(source(), "file ended early (fewer voxels than the header declares)");
            done += uint64_t(n);
        }
        if (swap_) swap_scalars_in_place(dst, n_bytes, scalar_type_bytes(type()));
    }

    gzFile f_;
    bool swap_;
    uint8_t flipped_;
    std::vector<std::byte> volume_;   // the current volume, only while a reversed z is handed out
};

}  // namespace

std::unique_ptr<VolumeStream> open_nifti_stream(const std::string& path) {
    const io::NiftiHeader h = io::read_nifti_header(path);
    gzFile f = ::gzopen(path.c_str(), "rb");
    if (!f) throw Error(path, "cannot open as NIfTI");
    ::gzbuffer(f, 1u << 20);
    if (::gzseek(f, z_off_t(h.vox_offset), SEEK_SET) < 0) {
        ::gzclose(f);
        throw Error(path, "cannot seek to vox_offset " + std::to_string(h.vox_offset));
    }
    return std::make_unique<NiftiStream>(path, h, f);
}

LoadedVolume read_nifti(const std::string& path) {
    std::unique_ptr<VolumeStream> s = open_nifti_stream(path);
    if (s->time_steps() > 1)
        throw Error(path, "is a 4-D NIfTI of " + std::to_string(s->time_steps()) +
                              " volumes: octiso-convert makes it a time series, one step per volume");
    return read_stream_whole(*s);
}

}  // namespace octiso
