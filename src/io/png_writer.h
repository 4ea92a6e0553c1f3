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

/// The row filter before deflate: libpng's adaptive choice per row (its default, which tries all
/// five filters on every row), or one filter for every row (none, Paeth, up), which the strip
/// encoder of png_writer.cpp applies itself.
enum class PngRowFilter { adaptive, none, paeth, up };
/// zlib's strategy: its standard match search at `zlib_level`, or run-length matches only
/// (Z_RLE: distance-1 matches, the level no longer matters).
enum class PngDeflate { standard, run_length };

/// How hard the encoder works: zlib's level (0-9) and strategy, and the row filter.
struct PngEffort {
    int zlib_level;
    PngRowFilter filter;
    PngDeflate deflate = PngDeflate::standard;
    /// Expert, for the benchmark's A/B: libpng filters and compresses every row on the calling
    /// thread even where one filter would let strips of rows go to threads.
    bool libpng_rows = false;
};
/// Files: every row Paeth-filtered, deflated as runs. On octiso-render's default frames
/// (`octiso-bench writers`: the MRI templates, plume and mixing at 512^2 and 1024^2) 1.00-1.03 x
/// the bytes of libpng's defaults (zlib 6, adaptive filters) in 0.14-0.28 x the encode time on one
/// thread (in strips; 0.16-0.34 x through libpng's rows), 0.08-0.17 x on two; zlib 1 with the same
/// filter is as fast and smaller on frames seen whole, but 1.19 x on a close-up that the surface
/// fills. An orbit or a series encodes its frames on one writer thread beside the trace, and at
/// libpng's defaults an orbit's writes at 1024^2 took 1.0-1.4 x its 2-thread trace (BENCHMARKS
/// "Image writers": whole orbits 0.64-0.90 x the wall time).
inline constexpr PngEffort kPngFile{1, PngRowFilter::paeth, PngDeflate::run_length};
/// The viewer's frames, which only cross a socket: zlib 1 without row filters, 0.49-0.52 x the
/// encode time of zlib 1 with them on five rendered frames at 512^2 and 1024^2 for 0.92-1.04 x
/// the bytes (BENCHMARKS "Start-up: PNG and EXR without the image module").
inline constexpr PngEffort kPngStream{1, PngRowFilter::none};

/// PNG bytes of `width` x `height` RGB pixels (`rgb`, 3 bytes a pixel, row 0 at the top), tagged
/// sRGB. With one filter for every row (not adaptive), strips of rows are filtered and deflated in
/// the process's arena of `threads` threads (util/shared_arena.h; 1: the calling thread alone; 0:
/// the caller's arena, all cores), the same bytes on any count.
/// Throws Error(ErrorKind::Other) naming `what` if libpng fails or the size is not a PNG's,
/// std::bad_alloc if memory runs out.
std::vector<unsigned char> encode_rgb8_png(int width, int height, const uint8_t* rgb, PngEffort effort, const std::string& what,
                                           int threads = 1);

}  // namespace octiso::io
