// Loads liboctiso_images.so (image_codec.h says why images live in a module of their own).
#include "io/image_codec_loader.h"

#include "io/module_loader.h"

namespace octiso::image_codec {

const ImageCodec& codec() {
    return io::module_table<ImageCodec>("image module", kModuleFile, "OCTISO_IMAGE_MODULE", kEntrySymbol, kImageCodecAbi);
}

}  // namespace octiso::image_codec
