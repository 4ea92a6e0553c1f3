// Two levels of checks (pbrt-v4's util/check.h): OCTISO_CHECK stays in every build and guards build
// and load code, where a broken invariant would otherwise write a corrupt octree or image; it
// throws Error(ErrorKind::Other) naming file:line, so the tools exit 1 with one line. OCTISO_DCHECK
// guards what validation already proved, in the hot code (traversal, cell walk, tile loop); it is
// compiled in for debug and sanitizer builds only and aborts with file:line and the message there,
// because that code is noexcept (Embree callbacks) and a throw could not leave it.
//
//   OCTISO_CHECK(cond, message parts...)    e.g. OCTISO_CHECK(at == total, "depth ", d, ": ", at, " of ", total)
//   OCTISO_DCHECK(cond, message parts...)   the parts are streamed with << only when the check fails
#pragma once

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

#include "octiso/error.h"

#if !defined(NDEBUG) || defined(OCTISO_SANITIZE_BUILD)
#define OCTISO_DCHECK_IS_ON 1
#else
#define OCTISO_DCHECK_IS_ON 0
#endif

namespace octiso::detail {

template <class... Parts> std::string check_message(const char* condition, const Parts&... parts) {
    std::ostringstream s;
    s << "check failed: " << condition;
    if constexpr (sizeof...(parts) > 0) {
        s << " (";
        (s << ... << parts);
        s << ")";
    }
    return s.str();
}

/// Cold paths, kept out of line so a passing check costs one compare and a not-taken branch.
template <class... Parts>
[[noreturn, gnu::cold, gnu::noinline]] void check_failed(const char* file, int line, const char* condition,
                                                         const Parts&... parts) {
    throw Error(std::string(file) + ":" + std::to_string(line), check_message(condition, parts...), ErrorKind::Other);
}

template <class... Parts>
[[noreturn, gnu::cold, gnu::noinline]] void dcheck_failed(const char* file, int line, const char* condition,
                                                          const Parts&... parts) noexcept {
    std::fprintf(stderr, "%s:%d: %s\n", file, line, check_message(condition, parts...).c_str());
    std::fflush(stderr);
    std::abort();
}

}  // namespace octiso::detail

#define OCTISO_CHECK(cond, ...)                                                                          \
    do {                                                                                                 \
        if (!(cond)) [[unlikely]]                                                                        \
            ::octiso::detail::check_failed(__FILE__, __LINE__, #cond __VA_OPT__(, ) __VA_ARGS__);        \
    } while (0)

#if OCTISO_DCHECK_IS_ON
#define OCTISO_DCHECK(cond, ...)                                                                         \
    do {                                                                                                 \
        if (!(cond)) [[unlikely]]                                                                        \
            ::octiso::detail::dcheck_failed(__FILE__, __LINE__, #cond __VA_OPT__(, ) __VA_ARGS__);       \
    } while (0)
#else
// Compiled but never evaluated: the condition and the message still type-check (and the names
// they use count as used), and the optimiser drops the dead branch.
#define OCTISO_DCHECK(cond, ...)                                                                         \
    do {                                                                                                 \
        if (false) {                                                                                     \
            (void)(cond);                                                                                \
            ::octiso::detail::dcheck_failed(__FILE__, __LINE__, #cond __VA_OPT__(, ) __VA_ARGS__);       \
        }                                                                                                \
    } while (0)
#endif
