// The NIfTI VolumeStream (volume_stream.h): .nii and .nii.gz through zlib's gzread (which reads
// uncompressed files as they are), header checked and parsed (nifti_header.h), voxels from
// vox_offset on in the file's order, swapped when the file's byte order is not the host's.
// A 4-D file is a time series: its volumes follow each other in the one stream.
#include <algorithm>
#include <climits>
#include <cstring>

#include <zlib.h>

#include "io/nifti_header.h"
#include "io/volume_stream.h"

namespace octiso {

namespace {

class NiftiStream final : public VolumeStream {
public:
    NiftiStream(const std::string& path, const io::NiftiHeader& h, gzFile f)
        : VolumeStream(h.type, h.dims, h.placement, path, VolumeFormat::nifti), f_(f), swap_(h.swap) {
        set_time_steps(h.time_steps);
    }
    ~NiftiStream() override { ::gzclose(f_); }
    uint64_t file_bytes_read() const override { return uint64_t(::gzoffset(f_)); }

protected:
    void read_bytes(uint64_t bytes, std::byte* dst) override {
        uint64_t done = 0;
        while (done < bytes) {
            const unsigned chunk = unsigned(std::min<uint64_t>(bytes - done, uint64_t(1) << 30));
            const int n = ::gzread(f_, dst + done, chunk);
            if (n < 0) {
                int code = 0;
                const char* msg = ::gzerror(f_, &code);
                throw Error(source(), std::string("cannot decompress: ") + (msg ? msg : "zlib error"));
            }
            if (n == 0) throw Error(source(), "file ended early (fewer voxels than the header declares)");
            done += uint64_t(n);
        }
        if (swap_) swap_scalars_in_place(dst, bytes, scalar_type_bytes(type()));
    }

private:
    gzFile f_;
    bool swap_;
};

}  // namespace

std::unique_ptr<VolumeStream> open_nifti_stream(const std::string& path) {
    const io::NiftiHeader h = io::read_nifti_header(path);
    if (!h.unplaced.empty())
        throw Error(path, "NIfTI " + h.unplaced + ": not streamed yet (convert it without --memory: VTK reads it whole)");
    if (h.scales_values())
        throw Error(path, "NIfTI scl_slope " + std::to_string(h.scl_slope) + " / scl_inter " + std::to_string(h.scl_inter) +
                              " map stored values to real ones; value scaling is not implemented yet, so it is refused "
                              "rather than stored unscaled");
    gzFile f = ::gzopen(path.c_str(), "rb");
    if (!f) throw Error(path, "cannot open as NIfTI");
    ::gzbuffer(f, 1u << 20);
    if (::gzseek(f, z_off_t(h.vox_offset), SEEK_SET) < 0) {
        ::gzclose(f);
        throw Error(path, "cannot seek to vox_offset " + std::to_string(h.vox_offset));
    }
    return std::make_unique<NiftiStream>(path, h, f);
}

}  // namespace octiso
