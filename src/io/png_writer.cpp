// encode_rgb8_png: libpng's write API into memory (png_writer.h says why not the image module).
// libpng reports errors by longjmp back to the setjmp in encode(): nothing with a destructor
// lives in that frame, and the write callback turns bad_alloc into a flag instead of throwing
// through C. With one filter for every row, the image data is made here instead, in strips that
// threads filter and deflate side by side (libpng compresses on the calling thread only), and
// libpng writes it as the IDAT chunk of the file it frames.
#include "io/png_writer.h"

#include <png.h>
#include <tbb/parallel_for.h>
#include <zlib.h>

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <new>

#include "io/file_extension.h"
#include "util/check.h"
#include "util/shared_arena.h"
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

/// Rows per strip of the strip encoder. Each strip is deflated on its own, so a match never
/// reaches back into the strip before: at 64 rows the strips cost 0.993-0.999 x the bytes of
/// libpng's one stream on five rendered frames (Z_RLE and Paeth, writers.json), and a 1024^2 frame
/// has 16 strips for the threads (BENCHMARKS "Image writers").
constexpr int kStripRows = 64;

/// PNG's filter type byte for a filter that applies to every row.
uint8_t filter_type(PngRowFilter f) { return f == PngRowFilter::none ? 0 : f == PngRowFilter::up ? 2 : 4; }

/// The Paeth predictor of the PNG specification (section 9.4): of left, above and upper left,
/// the one nearest to left + above - upper left, ties in that order.
inline int paeth_predictor(int a, int b, int c) {
    const int pa = std::abs(b - c), pb = std::abs(a - c), pc = std::abs(a + b - 2 * c);
    return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
}

/// One filtered row: the type byte, then `n` bytes of `row` less their prediction from `above`
/// (the row before, zeros for the first) and from the pixel to the left (3 bytes back).
void filter_row(PngRowFilter filter, const uint8_t* row, const uint8_t* above, size_t n, uint8_t* out) {
    *out++ = filter_type(filter);
    switch (filter) {
        case PngRowFilter::none: std::copy(row, row + n, out); break;
        case PngRowFilter::up:
            for (size_t i = 0; i < n; ++i) out[i] = uint8_t(row[i] - above[i]);
            break;
        default:   // paeth (adaptive never comes here)
            for (size_t i = 0; i < 3 && i < n; ++i) out[i] = uint8_t(row[i] - paeth_predictor(0, above[i], 0));
            for (size_t i = 3; i < n; ++i) out[i] = uint8_t(row[i] - paeth_predictor(row[i - 3], above[i], above[i - 3]));
    }
}

/// One strip's share of the image data: its raw deflate data, and the Adler-32 and length of the
/// filtered rows it compresses (the stream's check value is combined from them).
struct Strip {
    std::vector<unsigned char> deflated;
    uLong adler = 0;
    size_t filtered_bytes = 0;
};

/// Strip `s` filtered and deflated as raw deflate data. Every strip but the last ends in a sync
/// flush (an empty stored block: byte-aligned, not final), so the strips concatenated are one
/// deflate stream; the last one ends it.
Strip deflate_strip(int s, int width, int height, const uint8_t* rgb, PngEffort effort) {
    const size_t row_bytes = size_t(width) * 3;
    const int y0 = s * kStripRows, y1 = std::min(height, y0 + kStripRows);
    std::vector<uint8_t> filtered(size_t(y1 - y0) * (row_bytes + 1));
    const std::vector<uint8_t> zeros(y0 == 0 ? row_bytes : 0);
    for (int y = y0; y < y1; ++y) {
        const uint8_t* row = rgb + size_t(y) * row_bytes;
        filter_row(effort.filter, row, y == 0 ? zeros.data() : row - row_bytes, row_bytes, &filtered[size_t(y - y0) * (row_bytes + 1)]);
    }
    z_stream z{};
    const int strategy = effort.deflate == PngDeflate::run_length ? Z_RLE : Z_DEFAULT_STRATEGY;
    if (deflateInit2(&z, std::clamp(effort.zlib_level, 0, 9), Z_DEFLATED, -15, 8, strategy) != Z_OK) throw std::bad_alloc();
    Strip strip;
    std::vector<unsigned char>& out = strip.deflated;
    out.resize(deflateBound(&z, uLong(filtered.size())) + 64);
    z.next_in = filtered.data();
    z.avail_in = uInt(filtered.size());
    const bool last = y1 == height;
    size_t written = 0;
    int status = Z_OK;
    do {   // deflateBound is enough for Z_FINISH; a sync flush adds a few bytes, so grow if asked
        if (written == out.size()) out.resize(out.size() * 2);
        z.next_out = out.data() + written;
        z.avail_out = uInt(out.size() - written);
        status = deflate(&z, last ? Z_FINISH : Z_SYNC_FLUSH);
        written = out.size() - z.avail_out;
    } while (status == Z_OK && (z.avail_in > 0 || z.avail_out == 0 || last));
    deflateEnd(&z);
    // A sync flush that ended exactly at the buffer's end is finished by a call that has nothing
    // left to do (Z_BUF_ERROR); anything else short of the end is a zlib failure.
    OCTISO_CHECK(last ? status == Z_STREAM_END : status == Z_OK || status == Z_BUF_ERROR, "zlib deflate of a PNG strip failed");
    out.resize(written);
    strip.adler = adler32(1, filtered.data(), uInt(filtered.size()));
    strip.filtered_bytes = filtered.size();
    return strip;
}

