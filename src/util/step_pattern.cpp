// The one expansion of a series name pattern (include/octiso/step_pattern.h). Only %[0][width]d
// is accepted: any other conversion would read an argument snprintf was never given.
#include "octiso/step_pattern.h"

#include <cctype>
#include <cstdio>
#include <vector>

#include "octiso/error.h"

namespace octiso {

std::string format_step(const std::string& pattern, long long k, const std::string& flag) {
    // Accept exactly one conversion of the form %[0][width]d; "%%" is a literal percent.
    int fields = 0;
    for (size_t i = 0; i < pattern.size(); ++i) {
        if (pattern[i] != '%') continue;
        if (i + 1 < pattern.size() && pattern[i + 1] == '%') { ++i; continue; }
        size_t j = i + 1;
        while (j < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[j]))) ++j;
        if (j >= pattern.size() || pattern[j] != 'd')
            throw Error(flag, "pattern '" + pattern + "' may hold only %d-style fields");
        ++fields;
        i = j;
    }
    if (fields != 1) throw Error(flag, "pattern '" + pattern + "' needs exactly one printf integer field such as %04d");
    std::vector<char> buf(pattern.size() + 32);
    const int n = std::snprintf(buf.data(), buf.size(), pattern.c_str(), int(k));
    if (n < 0 || size_t(n) >= buf.size()) throw Error(flag, "pattern '" + pattern + "' did not expand");
    return std::string(buf.data(), size_t(n));
}

}  // namespace octiso
