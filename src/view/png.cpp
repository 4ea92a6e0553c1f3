// encode_png through libpng (src/io/png_writer.h), the encoder octiso-render's PNG files come from.
#include "view/png.h"

#include <vector>

#include "io/png_writer.h"
#include "octiso/error.h"

namespace octiso::view {

std::string encode_png(const Frame& frame, int threads) {
    if (frame.width <= 0 || frame.height <= 0 || frame.rgb.size() != size_t(frame.width) * size_t(frame.height) * 3)
        throw Error("frame", "no colour image to encode", ErrorKind::Other);
    const std::vector<unsigned char> bytes = io::encode_rgb8_png(frame.width, frame.height, frame.rgb.data(), io::kPngStream, "frame",
                                                                       threads);
    return std::string(bytes.begin(), bytes.end());
}

}  // namespace octiso::view
