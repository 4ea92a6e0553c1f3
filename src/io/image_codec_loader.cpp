// Loads liboctiso_images.so (image_codec.h says why images live in a module of their own).
#include "io/image_codec_loader.h"

#include <string>

#include "io/module_loader.h"
#include "octiso/error.h"

namespace octiso::image_codec {
namespace {

struct Loaded {
    const ImageCodec* codec = nullptr;
    std::string problem;   ///< why not, when codec is null
};

Loaded load() {
    const io::LoadedModule m = io::load_module(kModuleFile, "OCTISO_IMAGE_MODULE", kEntrySymbol);
    if (!m.entry) return {nullptr, m.problem};
    using Entry = const ImageCodec* (*)();
    const ImageCodec* c = reinterpret_cast<Entry>(m.entry)();
    if (!c || c->abi != kImageCodecAbi)
        return {nullptr, m.path + " is from another build of octiso (codec ABI " + std::to_string(c ? c->abi : -1) +
                             ", this build " + std::to_string(kImageCodecAbi) + "): reinstall octiso"};
    return {c, {}};
}

}  // namespace

const ImageCodec& codec() {
    static const Loaded loaded = load();   // once per process; later calls see the same outcome
    if (!loaded.codec) throw Error(std::string("image module ") + kModuleFile, loaded.problem, ErrorKind::Other);
    return *loaded.codec;
}

}  // namespace octiso::image_codec
