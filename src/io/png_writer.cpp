// encode_rgb8_png: libpng's write API into memory (png_writer.h says why not the image module).
// libpng reports errors by longjmp back to the setjmp in encode(): nothing with a destructor
// lives in that frame, and the write callback turns bad_alloc into a flag instead of throwing
// through C.
#include "io/png_writer.h"

#include <png.h>
#include <zlib.h>

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <limits>
#include <new>

#include "io/file_extension.h"
#include "octiso/error.h"

namespace octiso::io {

namespace {

struct Sink {
    std::vector<unsigned char>* bytes;
    bool out_of_memory = false;
    char message[160] = {};
};

void on_write(png_structp png, png_bytep data, size_t n) {
    auto* sink = static_cast<Sink*>(png_get_io_ptr(png));
    if (sink->out_of_memory) return;
    try {
        sink->bytes->insert(sink->bytes->end(), data, data + n);
    } catch (const std::bad_alloc&) {
        sink->out_of_memory = true;
    }
}

void on_flush(png_structp) {}

[[noreturn]] void on_error(png_structp png, png_const_charp message) {
    auto* sink = static_cast<Sink*>(png_get_error_ptr(png));
    std::snprintf(sink->message, sizeof sink->message, "%s", message);
    png_longjmp(png, 1);
}

/// libpng's warnings (none expected for 8-bit RGB) would go to stderr: a tool's stderr is its
/// one-line report.
void on_warning(png_structp, png_const_charp) {}

/// Returns false (sink.message says why, unless libpng could not even allocate) on failure.
bool encode(Sink& sink, int width, int height, const uint8_t* rgb, PngEffort effort) {
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &sink, on_error, on_warning);
    if (!png) return false;
    png_infop info = png_create_info_struct(png);
    if (!info) {
        png_destroy_write_struct(&png, nullptr);
        return false;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return false;
    }
    png_set_write_fn(png, &sink, on_write, on_flush);
    png_set_compression_level(png, std::clamp(effort.zlib_level, 0, 9));
    if (effort.deflate == PngDeflate::run_length) png_set_compression_strategy(png, Z_RLE);
    switch (effort.filter) {
        case PngRowFilter::adaptive: break;   // libpng's default: all five, chosen per row
        case PngRowFilter::none: png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE); break;
        case PngRowFilter::paeth: png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_PAETH); break;
        case PngRowFilter::up: png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_UP); break;
    }
    png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);   // CONVENTIONS 2: colour is 8-bit sRGB
    png_write_info(png, info);
    const size_t row_bytes = size_t(width) * 3;
    for (int y = 0; y < height; ++y) png_write_row(png, rgb + size_t(y) * row_bytes);
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    return true;
}

}  // namespace

bool is_png_path(const std::string& path) { return has_extension(path, ".png"); }

std::vector<unsigned char> encode_rgb8_png(int width, int height, const uint8_t* rgb, PngEffort effort, const std::string& what) {
    // PNG's own limit is 2^31 - 1 a side; rows of 3 bytes a pixel must fit libpng's size type.
    if (width <= 0 || height <= 0 || width > std::numeric_limits<int>::max() / 3)
        throw Error(what, "cannot encode a " + std::to_string(width) + "x" + std::to_string(height) + " PNG",
                    ErrorKind::Other);
    std::vector<unsigned char> bytes;
    Sink sink{&bytes};
    const bool ok = encode(sink, width, height, rgb, effort);
    if (sink.out_of_memory) throw std::bad_alloc();
    if (!ok)
        throw Error(what, std::string("PNG encoding failed: ") + (sink.message[0] ? sink.message : "libpng could not start"),
                    ErrorKind::Other);
    return bytes;
}

}  // namespace octiso::io
