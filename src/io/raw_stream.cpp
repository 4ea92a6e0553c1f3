// The raw VolumeStream (volume_stream.h): the checks of read_raw() on the grid and the file,
// then plain pread() calls at the cursor, so that a file larger than memory costs one slab of
// RAM and never a mapping. Big-endian scalars are swapped in the caller's buffer after each read.
#include <bit>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/input_file.h"
#include "io/volume_stream.h"
#include "util/mapping_guard.h"

namespace octiso {

namespace {

std::string dims_text(Dims d) { return std::to_string(d.x) + "," + std::to_string(d.y) + "," + std::to_string(d.z); }

class RawStream final : public VolumeStream {
public:
    RawStream(const std::string& path, Dims dims, ScalarType type, int fd, uint64_t offset, bool swap)
        : VolumeStream(type, dims, Placement{}, path, VolumeFormat::raw), fd_(fd), pos_(offset), swap_(swap) {}
    ~RawStream() override { ::close(fd_); }
    uint64_t file_bytes_read() const override { return read_; }

protected:
    void read_bytes(uint64_t bytes, std::byte* dst) override {
        pread_fully(fd_, dst, bytes, pos_, source());
        pos_ += bytes;
        read_ += bytes;
        if (swap_) swap_scalars_in_place(dst, bytes, scalar_type_bytes(type()));
    }

private:
    int fd_;
    uint64_t pos_;
    uint64_t read_ = 0;
    bool swap_;
};

}  // namespace

void pread_fully(int fd, std::byte* dst, uint64_t bytes, uint64_t pos, const std::string& source) {
    uint64_t done = 0;
    while (done < bytes) {
        const size_t chunk = size_t(std::min<uint64_t>(bytes - done, uint64_t(1) << 30));
        const ssize_t n = ::pread(fd, dst + done, chunk, off_t(pos + done));
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) throw Error(source, std::string("read failed: ") + std::strerror(errno));
        if (n == 0) throw Error(source, "file ended early (it changed while being read)");
        done += uint64_t(n);
    }
}

std::unique_ptr<VolumeStream> open_raw_stream(const std::string& path, Dims dims, ScalarType type, Endian endian,
                                              uint64_t offset) {
    // 1. The grid, then its byte count, exactly as read_raw() checks them.
    if (dims.x == 0 || dims.y == 0 || dims.z == 0) throw Error(path, "dims " + dims_text(dims) + " have a zero extent");
    if (dims.max_extent() > Dims::kMaxExtent)
        throw Error(path, "dims " + dims_text(dims) + " exceed the largest extent " + std::to_string(Dims::kMaxExtent));
    const uint64_t bytes = checked_volume_bytes(dims, type, path);

    // 2. The file: regular, readable, exactly offset + bytes long.
    io::check_input_file(path);
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) throw Error(path, std::string("cannot open: ") + std::strerror(errno));
    struct stat st {};
    const auto fail = [fd](const std::string& p, const std::string& what) {
        ::close(fd);
        throw Error(p, what);
    };
    if (::fstat(fd, &st) != 0) fail(path, std::string("cannot stat: ") + std::strerror(errno));
    if (!S_ISREG(st.st_mode)) fail(path, "is not a regular file");
    const uint64_t file_bytes = uint64_t(st.st_size);
    if (file_bytes == 0) fail(path, "empty file");
    if (offset > file_bytes)
        fail(path, "offset " + std::to_string(offset) + " lies past the end of the file (" + std::to_string(file_bytes) +
                       " bytes)");
    if (file_bytes - offset != bytes)
        fail(path, "size does not match " + dims_text(dims) + " " + std::string(scalar_type_name(type)) + " (expected " +
                       std::to_string(bytes) + " bytes after offset " + std::to_string(offset) + ", found " +
                       std::to_string(file_bytes - offset) + ")");
    try {
        io::lock_shared_or_refuse(fd, path);   // the same policy as mapped inputs (mapping_guard.h)
    } catch (...) {
        ::close(fd);
        throw;
    }
    const bool swap = scalar_type_bytes(type) > 1 && (endian == Endian::little) != (std::endian::native == std::endian::little);
    return std::make_unique<RawStream>(path, dims, type, fd, offset, swap);
}

}  // namespace octiso
