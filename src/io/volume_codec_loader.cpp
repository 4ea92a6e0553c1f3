// Loads liboctiso_volumes.so (volume_codec.h says why VTK lives in a module of its own).
#include "io/volume_codec_loader.h"

#include "io/module_loader.h"

namespace octiso::volume_codec {

const VolumeCodec& codec() {
    return io::module_table<VolumeCodec>("volume module", kModuleFile, "OCTISO_VOLUME_MODULE", kEntrySymbol, kVolumeCodecAbi);
}

}  // namespace octiso::volume_codec
