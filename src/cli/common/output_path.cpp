#include "cli/common/output_path.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "octiso/error.h"

namespace octiso::cli {

void check_output_file(const std::string& path, const std::string& flag) {
    if (path.empty()) throw Error(flag, "needs a file name");
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
        throw Error(path, "is a directory (" + flag + " needs a file name)");
    if (path.back() == '/') throw Error(path, "names a directory (" + flag + " needs a file name)");
    const size_t slash = path.find_last_of('/');
    const std::string folder = slash == std::string::npos ? "." : slash == 0 ? "/" : path.substr(0, slash);
    // A folder that is missing or closed to us is the environment's failure, not a malformed
    // argument: exit status 1, as the write itself would have given (CONVENTIONS 3).
    if (::stat(folder.c_str(), &st) != 0)
        throw Error(path, "cannot be written: folder '" + folder + "' " + (errno == ENOENT ? "does not exist" : std::strerror(errno)),
                    ErrorKind::Other);
    if (!S_ISDIR(st.st_mode)) throw Error(path, "cannot be written: '" + folder + "' is not a folder", ErrorKind::Other);
    // The temporary is created beside the file, so the folder itself must take new entries.
    if (::access(folder.c_str(), W_OK | X_OK) != 0)
        throw Error(path, "cannot be written: folder '" + folder + "' is not writable (" + std::strerror(errno) + ")",
                    ErrorKind::Other);
}

}  // namespace octiso::cli
