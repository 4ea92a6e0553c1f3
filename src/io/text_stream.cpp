// The NRRD / MetaImage VolumeStream (volume_stream.h): the voxels where text_data_layout() says
// they are, read with pread (raw), inflated as they are read (gzip or zlib framing: inflate
// finds which from the first bytes) or parsed (NRRD ascii), so that a file larger than memory
// costs one slab and a 1 MiB input buffer. Grid, type and placement are VTK's reading of the
// same header (vtk_information.h): a file the two read differently is left to VTK whole.
#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cerrno>
#include <climits>
#include <cstring>
#include <limits>
#include <fcntl.h>
#include <unistd.h>
#include <vector>

#include <zlib.h>

#include "io/text_layout.h"
#include "io/volume_stream.h"
#include "io/vtk_information.h"
#include "util/mapping_guard.h"

namespace octiso {

namespace {

constexpr size_t kInflateInput = size_t(1) << 20;   // compressed (or ascii) bytes per pread

class TextStream final : public VolumeStream {
public:
    TextStream(const std::string& path, const io::DataLayout& l, const Placement& placement, VolumeFormat format, int fd)
        : VolumeStream(l.type, l.dims, placement, path, format), layout_(l), fd_(fd), pos_(l.offset),
          swap_(scalar_type_bytes(l.type) > 1 && l.big_endian != (std::endian::native == std::endian::big)) {
        if (layout_.encoding != io::DataEncoding::raw) in_.resize(kInflateInput);
        if (layout_.encoding == io::DataEncoding::deflate) {
            if (::inflateInit2(&z_, 15 + 32) != Z_OK) {   // 15 + 32: a gzip or zlib header, detected
                ::close(fd_);
                throw Error(path, "cannot start zlib");
            }
        }
    }
    ~TextStream() override {
        if (layout_.encoding == io::DataEncoding::deflate) ::inflateEnd(&z_);
        ::close(fd_);
    }
    uint64_t file_bytes_read() const override { return pos_ - layout_.offset; }

protected:
    void read_bytes(uint64_t bytes, std::byte* dst) override {
        if (layout_.encoding == io::DataEncoding::raw) {
            pread_fully(fd_, dst, bytes, pos_, layout_.data_path);
            pos_ += bytes;
        } else if (layout_.encoding == io::DataEncoding::ascii) {
            parse_values(dst, bytes / scalar_type_bytes(type()));
            return;   // parsed into native order
        } else {
            inflate_into(dst, bytes);
            // After the last voxel, on to the end of the stream: its check value (gzip CRC-32,
            // zlib Adler-32) is what tells a damaged stream from one that merely decodes.
            if (uint64_t(next_layer()) * layer_bytes() + bytes == this->bytes()) drain_to_end();
        }
        if (swap_) swap_scalars_in_place(dst, bytes, scalar_type_bytes(type()));
    }

private:
    /// The next `bytes` decompressed bytes; a stream of several gzip members is read on through
    /// each member's end.
    void inflate_into(std::byte* dst, uint64_t bytes) {
        uint64_t done = 0;
        while (done < bytes) {
            if (z_.avail_in == 0) refill();
            const uInt want = uInt(std::min<uint64_t>(bytes - done, uint64_t(1) << 30));
            z_.next_out = reinterpret_cast<Bytef*>(dst + done);
            z_.avail_out = want;
            const int r = ::inflate(&z_, Z_NO_FLUSH);
            done += want - z_.avail_out;
            if (r == Z_STREAM_END) {
                ended_ = done == bytes;
                if (done < bytes) {
                    if (z_.avail_in == 0 && !more_input())
                        throw Error(layout_.data_path, "compressed data ends before the voxels the header declares (" +
                                                           std::to_string(total_out_ + z_.total_out) + " bytes)");
                    total_out_ += z_.total_out;
                    ::inflateReset(&z_);
                }
            } else if (r != Z_OK && !(r == Z_BUF_ERROR && z_.avail_in == 0)) {
                fail(r);
            }
        }
    }
    /// The next `n` numbers of NRRD ascii data (separated by whitespace or commas) as type(),
    /// each checked to be a whole number in range for integer types.
    void parse_values(std::byte* dst, uint64_t n) {
        const size_t b = scalar_type_bytes(type());
        for (uint64_t i = 0; i < n; ++i) {
            const std::string_view token = next_token();
            if (token.empty())
                throw Error(layout_.data_path, "ascii data ends after " + std::to_string(values_read_) + " of " +
                                                   std::to_string(dims().voxels()) + " values");
            auto store = [&](auto value) { std::memcpy(dst + i * b, &value, b); };
            const char* first = token.data();
            const char* last = first + token.size();
            bool ok = false;
            switch (type()) {
                case ScalarType::f32: {
                    float v;
                    ok = std::from_chars(first, last, v).ptr == last;
                    store(v);
                    break;
                }
                case ScalarType::f64: {
                    double v;
                    ok = std::from_chars(first, last, v).ptr == last;
                    store(v);
                    break;
                }
                default: {
                    int64_t v = 0;
                    ok = std::from_chars(first + (*first == '+'), last, v).ptr == last;
                    auto put = [&](auto tag) {
                        using T = decltype(tag);
                        ok = ok && v >= int64_t(std::numeric_limits<T>::min()) && v <= int64_t(std::numeric_limits<T>::max());
                        store(T(v));
                    };
                    switch (type()) {
                        case ScalarType::u8: put(uint8_t{}); break;
                        case ScalarType::i8: put(int8_t{}); break;
                        case ScalarType::u16: put(uint16_t{}); break;
                        case ScalarType::i16: put(int16_t{}); break;
                        case ScalarType::u32: put(uint32_t{}); break;
                        default: put(int32_t{}); break;
                    }
                }
            }
            if (!ok)
                throw Error(layout_.data_path, "ascii value " + std::to_string(values_read_ + 1) + " '" + std::string(token) +
                                                   "' is not a " + std::string(scalar_type_name(type())));
            ++values_read_;
        }
    }
    /// The next token, or empty at the end of the file. A token may span two reads; longer than
    /// 64 characters it is refused (no number of these types needs more).
    std::string_view next_token() {
        token_.clear();
        for (;;) {
            if (in_at_ == in_len_) {
                const ssize_t n = read_some();
                if (n == 0) return token_;
                in_at_ = 0, in_len_ = size_t(n);
            }
            const char c = char(in_[in_at_]);
            const bool separator = std::isspace((unsigned char)c) || c == ',';
            if (separator && !token_.empty()) return token_;
            ++in_at_;
            if (separator) continue;
            if (token_.size() == 64)
                throw Error(layout_.data_path, "ascii value " + std::to_string(values_read_ + 1) + " is over 64 characters");
            token_ += c;
        }
    }
    ssize_t read_some() {
        for (;;) {
            const ssize_t r = ::pread(fd_, in_.data(), in_.size(), off_t(pos_));
            if (r >= 0) {
                pos_ += uint64_t(r);
                return r;
            }
            if (errno != EINTR) throw Error(layout_.data_path, std::string("read failed: ") + std::strerror(errno));
        }
    }

