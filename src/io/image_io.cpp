// include/octiso/image.h over the image codec (image_codec.h): OpenImageIO in a module loaded on
// the first image, so that processes that never touch one do not load it. The 8-bit colour PNG,
// the image nearly every render writes, goes through libpng directly (png_writer.h), and float
// images in OpenEXR (the depth and normal AOVs) through OpenEXR directly (exr_writer.h): a render
// that writes only those never loads the module.
#include <algorithm>
#include <cmath>

#include "io/exr_writer.h"
#include "io/image_codec_loader.h"
#include "io/png_writer.h"
#include "util/atomic_output.h"
#include "util/check.h"
#include "octiso/error.h"
#include "octiso/image.h"

namespace octiso {

namespace {

using image_codec::Pixel;

void write_image(const std::string& path, int width, int height, int channels, Pixel type, const void* pixels,
                 const std::vector<std::string>& names, Pixel file_type, int threads = 1) {
    // Encode into memory, then write the bytes ourselves with every write checked: OIIO's PNG
    // writer did not report ENOSPC, and a truncated PNG was renamed into place (issue 18).
    // Colour PNG (libpng) and float OpenEXR (OpenEXR) without the module; check_image_path
    // decides by the same rule.
    if (type == Pixel::u8 && file_type == Pixel::u8 && channels == 3 && io::is_png_path(path)) {
        const auto bytes = io::encode_rgb8_png(width, height, static_cast<const uint8_t*>(pixels), io::kPngFile, path, threads);
        write_file_atomically(path, bytes.data(), bytes.size());
        return;
    }
    if (type == Pixel::f32 && file_type == Pixel::f32 && io::is_exr_path(path)) {
        OCTISO_CHECK(names.size() == size_t(channels), "one name per channel");
        const auto bytes = io::encode_float_exr(width, height, static_cast<const float*>(pixels), names, path, threads);
        write_file_atomically(path, bytes.data(), bytes.size());
        return;
    }
    const image_codec::EncodeRequest request{&path, width, height, channels, type, pixels, &names, file_type, -1};
    auto check = [&](const image_codec::Failure& f) {
        if (f.failed()) throw Error(path, f.message, f.other ? ErrorKind::Other : ErrorKind::BadInput);
    };
    const image_codec::ImageCodec& codec = image_codec::codec();
    std::vector<unsigned char> bytes;
    bool in_memory = false;
    check(codec.encode(request, bytes, in_memory));
    if (in_memory) {
        write_file_atomically(path, bytes.data(), bytes.size());
        return;
    }
    // A format without I/O proxies writes its own file; commit() still fsyncs it (which reports
    // deferred write errors) before the rename.
    AtomicOutput out(path);
    check(codec.write_file(request, out.temp_path()));
    out.commit();
}

/// The float type a file format can hold: float where supported, else its native 8 bits.
Pixel float_or_native(const std::string& path) {
    if (io::is_png_path(path)) return Pixel::u8;
    if (io::is_exr_path(path)) return Pixel::f32;
    const std::string fmt = image_codec::codec().output_format(path);
    if (fmt.empty()) throw Error(path, "no image format for this extension");
    if (fmt == "openexr" || fmt == "tiff" || fmt == "hdr" || fmt == "fits" || fmt == "pfm") return Pixel::f32;
    return Pixel::u8;
}

}  // namespace

void check_image_path(const std::string& path, const std::string& flag, ImageContent content) {
    if (content == ImageContent::Colour && io::is_png_path(path)) return;   // libpng, no module
    if (content == ImageContent::Aov && io::is_exr_path(path)) return;      // OpenEXR, no module
    if (image_codec::codec().output_format(path).empty()) throw Error(flag, "'" + path + "': no image format for this extension");
}

bool image_format_holds_floats(const std::string& path) { return float_or_native(path) == Pixel::f32; }

void write_colour_image(const std::string& path, const Frame& frame, int threads) {
    if (frame.rgb.empty()) throw Error(path, "the frame has no colour image", ErrorKind::Other);
    if (frame.rgb.size() != size_t(frame.width) * size_t(frame.height) * 3)
        throw Error(path, "the colour image is not width x height x 3 bytes", ErrorKind::Other);
    write_image(path, frame.width, frame.height, 3, Pixel::u8, frame.rgb.data(), {"R", "G", "B"}, Pixel::u8, threads);
}

void write_depth_image(const std::string& path, const Frame& frame, int threads) {
    if (frame.depth.empty()) throw Error(path, "the frame has no depth image", ErrorKind::Other);
    if (frame.depth.size() != size_t(frame.width) * size_t(frame.height))
        throw Error(path, "the depth image is not width x height floats", ErrorKind::Other);
    const Pixel type = float_or_native(path);
    if (type == Pixel::f32) {
        write_image(path, frame.width, frame.height, 1, Pixel::f32, frame.depth.data(), {"Z"}, type, threads);
        return;
    }
    // An 8-bit format cannot hold distances: scale the hit range to [1/255, 1], misses 0.
    float lo = INFINITY, hi = -INFINITY;
    for (float t : frame.depth)
        if (std::isfinite(t)) lo = std::min(lo, t), hi = std::max(hi, t);
    std::vector<float> scaled(frame.depth.size(), 0.0f);
    for (size_t i = 0; i < scaled.size(); ++i)
        if (std::isfinite(frame.depth[i])) scaled[i] = hi > lo ? 1.0f - 0.996f * (frame.depth[i] - lo) / (hi - lo) : 1.0f;
    write_image(path, frame.width, frame.height, 1, Pixel::f32, scaled.data(), {"Z"}, type);
}

void write_normal_image(const std::string& path, const Frame& frame, int threads) {
    if (frame.normal.empty()) throw Error(path, "the frame has no normal image", ErrorKind::Other);
    if (frame.normal.size() != size_t(frame.width) * size_t(frame.height) * 3)
        throw Error(path, "the normal image is not width x height x 3 floats", ErrorKind::Other);
    const Pixel type = float_or_native(path);
    if (type == Pixel::f32) {
        write_image(path, frame.width, frame.height, 3, Pixel::f32, frame.normal.data(), {"R", "G", "B"}, type, threads);
        return;
    }
    std::vector<float> mapped(frame.normal.size());   // 8-bit: the usual n * 0.5 + 0.5 encoding
    for (size_t i = 0; i < mapped.size(); ++i) mapped[i] = frame.normal[i] * 0.5f + 0.5f;
    write_image(path, frame.width, frame.height, 3, Pixel::f32, mapped.data(), {"R", "G", "B"}, type);
}

FloatImage read_image(const std::string& path) {
    FloatImage img;
    const image_codec::Failure f =
        image_codec::codec().read(path, img.width, img.height, img.channels, img.channel_names, img.pixels);
    if (f.failed()) throw Error(path, f.message);
    return img;
}

}  // namespace octiso
