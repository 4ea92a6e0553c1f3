// Loads liboctiso_volumes.so (volume_codec.h says why VTK lives in a module of its own).
#include "io/volume_codec_loader.h"

#include <string>

#include "io/module_loader.h"
#include "octiso/error.h"

namespace octiso::volume_codec {
namespace {

struct Loaded {
    const VolumeCodec* codec = nullptr;
    std::string problem;   ///< why not, when codec is null
};

Loaded load() {
    const io::LoadedModule m = io::load_module(kModuleFile, "OCTISO_VOLUME_MODULE", kEntrySymbol);
    if (!m.entry) return {nullptr, m.problem};
    using Entry = const VolumeCodec* (*)();
    const VolumeCodec* c = reinterpret_cast<Entry>(m.entry)();
    if (!c || c->abi != kVolumeCodecAbi)
        return {nullptr, m.path + " is from another build of octiso (codec ABI " + std::to_string(c ? c->abi : -1) +
                             ", this build " + std::to_string(kVolumeCodecAbi) + "): reinstall octiso"};
    return {c, {}};
}

}  // namespace

const VolumeCodec& codec() {
    static const Loaded loaded = load();   // once per process; later calls see the same outcome
    if (!loaded.codec) throw Error(std::string("volume module ") + kModuleFile, loaded.problem, ErrorKind::Other);
    return *loaded.codec;
}

}  // namespace octiso::volume_codec
