// Whether a path ends in a given extension, ignoring case: how the writers that bypass the image
// module (png_writer.h, exr_writer.h) recognise their files, as OpenImageIO does by extension.
#pragma once

#include <cctype>
#include <string>
#include <string_view>

namespace octiso::io {

/// `path` ends in `ext` (".png"), compared without regard to ASCII case.
inline bool has_extension(const std::string& path, std::string_view ext) {
    if (path.size() < ext.size()) return false;
    const size_t start = path.size() - ext.size();
    for (size_t i = 0; i < ext.size(); ++i) {
        const int a = std::tolower(static_cast<unsigned char>(path[start + i]));
        if (a != std::tolower(static_cast<unsigned char>(ext[i]))) return false;
    }
    return true;
}

}  // namespace octiso::io
