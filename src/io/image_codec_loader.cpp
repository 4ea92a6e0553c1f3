// Loads liboctiso_images.so (image_codec.h says why images live in a module of their own).
#include "io/image_codec_loader.h"

#include <dlfcn.h>
#include <link.h>
#include <unistd.h>

#include <cstddef>
#include <cstdlib>
#include <string>
#include <vector>

#include "octiso/error.h"

namespace octiso::image_codec {
namespace {

struct Loaded {
    const ImageCodec* codec = nullptr;
    std::string problem;   ///< why not, when codec is null
};

/// The object (executable or shared object) this code was linked into: its file and a dlopen
/// handle for it.
struct OwnObject {
    std::string file;
    void* handle = nullptr;
};

OwnObject own_object() {
    Dl_info info{};
    link_map* own = nullptr;
    if (!dladdr1(reinterpret_cast<void*>(&own_object), &info, reinterpret_cast<void**>(&own), RTLD_DL_LINKMAP) || !own)
        return {};
    OwnObject o{info.dli_fname ? info.dli_fname : "", nullptr};
    void* main_program = dlopen(nullptr, RTLD_LAZY);
    link_map* main_map = nullptr;
    if (main_program && dlinfo(main_program, RTLD_DI_LINKMAP, &main_map) == 0 && main_map == own) o.handle = main_program;
    else if (!o.file.empty()) o.handle = dlopen(o.file.c_str(), RTLD_LAZY | RTLD_NOLOAD);
    return o;
}

/// The directories the dynamic loader searches for a library the object behind `handle` needs
/// (dlinfo RTLD_DI_SERINFO): LD_LIBRARY_PATH, its RUNPATH with $ORIGIN expanded, the system ones.
/// Searched here rather than by dlopen("liboctiso_images.so"), because dlopen takes the RUNPATH
/// of its caller, and under ASan its caller is the sanitizer's interceptor in libasan.
std::vector<std::string> library_search_path(void* handle) {
    std::vector<std::string> dirs;
    Dl_serinfo size{};
    if (!handle || dlinfo(handle, RTLD_DI_SERINFOSIZE, &size) != 0) return dirs;
    std::vector<std::max_align_t> buffer(size.dls_size / sizeof(std::max_align_t) + 1);
    auto* info = reinterpret_cast<Dl_serinfo*>(buffer.data());
    if (dlinfo(handle, RTLD_DI_SERINFOSIZE, info) != 0 || dlinfo(handle, RTLD_DI_SERINFO, info) != 0) return dirs;
    for (unsigned i = 0; i < info->dls_cnt; ++i)
        if (info->dls_serpath[i].dls_name && *info->dls_serpath[i].dls_name) dirs.push_back(info->dls_serpath[i].dls_name);
    return dirs;
}

Loaded load() {
    std::string path;
    if (const char* forced = std::getenv("OCTISO_IMAGE_MODULE"); forced && *forced) {
        path = forced;
    } else {
        const OwnObject own = own_object();
        std::vector<std::string> dirs = library_search_path(own.handle);
        if (const size_t slash = own.file.rfind('/'); slash != std::string::npos) dirs.push_back(own.file.substr(0, slash));
        for (const std::string& dir : dirs) {
            const std::string candidate = dir + "/" + kModuleFile;
            if (access(candidate.c_str(), F_OK) == 0) {
                path = candidate;
                break;
            }
        }
        if (path.empty())
            return {nullptr, "not found in the library path of " + (own.file.empty() ? std::string("this program") : own.file) +
                                 " (its RUNPATH, LD_LIBRARY_PATH) nor beside it; reinstall octiso or set OCTISO_IMAGE_MODULE"};
    }
    // RTLD_LOCAL: OpenImageIO's symbols stay out of the global scope (nothing else binds to them);
    // RTLD_NOW: a broken module fails here, not at its first image.
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) return {nullptr, std::string("cannot load (") + dlerror() + ")"};
    using Entry = const ImageCodec* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(handle, kEntrySymbol));
    if (!entry) return {nullptr, path + " has no " + kEntrySymbol + " (" + dlerror() + ")"};
    const ImageCodec* c = entry();
    if (!c || c->abi != kImageCodecAbi)
        return {nullptr, path + " is from another build of octiso (codec ABI " + std::to_string(c ? c->abi : -1) +
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
