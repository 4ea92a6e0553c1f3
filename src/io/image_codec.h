// The image codec: what octiso asks of OpenImageIO, behind a table of functions that lives in a
// module of its own (liboctiso_images.so, src/io/image_codec_oiio.cpp) and is loaded on the first
// image read or written (image_codec_loader.h).
//
// Why a module: libOpenImageIO pulls in about 260 shared libraries on Debian 12 (FFmpeg, OpenCV,
// GDAL, DCMTK, ...), all built with BIND_NOW, so every process that links it spends 0.3-0.4 s in
// the dynamic loader before main(), 1-2 s under ASan: `octiso-render --help` took 0.40 s against
// 0.04 s for octiso-convert, and each of the ~680 test processes ctest starts paid it too
// (BENCHMARKS "CI time", start-up). Loaded on demand, only the processes that touch an image file
// pay, once.
//
// Both sides are built by this project with the same compiler and standard library, so the table
// passes std::string and std::vector; kImageCodecAbi guards against a stale module. The functions
// report a failure as a message, turned into octiso::Error by the caller, not as an exception.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace octiso::image_codec {

/// Bumped whenever ImageCodec or a request changes.
inline constexpr int kImageCodecAbi = 2;
/// The module's file name (dlopen) and the one symbol it exports.
inline constexpr const char* kModuleFile = "liboctiso_images.so";
inline constexpr const char* kEntrySymbol = "octiso_image_codec";

enum class Pixel : int { u8 = 0, f32 = 1 };

/// One image to encode: width x height x channels of `pixel` at `pixels`, stored in the file as
/// `file_pixel` under `names`; png_compression >= 0 sets zlib's level for PNG.
struct EncodeRequest {
    const std::string* path;   ///< names the format (by extension) and, for direct writes, the file
    int width, height, channels;
    Pixel pixel;
    const void* pixels;
    const std::vector<std::string>* names;
    Pixel file_pixel;
    int png_compression;
};

/// What went wrong: `message` for the user; `other` marks a failure of the write or encoder rather
/// than of the named input (ErrorKind::Other).
struct Failure {
    std::string message;
    bool other = false;
    bool failed() const { return !message.empty(); }
};

struct ImageCodec {
    int abi;
    /// The format OpenImageIO writes for `path` (its format_name(), e.g. "png", "openexr"), or ""
    /// when no writer takes the extension.
    std::string (*output_format)(const std::string& path);
    /// Encodes into `bytes` where the format supports I/O proxies (`in_memory` true); else leaves
    /// both alone and returns no failure, and the caller uses write_file.
    Failure (*encode)(const EncodeRequest& request, std::vector<unsigned char>& bytes, bool& in_memory);
    /// Writes the image itself to `file` (a temporary the caller renames), for formats without I/O
    /// proxies.
    Failure (*write_file)(const EncodeRequest& request, const std::string& file);
    /// Reads every channel of the first subimage as float, row 0 at the top.
    Failure (*read)(const std::string& path, int& width, int& height, int& channels, std::vector<std::string>& names,
                    std::vector<float>& pixels);
};

}  // namespace octiso::image_codec

/// The module's entry: its codec table (static storage).
extern "C" const octiso::image_codec::ImageCodec* octiso_image_codec();
