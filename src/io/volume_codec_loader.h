// The volume codec module (volume_codec.h), loaded once per process on first use.
#pragma once

#include "io/volume_codec.h"

namespace octiso::volume_codec {

/// The codec of liboctiso_volumes.so, loaded on the first call (thread-safe) and kept until exit,
/// found as the image module is (io::load_module; $OCTISO_VOLUME_MODULE names the file). Throws
/// Error(ErrorKind::Other) naming the module and the reason when it is not found, does not load,
/// or is of another build.
const VolumeCodec& codec();

}  // namespace octiso::volume_codec
