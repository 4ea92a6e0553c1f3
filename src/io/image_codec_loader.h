// The image codec module (image_codec.h), loaded once per process on first use.
#pragma once

#include "io/image_codec.h"

namespace octiso::image_codec {

/// The codec of liboctiso_images.so, loaded on the first call (thread-safe) and kept until exit.
/// Where from: $OCTISO_IMAGE_MODULE if set (that file only); else the first liboctiso_images.so
/// in the library search path of the object holding this code (LD_LIBRARY_PATH, its RUNPATH: the
/// build directory for the Python module, lib/octiso under the prefix once installed), then in
/// that object's own directory (the build tree's tools and tests). Throws Error(ErrorKind::Other)
/// naming the module and the reason when it is not found, does not load, or is of another build.
const ImageCodec& codec();

}  // namespace octiso::image_codec
