// encode_png over OpenImageIO's PNG writer with an in-memory I/O proxy (as src/io/image_io.cpp).
#include "view/png.h"

#include <vector>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "octiso/error.h"

namespace octiso::view {

std::string encode_png(const Frame& frame) {
    if (frame.width <= 0 || frame.height <= 0 || frame.rgb.size() != size_t(frame.width) * size_t(frame.height) * 3)
        throw Error("frame", "no colour image to encode", ErrorKind::Other);
    auto out = OIIO::ImageOutput::create("frame.png");
    if (!out || !out->supports("ioproxy")) throw Error("frame", "OpenImageIO has no PNG writer with I/O proxies", ErrorKind::Other);
    OIIO::ImageSpec spec(frame.width, frame.height, 3, OIIO::TypeDesc::UINT8);
    spec.attribute("png:compressionLevel", 1);
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput memory(bytes);
    if (!out->set_ioproxy(&memory) || !out->open("frame.png", spec) ||
        !out->write_image(OIIO::TypeDesc::UINT8, frame.rgb.data()) || !out->close())
        throw Error("frame", "PNG encoding failed: " + out->geterror(), ErrorKind::Other);
    return std::string(bytes.begin(), bytes.end());
}

}  // namespace octiso::view
