// encode_png through the image codec (src/io/image_codec.h: OpenImageIO's PNG writer with an
// in-memory I/O proxy, in the module loaded on the first image), as src/io/image_io.cpp writes.
#include "view/png.h"

#include <vector>

#include "io/image_codec_loader.h"
#include "octiso/error.h"

namespace octiso::view {

std::string encode_png(const Frame& frame) {
    if (frame.width <= 0 || frame.height <= 0 || frame.rgb.size() != size_t(frame.width) * size_t(frame.height) * 3)
        throw Error("frame", "no colour image to encode", ErrorKind::Other);
    const std::string name = "frame.png";
    const std::vector<std::string> channels{"R", "G", "B"};
    using image_codec::Pixel;
    const image_codec::EncodeRequest request{&name, frame.width, frame.height, 3, Pixel::u8, frame.rgb.data(), &channels, Pixel::u8, 1};
    std::vector<unsigned char> bytes;
    bool in_memory = false;
    const image_codec::Failure f = image_codec::codec().encode(request, bytes, in_memory);
    if (f.failed()) throw Error("frame", "PNG encoding failed: " + f.message, ErrorKind::Other);
    if (!in_memory) throw Error("frame", "OpenImageIO has no PNG writer with I/O proxies", ErrorKind::Other);
    return std::string(bytes.begin(), bytes.end());
}

}  // namespace octiso::view
