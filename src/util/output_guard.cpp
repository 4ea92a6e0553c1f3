// refuse_output_onto_input(): compares device and inode of an output path with every input.
#include "octiso/output_guard.h"

#include <sys/stat.h>

#include "octiso/error.h"

namespace octiso {

void refuse_output_onto_input(const std::string& output, const std::vector<std::string>& inputs, const std::string& flag) {
    struct stat out {};
    if (::stat(output.c_str(), &out) != 0) return;   // nothing there yet: nothing to destroy
    for (const std::string& in : inputs) {
        struct stat st {};
        if (::stat(in.c_str(), &st) != 0) continue;
        if (st.st_dev == out.st_dev && st.st_ino == out.st_ino)
            throw Error(flag, "'" + output + "' is the same file as the input '" + in + "'; refusing to overwrite it");
    }
}

}  // namespace octiso
