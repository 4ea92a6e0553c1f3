// Output paths checked before any work starts (issue 17): a directory, a missing folder or a
// folder the process cannot write into is refused at once, naming the path the user gave,
// instead of after a long render or conversion, naming a temporary.
#pragma once

#include <string>

namespace octiso::cli {

/// Throws Error(path, ...) unless a file named `path` can be created or replaced: a directory
/// given as the file is bad usage (exit 2); a folder that is missing, not a folder or not
/// writable is the environment's failure (exit 1, as the write would have given). `flag` is
/// named in the message ("-o", "--depth" ...).
void check_output_file(const std::string& path, const std::string& flag);

}  // namespace octiso::cli
