// The checks every reader makes on an input path before it touches the contents: it exists, is a
// regular file (not a directory) and can be opened for reading. Shared by the raw and VTK readers
// and by open_volume(), so "no such file" wins over any complaint about missing flags.
#pragma once

#include <cstdint>
#include <string>

namespace octiso::io {

/// Size in bytes of the regular, readable file `path`; throws Error(path, ...) otherwise.
uint64_t check_input_file(const std::string& path);

}  // namespace octiso::io