    void drain_to_end() {
        std::array<std::byte, 1 << 16> scratch;
        while (!ended_) {
            if (z_.avail_in == 0 && !more_input()) throw Error(layout_.data_path, "compressed data ends before its check value");
            if (z_.avail_in == 0) refill();
            z_.next_out = reinterpret_cast<Bytef*>(scratch.data());
            z_.avail_out = uInt(scratch.size());
            const int r = ::inflate(&z_, Z_NO_FLUSH);
            ended_ = r == Z_STREAM_END;
            if (!ended_ && r != Z_OK && !(r == Z_BUF_ERROR && z_.avail_in == 0)) fail(r);
        }
    }
    [[noreturn]] void fail(int r) const {
        throw Error(layout_.data_path,
                    std::string("cannot decompress the voxels: ") + (z_.msg ? z_.msg : "zlib error " + std::to_string(r)));
    }
    bool more_input() {
        std::byte probe;
        return ::pread(fd_, &probe, 1, off_t(pos_)) == 1;
    }
    void refill() {
        const ssize_t n = read_some();
        if (n == 0) throw Error(layout_.data_path, "compressed data ends early (fewer voxels than the header declares)");
        z_.next_in = reinterpret_cast<Bytef*>(in_.data());
        z_.avail_in = uInt(n);
    }

    io::DataLayout layout_;
    int fd_;
    uint64_t pos_;   // next byte of the data file to read
    bool swap_;
    z_stream z_{};
    uint64_t total_out_ = 0;   // decompressed bytes of the members before the current one
    bool ended_ = false;       // the last member's end (and check value) has been read
    std::vector<std::byte> in_;
    size_t in_at_ = 0, in_len_ = 0;   // ascii: the unparsed part of in_
    std::string token_;
    uint64_t values_read_ = 0;
};

/// The layout and VTK's placement, or why the file is left to VTK.
struct TextStreamPlan {
    std::optional<io::DataLayout> layout;
    Placement placement;
    std::string why_not;
};

TextStreamPlan plan_text_stream(const std::string& path, VolumeFormat format) {
    io::LayoutOrReason l = io::text_data_layout(path, format);
    if (!l.layout) return {std::nullopt, {}, std::move(l.why_not)};
    const io::VtkImageInformation vtk = io::read_vtk_information(path, format);
    const Dims d = l.layout->dims;
    if (vtk.extent != std::array<uint64_t, 3>{d.x, d.y, d.z} || vtk.components != 1 || vtk.type != l.layout->type)
        return {std::nullopt, {}, "VTK reads its grid, components or type differently from the header's sizes and type"};
    return {l.layout, vtk.placement, {}};
}

}  // namespace

std::optional<std::string> text_stream_refusal(const std::string& path, VolumeFormat format) {
    TextStreamPlan plan = plan_text_stream(path, format);
    return plan.layout ? std::nullopt : std::optional<std::string>(std::move(plan.why_not));
}

namespace {

std::unique_ptr<VolumeStream> open_planned(const std::string& path, const TextStreamPlan& plan, VolumeFormat format) {
    const io::DataLayout& layout = *plan.layout;
    const int fd = ::open(layout.data_path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) throw Error(layout.data_path, std::string("cannot open: ") + std::strerror(errno));
    try {
        io::lock_shared_or_refuse(fd, layout.data_path);   // the same policy as the raw stream
    } catch (...) {
        ::close(fd);
        throw;
    }
    return std::make_unique<TextStream>(path, layout, plan.placement, format, fd);
}

}  // namespace

std::unique_ptr<VolumeStream> open_text_stream(const std::string& path, VolumeFormat format) {
    const TextStreamPlan plan = plan_text_stream(path, format);
    if (!plan.layout)
        throw Error(path, std::string(volume_format_name(format)) + " input is read whole, not streamed (" + plan.why_not + ")",
                    ErrorKind::Other);
    return open_planned(path, plan, format);
}

std::unique_ptr<VolumeStream> try_open_text_stream(const std::string& path, VolumeFormat format) {
    const TextStreamPlan plan = plan_text_stream(path, format);
    return plan.layout ? open_planned(path, plan, format) : nullptr;
}

}  // namespace octiso
