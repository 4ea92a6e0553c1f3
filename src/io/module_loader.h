// Finding and loading octiso's own plug-in modules (liboctiso_images.so, liboctiso_volumes.so):
// libraries nothing links, loaded on first use so that a process which never needs them never
// pays for the libraries behind them (image_codec.h, volume_codec.h say what each one saves).
#pragma once

#include <string>

#include "octiso/error.h"

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

/// The table of functions a module exports (its entry returns `const Table*`, whose first member
/// `abi` must equal this build's `abi`), loaded on the first call for each Table (thread-safe)
/// and kept until exit. Throws Error(`kind` + " " + file, why, ErrorKind::Other) when the module
/// is not found, does not load, or is of another build, on that call and every later one.
template <class Table>
const Table& module_table(const char* kind, const char* file, const char* env_override, const char* entry_symbol, int abi) {
    struct Loaded {
        const Table* table = nullptr;
        std::string problem;   ///< why not, when table is null
    };
    static const Loaded loaded = [&]() -> Loaded {
        const LoadedModule m = load_module(file, env_override, entry_symbol);
        if (!m.entry) return {nullptr, m.problem};
        const Table* t = reinterpret_cast<const Table* (*)()>(m.entry)();
        if (!t || t->abi != abi)
            return {nullptr, m.path + " is from another build of octiso (codec ABI " + std::to_string(t ? t->abi : -1) +
                                 ", this build " + std::to_string(abi) + "): reinstall octiso"};
        return {t, {}};
    }();
    if (!loaded.table) throw Error(std::string(kind) + " " + file, loaded.problem, ErrorKind::Other);
    return *loaded.table;
}

}  // namespace octiso::io
