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
    release_memory();
}

void SpillFile::move_to_disk() {
    temp_ = std::make_unique<AtomicOutput>(name_);
    fd_ = ::open(temp_->temp_path().c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    if (fd_ < 0)
        throw Error(temp_->temp_path(), std::string("cannot create a temporary: ") + std::strerror(errno), ErrorKind::Other);
    for (uint64_t at = 0; at < size_; at += kBlockBytes)
        if (!io::write_all(fd_, blocks_[size_t(at / kBlockBytes)].get(), std::min(kBlockBytes, size_ - at)))
            throw Error(temp_->temp_path(), std::string("write failed: ") + std::strerror(errno), ErrorKind::Other);
    release_memory();
    on_disk_ = true;
}

void SpillFile::release_memory() {
    blocks_.clear();
    allowance_.bytes_left += charged_;
    charged_ = 0;
}

uint64_t SpillFile::append(const void* data, uint64_t n) {
    const uint64_t at = size_;
    if (!on_disk_) {
        // Whole new blocks this append needs, paid for before any is taken.
        const uint64_t have = uint64_t(blocks_.size()) * kBlockBytes;
        const uint64_t need = size_ + n > have ? (size_ + n - have + kBlockBytes - 1) / kBlockBytes * kBlockBytes : 0;
        if (need > allowance_.bytes_left) move_to_disk();
    }
    if (on_disk_) {
        if (!io::write_all(fd_, data, n))
            throw Error(temp_->temp_path(), std::string("write failed: ") + std::strerror(errno), ErrorKind::Other);
        size_ += n;
        return at;
    }
    const auto* p = static_cast<const std::byte*>(data);
    uint64_t done = 0;
    while (done < n) {
        const uint64_t in_block = size_ % kBlockBytes;
        if (in_block == 0 && size_ / kBlockBytes == blocks_.size()) {
            blocks_.push_back(std::unique_ptr<std::byte[]>(new std::byte[kBlockBytes]));
            allowance_.bytes_left -= kBlockBytes;
            charged_ += kBlockBytes;
        }
        const uint64_t k = std::min(n - done, kBlockBytes - in_block);
        std::memcpy(blocks_[size_t(size_ / kBlockBytes)].get() + in_block, p + done, size_t(k));
        done += k;
        size_ += k;
    }
    return at;
}

void SpillFile::read(uint64_t offset, uint64_t n, void* dst) const {
    if (offset > size_ || n > size_ - offset)
        throw Error(name_, "spill read past its end", ErrorKind::Other);
    auto* p = static_cast<char*>(dst);
    if (!on_disk_) {
        uint64_t done = 0;
        while (done < n) {
            const uint64_t at = offset + done, in_block = at % kBlockBytes;
            const uint64_t k = std::min(n - done, kBlockBytes - in_block);
            std::memcpy(p + done, blocks_[size_t(at / kBlockBytes)].get() + in_block, size_t(k));
            done += k;
        }
        return;
    }
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
    release_memory();
    size_ = 0;
}

}  // namespace octiso::convert_detail
