// Float images as OpenEXR through the OpenEXR library itself, without the image module: the
// depth and normal AOVs a render writes beside its colour (the colour PNG: png_writer.h). The
// module loads OpenImageIO's ~260 libraries (about 0.4 s per process); OpenEXR alone is 11 and
// 0.02 s (BENCHMARKS "Start-up: PNG and EXR without the image module"). The file holds what OpenImageIO
// wrote for the same request: 32-bit float channels under the given names, ZIP compression,
// scanlines top to bottom; the pixels read back are the same floats (ExrWriter.*, the golden
// frames' depth and normal images). No DateTime attribute: the same frame gives the same bytes.
#pragma once

#include <string>
#include <vector>

namespace octiso::io {

/// Whether `path` names an OpenEXR file by its extension (".exr", any case).
bool is_exr_path(const std::string& path);

/// zlib's level in the ZIP blocks (16 rows each): 1, where OpenEXR's default is 4. On the depth
/// and normal AOVs of rendered frames 0.74-0.90 x the encode time for 1.01-1.05 x the bytes
/// (`octiso-bench writers`, BENCHMARKS "Image writers").
inline constexpr int kExrZipLevel = 1;

/// OpenEXR bytes of `width` x `height` pixels of `names.size()` float channels, interleaved
/// (`pixels`, row 0 at the top). `threads` compress its blocks: 1, the calling thread alone; N > 1,
/// up to N of OpenEXR's worker threads (a pool of one per hardware thread, started on the first
/// such call); 0, all of them. The bytes are the same either way. Throws Error(ErrorKind::Other) naming
/// `what` if the size is not an image's or OpenEXR fails, std::bad_alloc if memory runs out.
std::vector<unsigned char> encode_float_exr(int width, int height, const float* pixels, const std::vector<std::string>& names,
                                            const std::string& what, int threads = 1, int zip_level = kExrZipLevel);

}  // namespace octiso::io
