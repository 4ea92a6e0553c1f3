// read_raw(): a headerless array of NX*NY*NZ scalars after an optional byte offset, mapped
// read-only with mmap so a volume larger than memory costs address space, not RAM. Every size is
// validated against the file before the mapping is trusted; big-endian data is swapped on load
// by VolumeView, never copied.
#include <bit>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/input_file.h"
#include "util/mapping_guard.h"
#include "octiso/reader.h"

namespace octiso {

namespace {

// Closes a descriptor on every exit path; the mapping outlives it.
struct FdCloser {
    int fd;
    ~FdCloser() { if (fd >= 0) ::close(fd); }
};

std::string dims_text(Dims d) {
    return std::to_string(d.x) + "," + std::to_string(d.y) + "," + std::to_string(d.z);
}

}  // namespace

LoadedVolume read_raw(const std::string& path, Dims dims, ScalarType type, Endian endian, uint64_t offset) {
    // 1. The grid itself, before the file: zero or oversized extents, then a 64-bit byte count.
    if (dims.x == 0 || dims.y == 0 || dims.z == 0)
        throw Error(path, "dims " + dims_text(dims) + " have a zero extent");
    if (dims.max_extent() > Dims::kMaxExtent)
        throw Error(path, "dims " + dims_text(dims) + " exceed the largest extent " + std::to_string(Dims::kMaxExtent));
    const uint64_t bytes = checked_volume_bytes(dims, type, path);

    // 2. The file: exists, regular, readable, non-empty, and exactly offset + bytes long.
    io::check_input_file(path);
    // O_NONBLOCK, then fstat: the path may have been swapped for a FIFO since the check above.
    const FdCloser fd{::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK)};
    if (fd.fd < 0) throw Error(path, std::string("cannot open: ") + std::strerror(errno));
    struct stat st {};
    if (::fstat(fd.fd, &st) != 0) throw Error(path, std::string("cannot stat: ") + std::strerror(errno));
    if (!S_ISREG(st.st_mode)) throw Error(path, "is not a regular file");
    const uint64_t file_bytes = uint64_t(st.st_size);
    if (file_bytes == 0) throw Error(path, "empty file");
    if (offset > file_bytes)
        throw Error(path, "offset " + std::to_string(offset) + " lies past the end of the file (" +
                              std::to_string(file_bytes) + " bytes)");
    if (file_bytes - offset != bytes)
        throw Error(path, "size does not match " + dims_text(dims) + " " + std::string(scalar_type_name(type)) +
                              " (expected " + std::to_string(bytes) + " bytes after offset " + std::to_string(offset) +
                              ", found " + std::to_string(file_bytes - offset) + ")");

    // 3. Map the whole file (mmap offsets must be page aligned; --offset need not be).
    //    The mapping is guarded like a .oct file's (util/mapping_guard.h): a shared flock, and a
    //    clean one-line exit if the file is truncated or rewritten while it is being read.
    io::lock_shared_or_refuse(fd.fd, path);
    void* base = ::mmap(nullptr, size_t(file_bytes), PROT_READ, MAP_PRIVATE, fd.fd, 0);
    if (base == MAP_FAILED) {
        if (errno == ENOMEM)   // the declared grid does not fit the address space allowed (ulimit -v)
            throw Error(path, "out of memory mapping " + std::to_string(file_bytes) + " bytes (" + dims_text(dims) + " " +
                                  std::string(scalar_type_name(type)) + ")");
        throw Error(path, std::string("cannot map: ") + std::strerror(errno), ErrorKind::Other);
    }
    const int kept_fd = ::fcntl(fd.fd, F_DUPFD_CLOEXEC, 0);   // the flock belongs to the open file, shared by the dup
    const int slot = kept_fd >= 0 ? io::register_mapping(base, file_bytes, kept_fd, path) : -1;
    std::shared_ptr<const void> owner(base, [file_bytes, kept_fd, slot](const void* p) {
        io::unregister_mapping(slot);
        ::munmap(const_cast<void*>(p), size_t(file_bytes));
        if (kept_fd >= 0) ::close(kept_fd);
    });

    const bool native_little = std::endian::native == std::endian::little;
    const bool swap = scalar_type_bytes(type) > 1 && (endian == Endian::little) != native_little;
    const auto* data = static_cast<const std::byte*>(base) + offset;
    return LoadedVolume(std::move(owner), data, type, dims, Placement{}, swap, path, VolumeFormat::raw);
}

}  // namespace octiso
