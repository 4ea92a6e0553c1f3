// Loads octiso's plug-in modules (module_loader.h).
#include "io/module_loader.h"

#include <dlfcn.h>
#include <link.h>
#include <unistd.h>

#include <cstddef>
#include <cstdlib>
#include <string>
#include <vector>

namespace octiso::io {
namespace {

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
/// Searched here rather than by dlopen of the bare name, because dlopen takes the RUNPATH of its
/// caller, and under ASan its caller is the sanitizer's interceptor in libasan.
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

}  // namespace

LoadedModule load_module(const std::string& file, const char* env_override, const char* entry_symbol) {
    LoadedModule m;
    if (const char* forced = std::getenv(env_override); forced && *forced) {
        m.path = forced;
    } else {
        const OwnObject own = own_object();
        std::vector<std::string> dirs = library_search_path(own.handle);
        if (const size_t slash = own.file.rfind('/'); slash != std::string::npos) dirs.push_back(own.file.substr(0, slash));
        for (const std::string& dir : dirs) {
            const std::string candidate = dir + "/" + file;
            if (access(candidate.c_str(), F_OK) == 0) {
                m.path = candidate;
                break;
            }
        }
        if (m.path.empty()) {
            m.problem = "not found in the library path of " + (own.file.empty() ? std::string("this program") : own.file) +
                        " (its RUNPATH, LD_LIBRARY_PATH) nor beside it; reinstall octiso or set " + env_override;
            return m;
        }
    }
    void* handle = dlopen(m.path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
        m.problem = std::string("cannot load (") + dlerror() + ")";
        return m;
    }
    m.entry = dlsym(handle, entry_symbol);
    if (!m.entry) m.problem = m.path + " has no " + entry_symbol + " (" + dlerror() + ")";
    return m;
}

}  // namespace octiso::io
