// SpillFile (spill_file.h). The temporary is unlinked by AtomicOutput's destructor (or its signal
// handler); the descriptor is closed first so that nothing holds the space afterwards.
#include "convert/spill_file.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <unistd.h>

#include "octiso/error.h"

namespace octiso::convert_detail {

SpillFile::SpillFile(std::string name, SpillAllowance& allowance) : name_(std::move(name)), allowance_(allowance) {}

SpillFile::~SpillFile() {
    if (fd_ >= 0) ::close(fd_);
    allowance_.bytes_left += charged_;
}

void SpillFile::move_to_disk() {
    temp_ = std::make_unique<AtomicOutput>(name_);
    fd_ = ::open(temp_->temp_path().c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    if (fd_ < 0)
        throw Error(temp_->temp_path(), std::string("cannot create a temporary: ") + std::strerror(errno), ErrorKind::Other);
    if (!io::write_all(fd_, memory_.data(), memory_.size()))
        throw Error(temp_->temp_path(), std::string("write failed: ") + std::strerror(errno), ErrorKind::Other);
    allowance_.bytes_left += charged_;
    charged_ = 0;
    std::vector<std::byte>().swap(memory_);
    on_disk_ = true;
}

uint64_t SpillFile::append(const void* data, uint64_t n) {
    const uint64_t at = size_;
    if (!on_disk_ && n > allowance_.bytes_left) move_to_disk();
    if (on_disk_) {
        if (!io::write_all(fd_, data, n))
            throw Error(temp_->temp_path(), std::string("write failed: ") + std::strerror(errno), ErrorKind::Other);
    } else {
        const auto* p = static_cast<const std::byte*>(data);
        const size_t before = memory_.capacity();
        memory_.insert(memory_.end(), p, p + n);
        // The allowance pays for the capacity actually held, growth slack included.
        const uint64_t grown = std::min<uint64_t>(memory_.capacity() - before, allowance_.bytes_left);
        allowance_.bytes_left -= grown;
        charged_ += grown;
    }
    size_ += n;
    return at;
}

void SpillFile::read(uint64_t offset, uint64_t n, void* dst) const {
    if (offset > size_ || n > size_ - offset)
        throw Error(name_, "spill read past its end", ErrorKind::Other);
    if (!on_disk_) {
        std::memcpy(dst, memory_.data() + offset, size_t(n));
        return;
    }
    auto* p = static_cast<char*>(dst);
    uint64_t done = 0;
    while (done < n) {
        const ssize_t r = ::pread(fd_, p + done, size_t(std::min<uint64_t>(n - done, uint64_t(1) << 30)), off_t(offset + done));
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) throw Error(temp_->temp_path(), std::string("read failed: ") + (r < 0 ? std::strerror(errno) : "short file"),
                                ErrorKind::Other);
        done += uint64_t(r);
    }
}

void SpillFile::clear() {
    if (fd_ >= 0) {
        if (::ftruncate(fd_, 0) != 0)
            throw Error(temp_->temp_path(), std::string("truncate failed: ") + std::strerror(errno), ErrorKind::Other);
        if (::lseek(fd_, 0, SEEK_SET) < 0)
            throw Error(temp_->temp_path(), std::string("seek failed: ") + std::strerror(errno), ErrorKind::Other);
    }
    allowance_.bytes_left += charged_;
    charged_ = 0;
    std::vector<std::byte>().swap(memory_);
    size_ = 0;
}

}  // namespace octiso::convert_detail