/// The zlib stream of the image data (RFC 1950: header, the strips' deflate data, the Adler-32 of
/// all filtered rows), its strips made in the process's arena of `threads` threads (0: the
/// caller's, all cores; util/shared_arena.h, the render's arena for its --threads). The same
/// bytes on any count: the strips do not depend on who makes them.
std::vector<unsigned char> image_data(int width, int height, const uint8_t* rgb, PngEffort effort, int threads) {
    const int count = (height + kStripRows - 1) / kStripRows;
    std::vector<Strip> strips(static_cast<size_t>(count));
    auto make = [&](int s) { strips[size_t(s)] = deflate_strip(s, width, height, rgb, effort); };
    if (threads == 1 || count == 1) {
        for (int s = 0; s < count; ++s) make(s);
    } else {
        in_shared_arena(threads, [&] { tbb::parallel_for(0, count, make); });
    }
    size_t total = 6;
    for (const Strip& strip : strips) total += strip.deflated.size();
    std::vector<unsigned char> data;
    data.reserve(total);
    data.push_back(0x78);   // CMF: deflate, 32 KiB window
    data.push_back(0x01);   // FLG: no dictionary, "fastest" level, (0x78 * 256 + 0x01) % 31 == 0
    uLong adler = strips[0].adler;
    for (size_t s = 0; s < strips.size(); ++s) {
        data.insert(data.end(), strips[s].deflated.begin(), strips[s].deflated.end());
        if (s > 0) adler = adler32_combine(adler, strips[s].adler, z_off_t(strips[s].filtered_bytes));
    }
    for (int shift = 24; shift >= 0; shift -= 8) data.push_back(uint8_t(adler >> shift));
    return data;
}

/// Returns false (sink.message says why, unless libpng could not even allocate) on failure.
/// `idat`: the image data made already (image_data), written as one IDAT chunk; null: libpng
/// filters and compresses the rows itself.
bool encode(Sink& sink, int width, int height, const uint8_t* rgb, PngEffort effort, const std::vector<unsigned char>* idat) {
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
    if (idat) {   // the chunks after IHDR and sRGB: the data, then the end
        png_write_chunk(png, reinterpret_cast<png_const_bytep>("IDAT"), idat->data(), idat->size());
        png_write_chunk(png, reinterpret_cast<png_const_bytep>("IEND"), nullptr, 0);
        png_destroy_write_struct(&png, &info);
        return true;
    }
    const size_t row_bytes = size_t(width) * 3;
    for (int y = 0; y < height; ++y) png_write_row(png, rgb + size_t(y) * row_bytes);
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    return true;
}

}  // namespace

bool is_png_path(const std::string& path) { return has_extension(path, ".png"); }

std::vector<unsigned char> encode_rgb8_png(int width, int height, const uint8_t* rgb, PngEffort effort, const std::string& what,
                                           int threads) {
    // PNG's own limit is 2^31 - 1 a side; rows of 3 bytes a pixel must fit libpng's size type.
    if (width <= 0 || height <= 0 || width > std::numeric_limits<int>::max() / 3)
        throw Error(what, "cannot encode a " + std::to_string(width) + "x" + std::to_string(height) + " PNG",
                    ErrorKind::Other);
    // One chunk holds at most 2^31 - 1 bytes; larger data goes through libpng's own rows.
    std::vector<unsigned char> idat;
    const bool one_filter = effort.filter != PngRowFilter::adaptive && !effort.libpng_rows;
    if (one_filter && (size_t(width) * 3 + 1) * size_t(height) < size_t(1) << 30) idat = image_data(width, height, rgb, effort, threads);
    std::vector<unsigned char> bytes;
    Sink sink{&bytes};
    const bool ok = encode(sink, width, height, rgb, effort, idat.empty() ? nullptr : &idat);
    if (sink.out_of_memory) throw std::bad_alloc();
    if (!ok)
        throw Error(what, std::string("PNG encoding failed: ") + (sink.message[0] ? sink.message : "libpng could not start"),
                    ErrorKind::Other);
    return bytes;
}

}  // namespace octiso::io
