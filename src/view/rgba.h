// rgba_bytes: a frame's 8-bit sRGB colour as raw RGBA rows (alpha 255), the viewer's loopback
// frame format (request.h FrameEncoding::rgba): the page wraps the bytes as ImageData and puts
// them on its canvas with no decode, so the screen holds exactly the tile loop's pixels.
#pragma once

#include <cstddef>
#include <string>

#include "octiso/error.h"
#include "octiso/frame.h"

namespace octiso::view {

/// width x height x 4 bytes, row 0 the top row. RGBA rather than the frame's RGB so that the
/// browser takes the buffer as it is (ImageData is RGBA); the widening costs the server well
/// under a millisecond at 512^2, the same loop in JavaScript a few. Throws Error(ErrorKind::Other)
/// when the frame has no colour.
inline std::string rgba_bytes(const Frame& frame) {
    const size_t pixels = size_t(frame.width) * size_t(frame.height);
    if (frame.width <= 0 || frame.height <= 0 || frame.rgb.size() != pixels * 3)
        throw Error("frame", "no colour image to send", ErrorKind::Other);
    std::string out(pixels * 4, '\xff');
    const uint8_t* rgb = frame.rgb.data();
    char* rgba = out.data();
    for (size_t i = 0; i < pixels; ++i) {
        rgba[4 * i + 0] = char(rgb[3 * i + 0]);
        rgba[4 * i + 1] = char(rgb[3 * i + 1]);
        rgba[4 * i + 2] = char(rgb[3 * i + 2]);
    }
    return out;
}

}  // namespace octiso::view
