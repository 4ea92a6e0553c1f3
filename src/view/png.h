// encode_png: a frame's 8-bit sRGB colour as PNG bytes in memory (libpng, the encoder
// octiso-render's PNG files come from), the viewer's frame format: lossless, so the page shows
// exactly the pixels octiso-render writes (the end-to-end test compares them).
#pragma once

#include <string>

#include "octiso/frame.h"

namespace octiso::view {

/// PNG of frame.rgb (width x height x 3) at io::kPngStream (zlib 1, unfiltered rows): at 1024^2
/// the file settings cost more than the render, and the bytes only cross a socket. Its strips of
/// rows are deflated by up to `threads` threads (the session's; 0: all cores): the frame waits
/// for its encode, so the encode gets the cores the render just had. Throws
/// Error(ErrorKind::Other) if the encoder fails.
std::string encode_png(const Frame& frame, int threads = 1);

}  // namespace octiso::view
