// encode_float_exr: OpenEXR's scanline writer into memory (exr_writer.h says why not the module).
#include "io/exr_writer.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfThreading.h>

#include <algorithm>
#include <cstring>
#include <exception>
#include <limits>
#include <new>
#include <thread>

#include "io/file_extension.h"
#include "octiso/error.h"

namespace octiso::io {

namespace {

/// OpenEXR's output stream over a byte vector: the writer seeks back to fill in its table of
/// line offsets, so writes land at the current position, growing the vector where they pass its end.
class MemoryStream final : public Imf::OStream {
public:
    explicit MemoryStream(std::vector<unsigned char>& bytes) : Imf::OStream("memory"), bytes_(bytes) {}
    void write(const char c[], int n) override {
        const size_t end = position_ + size_t(n);
        if (end > bytes_.size()) bytes_.resize(end);
        std::memcpy(bytes_.data() + position_, c, size_t(n));
        position_ = end;
    }
    uint64_t tellp() override { return position_; }
    void seekp(uint64_t pos) override { position_ = size_t(pos); }

private:
    std::vector<unsigned char>& bytes_;
    size_t position_ = 0;
};

/// How many of OpenEXR's workers a file may keep busy (0: none, the calling thread compresses).
/// Its pool is process-wide; it is sized once, to the hardware threads, and never resized, so that
/// no file being written by another thread sees the pool change under it.
int worker_threads(int wanted) {
    if (wanted == 1) return 0;
    static const int pool = [] {
        const int n = int(std::max(1u, std::thread::hardware_concurrency()));
        Imf::setGlobalThreadCount(n);
        return n;
    }();
    return wanted <= 0 ? pool : std::min(wanted, pool);
}

}  // namespace

bool is_exr_path(const std::string& path) { return has_extension(path, ".exr"); }

std::vector<unsigned char> encode_float_exr(int width, int height, const float* pixels, const std::vector<std::string>& names,
                                            const std::string& what, int threads, int zip_level) {
    const size_t channels = names.size();
    // Byte strides are size_t; the pixel count of a row must also fit OpenEXR's int arithmetic.
    if (width <= 0 || height <= 0 || channels == 0 || channels > 4 ||
        size_t(width) > size_t(std::numeric_limits<int>::max()) / (channels * sizeof(float)))
        throw Error(what, "cannot encode a " + std::to_string(width) + "x" + std::to_string(height) + " image of " +
                              std::to_string(channels) + " channels as OpenEXR", ErrorKind::Other);
    std::vector<unsigned char> bytes;
    try {
        Imf::Header header(width, height);
        header.compression() = Imf::ZIP_COMPRESSION;
        header.zipCompressionLevel() = std::clamp(zip_level, 1, 9);   // not written to the file
        Imf::FrameBuffer frame;
        const size_t x_stride = channels * sizeof(float), y_stride = x_stride * size_t(width);
        for (size_t c = 0; c < channels; ++c) {
            header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
            // Slice wants a writable pointer; the writer only reads through it.
            char* base = reinterpret_cast<char*>(const_cast<float*>(pixels + c));
            frame.insert(names[c], Imf::Slice(Imf::FLOAT, base, x_stride, y_stride));
        }
        MemoryStream stream(bytes);
        Imf::OutputFile file(stream, header, worker_threads(threads));   // 0: the calling thread alone
        file.setFrameBuffer(frame);
        file.writePixels(height);
    } catch (const std::bad_alloc&) {
        throw;
    } catch (const std::exception& e) {
        std::string message = e.what();   // one line, as every error a tool prints
        std::replace(message.begin(), message.end(), '\n', ' ');
        throw Error(what, "OpenEXR encoding failed: " + message, ErrorKind::Other);
    }
    return bytes;
}

}  // namespace octiso::io
