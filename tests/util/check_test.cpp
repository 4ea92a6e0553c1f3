// src/util/check.h: OCTISO_CHECK fires in every build with file:line and the message, as an
// Error of kind Other; OCTISO_DCHECK aborts with its message where it is on (debug and sanitizer
// builds) and evaluates nothing where it is off (Release).
#include <gtest/gtest.h>

#include <string>

#include "util/check.h"

namespace octiso {
namespace {

TEST(Check, FiresWithFileLineAndMessage) {
    const int depth = 31;
    try {
        OCTISO_CHECK(depth < 31, "depth ", depth, " of at most ", 30);
        FAIL() << "OCTISO_CHECK did not fire";
    } catch (const Error& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Other);
        EXPECT_EQ(e.exit_status(), 1);
        EXPECT_NE(e.subject().find("check_test.cpp:"), std::string::npos) << e.subject();
        EXPECT_EQ(e.problem(), "check failed: depth < 31 (depth 31 of at most 30)");
    }
}

TEST(Check, PassingCheckEvaluatesItsConditionOnceAndNoMessage) {
    int evaluated = 0, formatted = 0;
    auto message = [&] { return ++formatted; };
    OCTISO_CHECK(++evaluated == 1, message());
    EXPECT_EQ(evaluated, 1);
    EXPECT_EQ(formatted, 0);
    OCTISO_CHECK(true);   // a message is optional
}

#if OCTISO_DCHECK_IS_ON
TEST(CheckDeathTest, DcheckAbortsWithItsMessage) {
    const int tile = 7;
    EXPECT_DEATH(OCTISO_DCHECK(tile < 4, "tile ", tile, " of 4"), "check failed: tile < 4 \\(tile 7 of 4\\)");
}
#else
TEST(Check, DcheckCompilesAwayInRelease) {
    int evaluated = 0;
    OCTISO_DCHECK(++evaluated < 0, "never formatted");
    OCTISO_DCHECK(false);
    EXPECT_EQ(evaluated, 0) << "an off DCHECK must not evaluate its condition";
}
#endif

}  // namespace
}  // namespace octiso
