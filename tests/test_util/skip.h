// OCTISO_SKIP(reason): the only way a test here skips. Locally a missing tool or data file (not
// built, mricron-data not installed) skips the test; with OCTISO_REQUIRE_ALL=1 in the environment
// (set by .ci/run, after scripts/setup.sh installed everything) the same test fails instead, so a
// skip can never pass CI. Works in a test body and in a fixture's SetUp(); like GTEST_SKIP it
// returns from the calling function. .ci/run refuses a bare GTEST_SKIP anywhere else in tests/.
#pragma once

#include <cstdlib>
#include <cstring>

#include <gtest/gtest.h>

namespace octiso::test {

inline bool skips_must_fail() {
    const char* v = std::getenv("OCTISO_REQUIRE_ALL");
    return v && std::strcmp(v, "") != 0 && std::strcmp(v, "0") != 0;
}

}  // namespace octiso::test

// The switch makes the macro one statement, so `if (missing) OCTISO_SKIP(...);` has no dangling
// else (the trick GTEST_AMBIGUOUS_ELSE_BLOCKER_ uses).
#define OCTISO_SKIP(reason)                                                     \
    switch (0)                                                                  \
    case 0:                                                                     \
    default:                                                                    \
        if (!::octiso::test::skips_must_fail())                                 \
            GTEST_SKIP() << reason;                                             \
        else                                                                    \
            FAIL() << reason << " (OCTISO_REQUIRE_ALL is set: a skip fails)"
