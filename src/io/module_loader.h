// Finding and loading octiso's own plug-in modules (liboctiso_images.so, liboctiso_volumes.so):
// libraries nothing links, loaded on first use so that a process which never needs them never
// pays for the libraries behind them (image_codec.h, volume_codec.h say what each one saves).
#pragma once

#include <string>

namespace octiso::io {

/// A module's entry point, or why there is none.
struct LoadedModule {
    void* entry = nullptr;   ///< the address of `entry_symbol` in the module
    std::string path;        ///< the file loaded (or tried)
    std::string problem;     ///< why not, when entry is null
};

/// Loads the module `file` once per call (callers keep the result in a function-local static)
/// and looks up `entry_symbol` in it. Where from: $`env_override` if set (that file only); else
/// the first `file` in the library search path of the object holding this code (LD_LIBRARY_PATH,
/// its RUNPATH: the build directory for the Python module, lib/octiso under the prefix once
/// installed), then in that object's own directory (the build tree's tools and tests). The module
/// is opened RTLD_NOW | RTLD_LOCAL: a broken one fails here, and its libraries' symbols stay out
/// of the global scope.
LoadedModule load_module(const std::string& file, const char* env_override, const char* entry_symbol);

}  // namespace octiso::io
