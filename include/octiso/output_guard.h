// Guards for output paths given on a command line: an output must never be one of the inputs
// (issue 18: `octiso-convert in.raw ... -o in.raw` replaced its input and exited 0). Same file
// means the same device and inode, so links and other spellings of the path are caught too.
#pragma once

#include <string>
#include <vector>

namespace octiso {

/// Throws Error(flag, ...) (bad input, exit 2) naming both paths if `output` exists and is the
/// same file (st_dev, st_ino) as any of `inputs`. Inputs that do not exist are ignored (the
/// readers report them).
void refuse_output_onto_input(const std::string& output, const std::vector<std::string>& inputs,
                              const std::string& flag = "-o");

}  // namespace octiso
