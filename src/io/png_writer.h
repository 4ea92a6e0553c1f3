// 8-bit RGB PNG through libpng itself, without the image module: the colour image is the one
// output nearly every render writes, and loading OpenImageIO for it cost each single-frame
// octiso-render about 0.4 s against a 0.03-0.05 s frame at 512^2 (its 260 shared libraries, all
// bound before their first call; BENCHMARKS "Start-up: PNG and EXR without the image module").
// OpenImageIO's PNG writer is libpng too: the pixels are the ones it wrote (ImageModuleCli, the
// golden frames); float OpenEXR is exr_writer.h's, other formats still go through the module.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace octiso::io {

/// Whether `path` names a PNG file by its extension (".png", any case).
bool is_png_path(const std::string& path);

/// How hard the encoder works: zlib's level (0-9) and whether libpng picks a filter per row
/// (adaptive) or stores the rows unfiltered.
struct PngEffort {
    int zlib_level;
    bool row_filters;
};
/// Files: libpng's defaults (zlib 6, adaptive row filters); 1.4-2.9 % more bytes than OpenImageIO
/// 2.4 wrote for the same frames (three renders at 512^2 and 1024^2).
inline constexpr PngEffort kPngFile{6, true};
/// The viewer's frames, which only cross a socket: zlib 1 without row filters, 0.49-0.52 x the
/// encode time of zlib 1 with them on five rendered frames at 512^2 and 1024^2 for 0.92-1.04 x
/// the bytes (BENCHMARKS "Start-up: PNG and EXR without the image module").
inline constexpr PngEffort kPngStream{1, false};

/// PNG bytes of `width` x `height` RGB pixels (`rgb`, 3 bytes a pixel, row 0 at the top), tagged
/// sRGB. Throws Error(ErrorKind::Other) naming `what` if libpng fails or the size is not a PNG's,
/// std::bad_alloc if memory runs out.
std::vector<unsigned char> encode_rgb8_png(int width, int height, const uint8_t* rgb, PngEffort effort, const std::string& what);

}  // namespace octiso::io
